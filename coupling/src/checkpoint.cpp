// Mechanics checkpoints in HDF5 (checkpoint.hpp). Layout: root attributes "format" (1) and
// "dimension"; dataset "/scene" (the scene text, bytes); every member of Simulation::visit_state under
// "/mechanics/<name>": vectors of n items with c doubles (or int32) each as n × c (c = 1: n), scalars as
// one-element datasets (long: int64, bool: int32).
#include <frictherm/coupling/checkpoint.hpp>

#include "h5_util.hpp"

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace frictherm::coupling {

namespace {

using h5detail::check;
using h5detail::check_id;
using h5detail::Handle;

constexpr int kFormat = 1;

// Element type of a member: its HDF5 type and components per item.
template <class T> struct Layout {  // fixed-size Eigen vector or matrix of doubles
  static_assert(std::is_same_v<typename T::Scalar, double>, "checkpoint: Eigen members must hold doubles");
  static_assert(sizeof(T) == sizeof(double) * T::SizeAtCompileTime, "checkpoint: padded Eigen type");
  using Scalar = double;
  static constexpr int components = T::SizeAtCompileTime;
  static hid_t type() { return H5T_NATIVE_DOUBLE; }
};
template <> struct Layout<double> {
  using Scalar = double;
  static constexpr int components = 1;
  static hid_t type() { return H5T_NATIVE_DOUBLE; }
};
template <> struct Layout<std::int32_t> {
  using Scalar = std::int32_t;
  static constexpr int components = 1;
  static hid_t type() { return H5T_NATIVE_INT32; }
};
template <> struct Layout<long> {
  using Scalar = long;
  static constexpr int components = 1;
  static hid_t type() { return H5T_NATIVE_LONG; }
};

hid_t file_type(hid_t memory_type) {
  if (memory_type == H5T_NATIVE_DOUBLE) return H5T_IEEE_F64LE;
  if (memory_type == H5T_NATIVE_INT32) return H5T_STD_I32LE;
  if (memory_type == H5T_NATIVE_CHAR) return H5T_STD_I8LE;
  return H5T_STD_I64LE;
}

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

// Opens `name`, checks that it holds items of `components` values, returns the item count.
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

struct Writer {
  hid_t group;
  const std::string& file;
  template <class T> void operator()(const char* name, std::vector<T>& data) const {
    using L = Layout<T>;
    write_array(group, file, name, L::type(), data.data(), data.size(), L::components);
  }
  void operator()(const char* name, double& x) const { write_array(group, file, name, H5T_NATIVE_DOUBLE, &x, 1, 1); }
  void operator()(const char* name, long& x) const { write_array(group, file, name, H5T_NATIVE_LONG, &x, 1, 1); }
  void operator()(const char* name, bool& x) const {
    const std::int32_t b = x ? 1 : 0;
    write_array(group, file, name, H5T_NATIVE_INT32, &b, 1, 1);
  }
};

struct Reader {
  hid_t group;
  const std::string& file;
  std::size_t particles;  // the rebuilt simulation's particle count
  template <class T> void operator()(const char* name, std::vector<T>& data) const {
    using L = Layout<T>;
    hsize_t n = 0;
    const Handle d = open_array(group, file, name, L::components, n);
    const std::string key(name);
    if (key.rfind("particles/", 0) == 0 && n != particles)
      throw std::runtime_error("checkpoint '" + file + "': '" + key + "' holds " + std::to_string(n) +
                               " particles, the simulation built from the scene has " + std::to_string(particles));
    data.resize(n);
    if (n > 0) check(H5Dread(d.get(), L::type(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), file, "cannot read '" + key + "'");
  }
  template <class T> void scalar(const char* name, hid_t type, T& x) const {
    hsize_t n = 0;
    const Handle d = open_array(group, file, name, 1, n);
    if (n != 1) throw std::runtime_error("checkpoint '" + file + "': '" + std::string(name) + "' is not one value");
    check(H5Dread(d.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &x), file, "cannot read '" + std::string(name) + "'");
  }
  void operator()(const char* name, double& x) const { scalar(name, H5T_NATIVE_DOUBLE, x); }
  void operator()(const char* name, long& x) const { scalar(name, H5T_NATIVE_LONG, x); }
  void operator()(const char* name, bool& x) const {
    std::int32_t b = 0;
    scalar(name, H5T_NATIVE_INT32, b);
    x = b != 0;
  }
};

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
  if (read_int_attribute(f.get(), path, "format") != kFormat)
    throw std::runtime_error("checkpoint '" + path + "': unknown format (expected " + std::to_string(kFormat) + ")");
  if (dimension > 0 && read_int_attribute(f.get(), path, "dimension") != dimension)
    throw std::runtime_error("checkpoint '" + path + "': written by a " +
                             std::to_string(read_int_attribute(f.get(), path, "dimension")) +
                             "D simulation, restored into a " + std::to_string(dimension) + "D one");
  return f;
}


template <int Dim>
void write_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim, const std::string& scene_text,
                      const std::string& source, const std::string& overrides) {
  sim.finalize();  // penalty contact is set up here
  const std::string why = sim.checkpoint_refusal();
  if (!why.empty()) throw std::invalid_argument("cannot checkpoint this run: " + why);
  const std::string tmp = path + ".tmp";
  {
    const h5detail::Quiet quiet;
    const Handle f{check_id(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), tmp,
                            "cannot create the checkpoint"),
                   H5Fclose};
    write_int_attribute(f.get(), tmp, "format", kFormat);
    write_int_attribute(f.get(), tmp, "dimension", Dim);
    write_array(f.get(), tmp, "scene", H5T_NATIVE_CHAR, scene_text.data(), scene_text.size(), 1);
    write_array(f.get(), tmp, "scene_source", H5T_NATIVE_CHAR, source.data(), source.size(), 1);
    write_array(f.get(), tmp, "scene_overrides", H5T_NATIVE_CHAR, overrides.data(), overrides.size(), 1);
    const Handle g{check_id(H5Gcreate2(f.get(), "mechanics", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), tmp, "group"),
                   H5Gclose};
    sim.visit_state(Writer{g.get(), tmp});
    check(H5Fflush(f.get(), H5F_SCOPE_GLOBAL), tmp, "cannot flush the checkpoint");
  }
  // POSIX rename replaces `path` atomically: a reader sees the old or the new checkpoint, never half.
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error("checkpoint '" + path + "': cannot rename '" + tmp + "' over it");
}

std::string read_text(const std::string& path, const char* name) {
  const h5detail::Quiet quiet;
  const Handle f = open_checkpoint(path, 0);
  hsize_t n = 0;
  const Handle d = open_array(f.get(), path, name, 1, n);
  std::string text(n, '\0');
  if (n > 0) check(H5Dread(d.get(), H5T_NATIVE_CHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()), path, std::string("cannot read ") + name);
  return text;
}

}  // namespace

std::string checkpoint_path(const std::string& result_path) { return result_path + ".checkpoint"; }

template <int Dim>
void write_mechanics_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim,
                                const std::string& scene_text) {
  write_checkpoint(path, sim, scene_text, "", "");
}

template <int Dim>
void write_mechanics_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim, const Scene& scene) {
  std::string overrides;  // one "path=value" per line
  for (const SceneOverride& o : scene.overrides) overrides += o.path + "=" + o.value + "\n";
  write_checkpoint(path, sim, scene.text, scene.source, overrides);
}

template <int Dim>
void read_mechanics_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim) {
  const h5detail::Quiet quiet;
  const Handle f = open_checkpoint(path, Dim);
  const Handle g{check_id(H5Gopen2(f.get(), "mechanics", H5P_DEFAULT), path, "checkpoint has no /mechanics"), H5Gclose};
  sim.finalize();
  sim.visit_state(Reader{g.get(), path, sim.particles().size()});
}

std::string checkpoint_scene_text(const std::string& path) { return read_text(path, "scene"); }

Scene checkpoint_scene(const std::string& path) {
  const std::string text = read_text(path, "scene"), source = read_text(path, "scene_source");
  std::vector<SceneOverride> overrides;
  const std::string lines = read_text(path, "scene_overrides");
  for (std::size_t a = 0, b; a < lines.size(); a = b + 1) {
    b = lines.find('\n', a);
    if (b == std::string::npos) b = lines.size();
    if (b > a) overrides.push_back(parse_override(lines.substr(a, b - a)));
  }
  const std::size_t slash = source.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : source.substr(0, slash));
  std::string name = slash == std::string::npos ? source : source.substr(slash + 1);
  if (const std::size_t dot = name.find_last_of('.'); dot != std::string::npos && dot > 0) name = name.substr(0, dot);
  if (name.empty()) name = "scene";
  return parse_scene(text, source.empty() ? "<string>" : source, dir, name, overrides);
}

template void write_mechanics_checkpoint<2>(const std::string&, mechanics::Simulation<2>&, const std::string&);
template void write_mechanics_checkpoint<3>(const std::string&, mechanics::Simulation<3>&, const std::string&);
template void write_mechanics_checkpoint<2>(const std::string&, mechanics::Simulation<2>&, const Scene&);
template void write_mechanics_checkpoint<3>(const std::string&, mechanics::Simulation<3>&, const Scene&);
template void read_mechanics_checkpoint<2>(const std::string&, mechanics::Simulation<2>&);
template void read_mechanics_checkpoint<3>(const std::string&, mechanics::Simulation<3>&);

}  // namespace frictherm::coupling
