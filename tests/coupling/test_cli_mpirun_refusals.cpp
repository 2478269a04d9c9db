// Refusals of `mpirun -n 2 frictherm run` and `validate` (issue 16, issue 34; coupling/app/cli_run_mpi.cpp,
// coupling/src/scene/scene_decomposed.cpp, coupling/src/distributed_run/decomposed_runner.cpp):
//   * a scene the decomposed engine does not support would be refused with exit code 2 naming the
//     scene key, before any file is written; none is left (the last, coupling.reuse_distance > 0 with
//     forward_euler, runs since issue 32's reuse), and `validate` says the scene decomposes;
//   * an existing output file (the series file or one rank's file) is refused without --force, left
//     untouched, and replaced with it;
//   * `validate` under mpirun: every rank validates, rank 0 alone prints.
// Skipped when mpirun is not installed. Labels verification;mpi.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_mpirun_test_support.hpp"
#include "h5_test_support.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using namespace frictherm::test;  // exe, scene, shell, Result, read_doubles, read_text, ...
constexpr auto mpirun = mpirun_command;
using CliMpirun = CliMpirunTest;

// The last refusal (coupling.reuse_distance > 0 with forward_euler, before issue 32's reuse) is gone:
// `validate` says that the scene decomposes.
TEST_F(CliMpirun, ReuseDistanceIsNoLongerRefused) {
  const Result v = shell(exe() + " validate " + scene("decomposed_sliding_block.json") +
                         " --set coupling.reuse_distance=0.02");
  EXPECT_EQ(v.code, 0) << v.output;
  EXPECT_THAT(v.output, HasSubstr("mpirun -n K frictherm run decomposes it"));
  EXPECT_THAT(v.output, ::testing::Not(HasSubstr("serial only")));
}

TEST_F(CliMpirun, ExistingOutputIsRefusedWithoutForce) {
  const std::string run = mpirun(2) + " " + exe() + " run " + scene("decomposed_sliding_block.json") +
                          " -q --set run.end_time=2e-5 -o '" + path("out.h5") + "'";
  const char* const files[] = {"out.h5", "out.rank0.h5", "out.rank1.h5", "out.xdmf"};
  for (const char* existing : {"out.h5", "out.rank1.h5", "out.xdmf"}) {
    for (const char* f : files) fs::remove(path(f));
    std::ofstream(path(existing)) << "an earlier result";
    const Result r = shell(run);
    EXPECT_EQ(r.code, 2) << existing << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr(std::string(existing) + "' exists; refusing to replace an existing result"));
    std::ifstream in(path(existing));
    std::stringstream kept;
    kept << in.rdbuf();
    EXPECT_EQ(kept.str(), "an earlier result") << existing;
    for (const char* f : files)
      if (std::string(f) != existing) {
        EXPECT_FALSE(fs::exists(path(f))) << existing << " refused, yet " << f << " written";
      }
  }
  // With --force every file is replaced (here out.xdmf existed).
  const Result forced = shell(run + " --force");
  EXPECT_EQ(forced.code, 0) << forced.output;
  EXPECT_FALSE(read_doubles(path("out.rank1.h5"), "/snapshots/000000/id").empty() &&
               read_doubles(path("out.rank0.h5"), "/snapshots/000000/id").empty());
  EXPECT_FALSE(read_doubles(path("out.h5"), "/series/time").empty());
  std::ifstream xdmf(path("out.xdmf"));
  std::stringstream text;
  text << xdmf.rdbuf();
  EXPECT_THAT(text.str(), HasSubstr("out.rank1.h5:/snapshots/000000/position"));
}

// `validate` under mpirun: every rank validates, rank 0 alone prints (issue 34: once per rank).
TEST_F(CliMpirun, ValidateUnderMpirunSpeaksOnce) {
  const Result ok = shell(mpirun(2) + " " + exe() + " validate " + scene("decomposed_sliding_block.json"));
  EXPECT_EQ(ok.code, 0) << ok.output;
  std::size_t count = 0;
  for (std::size_t at = ok.output.find("\nok\n"); at != std::string::npos; at = ok.output.find("\nok\n", at + 1)) ++count;
  EXPECT_EQ(count, 1u) << ok.output;
  const Result bad = shell(mpirun(2) + " " + exe() + " validate " + scene("decomposed_sliding_block.json") +
                           " --set run.end_time=-1");
  EXPECT_EQ(bad.code, 2) << bad.output;
  std::size_t said = 0;
  for (std::size_t at = bad.output.find("run.end_time"); at != std::string::npos; at = bad.output.find("run.end_time", at + 1)) ++said;
  EXPECT_EQ(said, 1u) << bad.output;
}
