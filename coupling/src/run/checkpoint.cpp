// Checkpoints in HDF5 (checkpoint.hpp). Layout: root attributes "format" (2) and "dimension";
// datasets "/scene", "/scene_source", "/scene_overrides" (bytes); every member of
// Simulation::visit_state under "/mechanics/<name>"; the output marks under "/marks/<name>"; what the
// run loop adds (the thermal coupler, series memory) under its own groups. Vectors of n items with c
// values each are n × c (c = 1: n), scalars one-element datasets (long: int64, bool: int32).
#include <frictherm/coupling/checkpoint.hpp>

#include "run/checkpoint_io.hpp"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace frictherm::coupling {

namespace ckpt {

using h5detail::check;
using h5detail::check_id;
using h5detail::Handle;

namespace {

hid_t file_type(hid_t memory_type) {
  if (memory_type == H5T_NATIVE_DOUBLE) return H5T_IEEE_F64LE;
  if (memory_type == H5T_NATIVE_INT32) return H5T_STD_I32LE;
  if (memory_type == H5T_NATIVE_CHAR) return H5T_STD_I8LE;
  if (memory_type == H5T_NATIVE_UINT64) return H5T_STD_U64LE;
  return H5T_STD_I64LE;
}

}  // namespace

void write_array(hid_t group, const std::string& file, const std::string& name, hid_t type, const void* data,
                 hsize_t n, int components) {
  const hsize_t dims[2] = {n, static_cast<hsize_t>(components)};
  const Handle space{check_id(H5Screate_simple(components == 1 ? 1 : 2, dims, nullptr), file, "dataspace"), H5Sclose};
  const Handle lcpl{check_id(H5Pcreate(H5P_LINK_CREATE), file, "property list"), H5Pclose};
  check(H5Pset_create_intermediate_group(lcpl.get(), 1), file, "property list");
  const Handle dcpl{check_id(H5Pcreate(H5P_DATASET_CREATE), file, "property list"), H5Pclose};
  check(H5Pset_obj_track_times(dcpl.get(), 0), file, "property list");  // equal states give equal files
  const Handle d{check_id(H5Dcreate2(group, name.c_str(), file_type(type), space.get(), lcpl.get(), dcpl.get(),
                                     H5P_DEFAULT),
                          file, "cannot create '" + name + "'"),
                 H5Dclose};
  if (n > 0) check(H5Dwrite(d.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), file, "cannot write '" + name + "'");
}

Handle open_array(hid_t group, const std::string& file, const std::string& name, int components, hsize_t& n) {
  Handle d{check_id(H5Dopen2(group, name.c_str(), H5P_DEFAULT), file, "checkpoint has no '" + name + "'"), H5Dclose};
  const Handle space{check_id(H5Dget_space(d.get()), file, "dataspace of '" + name + "'"), H5Sclose};
  hsize_t dims[2] = {0, 1};
  const int rank = H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  if (rank < 1 || rank > 2 || static_cast<int>(dims[1]) != (rank == 1 ? 1 : components) ||
      (rank == 1) != (components == 1))
    throw std::runtime_error("checkpoint '" + file + "': '" + name + "' has the wrong shape (expected " +
                             std::to_string(components) + " values per item)");
  n = dims[0];
  return d;
}

}  // namespace ckpt

namespace {

using ckpt::open_array;
using ckpt::write_array;
using h5detail::check;
using h5detail::check_id;
using h5detail::Handle;

constexpr int kFormat = 2;  // 2: thermal coupler, penalty contact and output marks (1: mechanics only)

void write_int_attribute(hid_t obj, const std::string& file, const char* name, int value) {
  const Handle space{check_id(H5Screate(H5S_SCALAR), file, "dataspace"), H5Sclose};
  const Handle a{check_id(H5Acreate2(obj, name, H5T_STD_I32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), file,
                          std::string("attribute ") + name),
                 H5Aclose};
  check(H5Awrite(a.get(), H5T_NATIVE_INT, &value), file, std::string("attribute ") + name);
}

int read_int_attribute(hid_t obj, const std::string& file, const char* name) {
  const Handle a{check_id(H5Aopen(obj, name, H5P_DEFAULT), file, std::string("not a checkpoint: no attribute ") + name),
                 H5Aclose};
  int value = 0;
  check(H5Aread(a.get(), H5T_NATIVE_INT, &value), file, std::string("attribute ") + name);
  return value;
}

Handle open_checkpoint(const std::string& path, int dimension) {
  Handle f{check_id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), path, "cannot open the checkpoint"), H5Fclose};
  const int format = read_int_attribute(f.get(), path, "format");
  if (format != kFormat)
    throw std::runtime_error("checkpoint '" + path + "': format " + std::to_string(format) + " (expected " +
                             std::to_string(kFormat) + "; written by another frictherm version)");
  if (dimension > 0 && read_int_attribute(f.get(), path, "dimension") != dimension)
    throw std::runtime_error("checkpoint '" + path + "': written by a " +
                             std::to_string(read_int_attribute(f.get(), path, "dimension")) +
                             "D simulation, restored into a " + std::to_string(dimension) + "D one");
  return f;
}

void write_text(hid_t f, const std::string& file, const char* name, const std::string& text) {
  write_array(f, file, name, H5T_NATIVE_CHAR, text.data(), text.size(), 1);
}

std::string read_text(hid_t f, const std::string& path, const char* name) {
  hsize_t n = 0;
  const Handle d = open_array(f, path, name, 1, n);
  std::string text(n, '\0');
  if (n > 0)
    check(H5Dread(d.get(), H5T_NATIVE_CHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()), path,
          std::string("cannot read ") + name);
  return text;
}

std::string read_text(const std::string& path, const char* name) {
  const h5detail::Quiet quiet;
  const Handle f = open_checkpoint(path, 0);
  return read_text(f.get(), path, name);
}


template <int Dim>
void write_file(const std::string& path, mechanics::Simulation<Dim>& sim, const std::string& scene_text,
                const std::string& source, const std::string& overrides, const CheckpointMarks& marks,
                const std::function<void(const ckpt::Writer&)>& extra) {
  sim.finalize();  // penalty contact is set up here
  // Per process: two runs checkpointing into one folder never share a temporary.
  const std::string tmp = path + "." + std::to_string(static_cast<long>(getpid())) + ".tmp";
  try {
    const h5detail::Quiet quiet;
    const Handle f{check_id(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), tmp,
                            "cannot create the checkpoint"),
                   H5Fclose};
    write_int_attribute(f.get(), tmp, "format", kFormat);
    write_int_attribute(f.get(), tmp, "dimension", Dim);
    write_text(f.get(), tmp, "scene", scene_text);
    write_text(f.get(), tmp, "scene_source", source);
    write_text(f.get(), tmp, "scene_overrides", overrides);
    {
      const Handle g{check_id(H5Gcreate2(f.get(), "mechanics", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), tmp, "group"),
                     H5Gclose};
      sim.visit_state(ckpt::Writer{g.get(), tmp});
    }
    const ckpt::Writer root{f.get(), tmp};
    ckpt::write_marks(root, f.get(), tmp, marks);
    if (extra) extra(root);
    check(H5Fflush(f.get(), H5F_SCOPE_GLOBAL), tmp, "cannot flush the checkpoint");
    void* handle = nullptr;  // durable before it takes the name (issue 34)
    check(H5Fget_vfd_handle(f.get(), H5P_DEFAULT, &handle), tmp, "cannot get the checkpoint's descriptor");
    if (handle != nullptr && ::fsync(*static_cast<int*>(handle)) != 0)
      throw std::runtime_error("checkpoint '" + tmp + "': cannot make it durable (fsync: " + std::strerror(errno) + ")");
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  // POSIX rename replaces `path` atomically: a reader sees the old or the new checkpoint, never half.
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp.c_str());
    throw std::runtime_error("checkpoint '" + path + "': cannot rename '" + tmp + "' over it: " + reason);
  }
}

std::string joined_overrides(const std::vector<SceneOverride>& list) {
  std::string text;  // one "path=value" per line
  for (const SceneOverride& o : list) text += o.path + "=" + o.value + "\n";
  return text;
}

}  // namespace

std::string checkpoint_path(const std::string& result_path) { return result_path + ".checkpoint"; }

int checkpoint_ranks(const std::string& path) {
  const h5detail::Quiet quiet;
  const Handle f = open_checkpoint(path, 0);
  if (H5Aexists(f.get(), "ranks") <= 0) return 0;
  return read_int_attribute(f.get(), path, "ranks");
}

template <int Dim>
void write_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim, const Scene& scene,
                      const CheckpointMarks& marks, const std::function<void(const ckpt::Writer&)>& extra) {
  write_file(path, sim, scene.text, scene.source, joined_overrides(scene.overrides), marks, extra);
}

namespace {

// Items (first dimension) of dataset `name`, or -1 when the checkpoint has none of that name.
long items(hid_t f, const std::string& path, const std::string& name) {
  if (H5Lexists(f, name.substr(0, name.find('/')).c_str(), H5P_DEFAULT) <= 0) return -1;
  if (name.find('/') != std::string::npos && H5Lexists(f, name.c_str(), H5P_DEFAULT) <= 0) return -1;
  const Handle d{check_id(H5Dopen2(f, name.c_str(), H5P_DEFAULT), path, "cannot open '" + name + "'"), H5Dclose};
  const Handle space{check_id(H5Dget_space(d.get()), path, "dataspace of '" + name + "'"), H5Sclose};
  hsize_t dims[2] = {0, 0};
  if (H5Sget_simple_extent_ndims(space.get()) < 1) return 0;
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  return static_cast<long>(dims[0]);
}

// Every value of the double dataset `name` (when present) is finite; else the first item that is not.
void require_finite(hid_t f, const std::string& path, const std::string& name) {
  if (items(f, path, name) <= 0) return;
  const Handle d{check_id(H5Dopen2(f, name.c_str(), H5P_DEFAULT), path, "cannot open '" + name + "'"), H5Dclose};
  const Handle type{check_id(H5Dget_type(d.get()), path, "type of '" + name + "'"), H5Tclose};
  if (H5Tget_class(type.get()) != H5T_FLOAT) return;
  const Handle space{check_id(H5Dget_space(d.get()), path, "dataspace of '" + name + "'"), H5Sclose};
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  std::vector<double> v(static_cast<std::size_t>(n));
  check(H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path, "cannot read '" + name + "'");
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw std::runtime_error("checkpoint '" + path + "': /" + name + " holds a non-finite value (" +
                               std::to_string(v[i]) + " at value " + std::to_string(i) + "); the checkpoint is damaged");
}

// The arrays' sizes against the simulation built from the scene (P particles, G grid nodes, M
// materials) and the values the next step reads for finiteness, before any state is restored
// (issue 34: truncated, padded or NaN arrays had been accepted). Arrays a run has not filled yet
// may be empty.
void check_arrays(hid_t f, const std::string& path, std::size_t particles, std::size_t nodes, std::size_t materials) {
  const long P = static_cast<long>(particles), G = static_cast<long>(nodes), M = static_cast<long>(materials);
  auto require = [&](const std::string& name, long expected, bool may_be_empty, const char* what) {
    const long n = items(f, path, name);
    if (n < 0 || n == expected || (may_be_empty && n == 0)) return;
    throw std::runtime_error("checkpoint '" + path + "': /" + name + " holds " + std::to_string(n) +
                             " items, expected " + std::to_string(expected) + " (" + what +
                             "); the checkpoint is damaged or belongs to another scene");
  };
  static const char* const kParticleArrays[] = {
      "position", "initial_position", "velocity", "half_size", "mass", "initial_volume", "volume",
      "deformation_gradient", "stress", "stress_zz", "temperature", "plastic_strain", "internal_energy",
      "plastic_work", "material", "body"};
  for (const char* a : kParticleArrays) {
    const std::string name = std::string("mechanics/particles/") + a;
    require(name, P, false, "the scene's particles");
    require_finite(f, path, name);
  }
  require("mechanics/wave_speed", P, true, "the scene's particles");
  for (const char* a : {"mechanics/work_first", "mechanics/work_second", "mechanics/contact/lagged_normal_traction",
                        "mechanics/contact/lagged_normal_step", "pending/work", "system/unknown"})
    require(a, G, true, "the scene's grid nodes");
  for (const char* a : {"mechanics/pair_work_first", "mechanics/pair_work_second"})
    require(a, M * M, true, "material pairs of the scene");
  for (const char* a : {"hotspots/owner", "hotspots/reference", "reaction/particle_progress"})
    require(a, P, true, "the scene's particles");
  // The thermal unknowns: as many temperatures and masses as grid nodes listed, at most G.
  const long unknowns = items(f, path, "system/grid_node");
  if (unknowns > G)
    throw std::runtime_error("checkpoint '" + path + "': /system/grid_node holds " + std::to_string(unknowns) +
                             " items, expected at most " + std::to_string(G) + " (the scene's grid nodes)");
  if (unknowns >= 0) {
    require("nodal_temperature", unknowns, false, "the thermal unknowns listed in /system/grid_node");
    require("system/mass", unknowns, false, "the thermal unknowns listed in /system/grid_node");
  }
  for (const char* a : {"mechanics/time", "mechanics/last_dt", "mechanics/work_first", "mechanics/work_second",
                        "mechanics/pair_work_first", "mechanics/pair_work_second", "nodal_temperature", "system/mass",
                        "pending/work", "window_start"})
    require_finite(f, path, a);
}

}  // namespace

template <int Dim>
void read_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim,
                     const std::function<void(const ckpt::Reader&)>& extra) {
  const h5detail::Quiet quiet;
  const Handle f = open_checkpoint(path, Dim);
  check_arrays(f.get(), path, sim.particles().size(), sim.grid().node_count(), sim.materials().size());
  {
    const Handle g{check_id(H5Gopen2(f.get(), "mechanics", H5P_DEFAULT), path, "checkpoint has no /mechanics"),
                   H5Gclose};
    sim.finalize();
    sim.visit_state(ckpt::Reader{g.get(), path, sim.particles().size()});
  }
  if (extra) extra(ckpt::Reader{f.get(), path, sim.particles().size()});
}

CheckpointMarks checkpoint_marks(const std::string& path) {
  const h5detail::Quiet quiet;
  const Handle f = open_checkpoint(path, 0);
  const ckpt::Reader r{f.get(), path, 0};
  CheckpointMarks m;
  r("marks/step", m.step);
  r("marks/time", m.time);
  r("marks/series_rows", m.series_rows);
  r("marks/snapshots", m.snapshots);
  r("marks/end_of_loading", m.end_of_loading);
  if (H5Lexists(f.get(), "marks/run_id", H5P_DEFAULT) > 0) m.run_id = read_text(f.get(), path, "marks/run_id");
  const std::string names = read_text(f.get(), path, "marks/table_names");
  std::vector<long> rows;
  r("marks/table_rows", rows);
  std::size_t k = 0;
  for (std::size_t a = 0, b; a < names.size() && k < rows.size(); a = b + 1, ++k) {
    b = names.find('\n', a);
    if (b == std::string::npos) b = names.size();
    m.table_rows.emplace_back(names.substr(a, b - a), rows[k]);
  }
  return m;
}

template <int Dim>
void write_mechanics_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim,
                                const std::string& scene_text) {
  CheckpointMarks marks;
  marks.step = sim.step_count();
  marks.time = sim.time();
  write_file(path, sim, scene_text, "", "", marks, {});
}

template <int Dim>
void read_mechanics_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim) {
  read_checkpoint(path, sim, {});
}

std::string checkpoint_scene_text(const std::string& path) { return read_text(path, "scene"); }

std::vector<SceneOverride> checkpoint_overrides(const std::string& path) {
  std::vector<SceneOverride> overrides;
  const std::string lines = read_text(path, "scene_overrides");
  for (std::size_t a = 0, b; a < lines.size(); a = b + 1) {
    b = lines.find('\n', a);
    if (b == std::string::npos) b = lines.size();
    if (b > a) overrides.push_back(parse_override(lines.substr(a, b - a)));
  }
  return overrides;
}

Scene checkpoint_scene(const std::string& path, const std::vector<SceneOverride>& more) {
  const std::string text = read_text(path, "scene"), source = read_text(path, "scene_source");
  std::vector<SceneOverride> overrides = checkpoint_overrides(path);
  overrides.insert(overrides.end(), more.begin(), more.end());
  const std::size_t slash = source.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : source.substr(0, slash));
  std::string name = slash == std::string::npos ? source : source.substr(slash + 1);
  if (const std::size_t dot = name.find_last_of('.'); dot != std::string::npos && dot > 0) name = name.substr(0, dot);
  if (name.empty()) name = "scene";
  return parse_scene(text, source.empty() ? "<string>" : source, dir, name, overrides);
}

#define FRICTHERM_INSTANTIATE_CHECKPOINT(D)                                                                  \
  template void write_checkpoint<D>(const std::string&, mechanics::Simulation<D>&, const Scene&,             \
                                    const CheckpointMarks&, const std::function<void(const ckpt::Writer&)>&); \
  template void read_checkpoint<D>(const std::string&, mechanics::Simulation<D>&,                            \
                                   const std::function<void(const ckpt::Reader&)>&);                         \
  template void write_mechanics_checkpoint<D>(const std::string&, mechanics::Simulation<D>&, const std::string&); \
  template void read_mechanics_checkpoint<D>(const std::string&, mechanics::Simulation<D>&);
FRICTHERM_INSTANTIATE_CHECKPOINT(2)
FRICTHERM_INSTANTIATE_CHECKPOINT(3)
#undef FRICTHERM_INSTANTIATE_CHECKPOINT

void ckpt::write_marks(const Writer& w, hid_t f, const std::string& file, CheckpointMarks m) {
  w("marks/step", m.step);
  w("marks/time", m.time);
  w("marks/series_rows", m.series_rows);
  w("marks/snapshots", m.snapshots);
  w("marks/end_of_loading", m.end_of_loading);
  std::string names;
  std::vector<long> rows;
  for (const auto& [name, n] : m.table_rows) {
    names += name + "\n";
    rows.push_back(n);
  }
  write_text(f, file, "marks/table_names", names);
  write_text(f, file, "marks/run_id", m.run_id);
  w("marks/table_rows", rows);
}

}  // namespace frictherm::coupling
