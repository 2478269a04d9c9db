#pragma once
// Comparing a resumed (joined) result with an uninterrupted run's in tests (test_checkpoint_thermal.cpp,
// test_cli_resume.cpp): whole files as bytes and the XDMF files that list their grids.
#include <frictherm/coupling/xdmf.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

namespace frictherm::test {

/// The bytes of a file ("" when it does not open).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The lines of an XDMF file, sorted, with the HDF5 file's name `from` written as `to`: two results
/// whose XDMF files list the same grids (times, steps, point counts, datasets) give equal lists,
/// whatever order each writer gave the attributes of a grid in.
inline std::vector<std::string> xdmf_lines(const std::string& path, const std::string& from, const std::string& to) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    for (std::size_t at = from.empty() ? std::string::npos : line.find(from); at != std::string::npos;
         at = line.find(from, at + to.size()))
      line.replace(at, from.size(), to);
    lines.push_back(line);
  }
  std::sort(lines.begin(), lines.end());
  return lines;
}

inline std::string base_name(const std::string& path) { return path.substr(path.find_last_of('/') + 1); }

/// The joined result's XDMF files (RUN.xdmf, RUN_reference.xdmf and, with `nodes`, RUN_nodes.xdmf)
/// list what the uninterrupted run's list: a resume rewrites all of them (issue 33: RUN_reference.xdmf
/// was left as the interrupted run wrote it).
inline void expect_same_xdmf(const std::string& joined, const std::string& full, bool nodes) {
  using namespace frictherm::coupling;
  std::vector<std::pair<std::string, std::string>> files{{xdmf_path_for(joined), xdmf_path_for(full)},
                                                         {xdmf_reference_path_for(joined), xdmf_reference_path_for(full)}};
  if (nodes) files.emplace_back(xdmf_nodes_path_for(joined), xdmf_nodes_path_for(full));
  for (const auto& [a, b] : files) {
    const std::vector<std::string> la = xdmf_lines(a, base_name(joined), base_name(full)), lb = xdmf_lines(b, "", "");
    EXPECT_GT(lb.size(), 20u) << b;
    EXPECT_TRUE(la == lb) << a << " does not list what " << b << " lists (" << la.size() << " and " << lb.size()
                          << " lines)";
  }
}

}  // namespace frictherm::test
