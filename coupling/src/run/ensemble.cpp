// Ensembles of one scene over seeds, and the aggregation of their hot spots (ensemble.hpp).
#include <frictherm/coupling/results.hpp>
#include <frictherm/coupling/ensemble.hpp>
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/h5_output.hpp>

#include "output/h5_io.hpp"
#include "output/h5_util.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <map>
#include <stdexcept>

namespace frictherm::coupling {

using h5detail::check;
using h5detail::check_id;
using h5detail::Handle;

void validate(const EnsembleOptions& o) {
  auto bad = [](const std::string& what) { throw std::invalid_argument(what); };
  if (o.seed_key.empty()) bad("--seed-key: expected the scene key path that takes each member's seed, e.g. bodies[1].shape.seed");
  if (o.members < 1) bad("--members: expected an integer >= 1");
  if (o.first_seed < 0) bad("--first-seed: expected an integer >= 0");
  if (o.output.empty()) bad("--output: expected the aggregate HDF5 file");
  if (o.ranks < 1 || o.rank < 0 || o.rank >= o.ranks) bad("rank must be in [0, ranks)");
}

std::string member_file(const EnsembleOptions& o, long seed) {
  std::string prefix = o.member_prefix;
  if (prefix.empty()) {
    prefix = o.output;
    if (prefix.size() > 3 && prefix.compare(prefix.size() - 3, 3, ".h5") == 0) prefix.resize(prefix.size() - 3);
    prefix += "_seed";
  }
  return prefix + std::to_string(seed) + ".h5";
}

std::vector<MemberRecord> run_members(const std::string& scene_path, const EnsembleOptions& o) {
  validate(o);
  std::vector<MemberRecord> out;
  for (int k = o.rank; k < o.members; k += o.ranks) {
    MemberRecord r;
    r.seed = o.first_seed + k;
    r.file = member_file(o, r.seed);
    std::vector<SceneOverride> ov = o.overrides;
    ov.push_back({o.seed_key, std::to_string(r.seed)});
    RunOptions ro;
    ro.output = r.file;
    ro.threads = o.threads;
    ro.quiet = o.quiet;
    ro.overwrite = o.overwrite;
    ro.command_line = "ensemble member " + std::to_string(k) + " of " + scene_path + " with " + o.seed_key + "=" +
                      std::to_string(r.seed);
    try {
      const RunResult res = run_scene(load_scene(scene_path, ov), ro);
      r.status = res.status == RunResult::Status::completed ? 0 : res.status == RunResult::Status::stopped_at_max_steps ? 1 : 2;
      r.steps = res.steps, r.simulated_time = res.time, r.wall_time = res.wall_time, r.message = res.message;
    } catch (const std::exception& e) {
      r.status = 2, r.message = e.what();
    }
    if (!o.quiet) {
      std::cerr << "frictherm ensemble: member " << k + 1 << "/" << o.members << " (seed " << r.seed << ") "
                << (r.status == 2 ? "failed: " + r.message : "done in " + std::to_string(r.wall_time) + " s") << '\n';
    }
    out.push_back(std::move(r));
  }
  return out;
}

namespace {

const std::vector<double>* column(const SeriesTable& t, const std::string& name) {
  for (std::size_t j = 0; j < t.names.size(); ++j)
    if (t.names[j] == name) return &t.columns[j];
  return nullptr;
}

const std::vector<double>& need(const SeriesTable& t, const std::string& name, const std::string& file,
                                const std::string& table) {
  const auto* c = column(t, name);
  if (!c) throw std::runtime_error("HDF5 file '" + file + "': /" + table + " has no column " + name);
  return *c;
}

// One column group with a `columns` attribute (fixed-length strings) and 1-D double datasets.
void write_columns(hid_t file, const std::string& path, const std::string& group,
                   const std::vector<std::string>& names, const std::vector<std::vector<double>>& cols, int dim) {
  const Handle g{check_id(H5Gcreate2(file, group.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path,
                          "cannot create /" + group),
                 H5Gclose};
  std::size_t width = 1;
  for (const auto& n : names) width = std::max(width, n.size() + 1);
  std::string packed(width * names.size(), '\0');
  for (std::size_t i = 0; i < names.size(); ++i) packed.replace(i * width, names[i].size(), names[i]);
  const Handle type{check_id(H5Tcopy(H5T_C_S1), path, "string type"), H5Tclose};
  check(H5Tset_size(type.get(), width), path, "string type");
  const hsize_t count = names.size();
  const Handle as{check_id(H5Screate_simple(1, &count, nullptr), path, "attribute space"), H5Sclose};
  const Handle a{check_id(H5Acreate2(g.get(), "columns", type.get(), as.get(), H5P_DEFAULT, H5P_DEFAULT), path,
                          "cannot create /" + group + " attribute columns"),
                 H5Aclose};
  check(H5Awrite(a.get(), type.get(), packed.data()), path, "cannot write /" + group + " attribute columns");
  for (std::size_t j = 0; j < names.size(); ++j) {
    const hsize_t n = cols[j].size();
    const Handle s{check_id(H5Screate_simple(1, &n, nullptr), path, "dataspace"), H5Sclose};
    const std::string where = "/" + group + "/" + names[j];
    const bool integer = H5Output::is_count_column(names[j]);  // seeds, ids, counts: int64 (format version 2)
    const Handle d{check_id(H5Dcreate2(g.get(), names[j].c_str(), integer ? H5T_STD_I64LE : H5T_IEEE_F64LE, s.get(),
                                       H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                            path, "cannot create " + where),
                   H5Dclose};
    std::vector<double> values = cols[j];
    if (integer)
      for (double& v : values) v = std::nearbyint(v);
    if (n > 0)
      check(H5Dwrite(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), path,
            "cannot write " + where);
    h5detail::Io{path}.describe(d.get(), names[j], dim, false, where);  // units, long_name (output_quantities.hpp)
  }
}

void write_attribute(hid_t file, const std::string& path, const std::string& name, double value) {
  const Handle s{check_id(H5Screate(H5S_SCALAR), path, "dataspace"), H5Sclose};
  const Handle a{check_id(H5Acreate2(file, name.c_str(), H5T_NATIVE_DOUBLE, s.get(), H5P_DEFAULT, H5P_DEFAULT), path,
                          "cannot create attribute " + name),
                 H5Aclose};
  check(H5Awrite(a.get(), H5T_NATIVE_DOUBLE, &value), path, "cannot write attribute " + name);
}

void write_attribute(hid_t file, const std::string& path, const std::string& name, std::int64_t value) {
  const Handle s{check_id(H5Screate(H5S_SCALAR), path, "dataspace"), H5Sclose};
  const Handle a{check_id(H5Acreate2(file, name.c_str(), H5T_STD_I64LE, s.get(), H5P_DEFAULT, H5P_DEFAULT), path,
                          "cannot create attribute " + name),
                 H5Aclose};
  check(H5Awrite(a.get(), H5T_NATIVE_INT64, &value), path, "cannot write attribute " + name);
}

// The member files, in /members row order: a 1-D fixed-length UTF-8 string dataset /member_files.
void write_strings(hid_t file, const std::string& path, const std::string& name, const std::vector<std::string>& values) {
  std::size_t width = 1;
  for (const auto& v : values) width = std::max(width, v.size());
  std::string packed(width * values.size(), '\0');
  for (std::size_t i = 0; i < values.size(); ++i) packed.replace(i * width, values[i].size(), values[i]);
  const Handle type{check_id(H5Tcopy(H5T_C_S1), path, "string type"), H5Tclose};
  check(H5Tset_size(type.get(), width), path, "string type");
  check(H5Tset_cset(type.get(), H5T_CSET_UTF8), path, "string type");
  const hsize_t n = values.size();
  const Handle s{check_id(H5Screate_simple(1, &n, nullptr), path, "dataspace"), H5Sclose};
  const Handle d{check_id(H5Dcreate2(file, name.c_str(), type.get(), s.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                          path, "cannot create /" + name),
                 H5Dclose};
  if (n > 0) check(H5Dwrite(d.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, packed.data()), path, "cannot write /" + name);
  h5detail::Io{path}.describe(d.get(), name, 2, true, "/" + name);  // text: units "", long_name
}

void write_attribute(hid_t file, const std::string& path, const std::string& name, const std::string& value) {
  const Handle type{check_id(H5Tcopy(H5T_C_S1), path, "string type"), H5Tclose};
  check(H5Tset_size(type.get(), std::max<std::size_t>(1, value.size())), path, "string type");
  const Handle s{check_id(H5Screate(H5S_SCALAR), path, "dataspace"), H5Sclose};
  const Handle a{check_id(H5Acreate2(file, name.c_str(), type.get(), s.get(), H5P_DEFAULT, H5P_DEFAULT), path,
                          "cannot create attribute " + name),
                 H5Aclose};
  const std::string v = value.empty() ? std::string(1, '\0') : value;
  check(H5Awrite(a.get(), type.get(), v.data()), path, "cannot write attribute " + name);
}

}  // namespace

std::vector<EnsembleHotSpot> read_member_hotspots(const std::string& file, long seed) {
  const SeriesTable t = read_table(file, "hotspots");
  std::map<long, EnsembleHotSpot> by_id;
  std::map<long, double> last_seen;
  if (t.rows() > 0) {
    const auto& time = need(t, "time", file, "hotspots");
    const auto& id = need(t, "id", file, "hotspots");
    const auto& peak = need(t, "peak_temperature", file, "hotspots");
    const auto& diam = need(t, "equivalent_diameter", file, "hotspots");
    const auto& size = need(t, "size", file, "hotspots");
    const auto& birth = need(t, "birth_time", file, "hotspots");
    for (std::size_t r = 0; r < t.rows(); ++r) {
      const long k = std::lround(id[r]);
      auto [it, fresh] = by_id.try_emplace(k);
      EnsembleHotSpot& h = it->second;
      if (fresh) h.seed = seed, h.id = k, h.birth_time = birth[r], h.time_to_runaway = std::nan("");
      if (fresh || peak[r] > h.peak_temperature) h.peak_temperature = peak[r], h.equivalent_diameter = diam[r], h.size = size[r];
      last_seen[k] = std::max(last_seen[k], time[r]);
    }
  }
  for (auto& [k, h] : by_id) h.duration = last_seen[k] - h.birth_time;
  // Fates from the thermal-only continuation, when the run had one.
  const SeriesTable f = read_table(file, "hotspot_fates");
  if (f.rows() > 0) {
    const auto& id = need(f, "id", file, "hotspot_fates");
    const auto& fate = need(f, "fate", file, "hotspot_fates");
    const auto* ttr = column(f, "time_to_runaway");
    for (std::size_t r = 0; r < f.rows(); ++r) {
      auto it = by_id.find(std::lround(id[r]));
      if (it == by_id.end()) continue;
      it->second.fate = static_cast<int>(std::lround(fate[r]));
      if (ttr) it->second.time_to_runaway = (*ttr)[r];
    }
  }
  std::vector<EnsembleHotSpot> out;
  for (auto& kv : by_id) out.push_back(kv.second);
  return out;
}

EnsembleSummary aggregate_members(const std::string& scene_path, const EnsembleOptions& o,
                                  const std::vector<MemberRecord>& records) {
  EnsembleSummary s;
  s.members = static_cast<int>(records.size());
  std::vector<std::vector<double>> m(9);
  std::vector<double> counts;
  for (const MemberRecord& r : records) {
    std::vector<EnsembleHotSpot> hs;
    if (r.status != 2) hs = read_member_hotspots(r.file, r.seed);
    if (r.status == 0) ++s.completed;
    double max_peak = 0.0;
    long runaway = 0, dying = 0;
    for (const auto& h : hs) {
      max_peak = std::max(max_peak, h.peak_temperature);
      runaway += h.fate == static_cast<int>(HotSpotFate::runaway), dying += h.fate == static_cast<int>(HotSpotFate::dying);
    }
    if (r.status != 2) counts.push_back(static_cast<double>(hs.size()));
    s.runaway += runaway, s.dying += dying, s.members_with_runaway += runaway > 0;
    const double row[9] = {static_cast<double>(r.seed), static_cast<double>(r.status), static_cast<double>(r.steps),
                           r.simulated_time, r.wall_time, static_cast<double>(hs.size()), max_peak,
                           static_cast<double>(runaway), static_cast<double>(dying)};
    for (int j = 0; j < 9; ++j) m[static_cast<std::size_t>(j)].push_back(row[j]);
    s.hotspots.insert(s.hotspots.end(), hs.begin(), hs.end());
  }
  s.hotspots_total = static_cast<long>(s.hotspots.size());
  if (!counts.empty()) {
    double mean = 0.0, var = 0.0;
    for (double c : counts) mean += c / static_cast<double>(counts.size());
    for (double c : counts) var += (c - mean) * (c - mean);
    s.hotspots_per_member_mean = mean;
    s.hotspots_per_member_std = counts.size() > 1 ? std::sqrt(var / static_cast<double>(counts.size() - 1)) : 0.0;
  }
  s.critical_fraction = (s.runaway + s.dying) > 0 ? static_cast<double>(s.runaway) / static_cast<double>(s.runaway + s.dying)
                                                  : std::numeric_limits<double>::quiet_NaN();  // no decided spot: undefined

  std::vector<std::vector<double>> h(9);
  for (const auto& x : s.hotspots) {
    const double row[9] = {static_cast<double>(x.seed), static_cast<double>(x.id), x.peak_temperature,
                            x.equivalent_diameter, x.size, x.birth_time, x.duration, static_cast<double>(x.fate),
                            x.time_to_runaway};
    for (int j = 0; j < 9; ++j) h[static_cast<std::size_t>(j)].push_back(row[j]);
  }
  const h5detail::Quiet quiet;
  // Written under a temporary name and renamed when complete (output_files.hpp).
  const std::string live = temporary_path(o.output);
  {
  const Handle file{check_id(H5Fcreate(live.c_str(), H5F_ACC_EXCL, H5P_DEFAULT, H5P_DEFAULT), live,
                             "cannot create the file"),
                    H5Fclose};
  int dim = 2;  // the members' dimension (hot-spot sizes: m^2 in 2D, m^3 in 3D)
  for (const MemberRecord& r : records) {
    try {
      dim = static_cast<int>(read_metadata_number(r.file, "dimension"));
      break;
    } catch (const std::exception&) {  // a member without a readable file: try the next
    }
  }
  write_columns(file.get(), o.output, "members",
                {"seed", "status", "steps", "simulated_time", "wall_time", "hotspots", "max_peak_temperature", "runaway",
                 "dying"},
                m, dim);
  write_columns(file.get(), o.output, "hotspots",
                {"seed", "id", "peak_temperature", "equivalent_diameter", "size", "birth_time", "duration", "fate",
                 "time_to_runaway"},
                h, dim);
  const hid_t f = file.get();
  std::vector<std::string> files;
  for (const MemberRecord& r : records) files.push_back(r.file);
  write_strings(f, o.output, "member_files", files);
  write_attribute(f, o.output, "format", std::string("frictherm-ensemble"));
  write_attribute(f, o.output, "format_version", std::int64_t{2});
  write_attribute(f, o.output, "members", std::int64_t{s.members});
  write_attribute(f, o.output, "completed", std::int64_t{s.completed});
  write_attribute(f, o.output, "hotspots_total", std::int64_t{s.hotspots_total});
  write_attribute(f, o.output, "hotspots_per_member_mean", s.hotspots_per_member_mean);
  write_attribute(f, o.output, "hotspots_per_member_std", s.hotspots_per_member_std);
  write_attribute(f, o.output, "critical_fraction", s.critical_fraction);
  write_attribute(f, o.output, "members_with_runaway", std::int64_t{s.members_with_runaway});
  write_attribute(f, o.output, "seed_key", o.seed_key);
  write_attribute(f, o.output, "scene", scene_path);
  }
  publish_file(live, o.output, o.overwrite);
  return s;
}

}  // namespace frictherm::coupling
