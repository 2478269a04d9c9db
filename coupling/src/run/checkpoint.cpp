// Checkpoints in HDF5 (checkpoint.hpp). Layout: root attributes "format" (3) and "dimension";
// datasets "/scene", "/scene_source", "/scene_overrides" (bytes); every member of
// Simulation::visit_state under "/mechanics/<name>"; the output marks under "/marks/<name>"; what the
// run loop adds (the thermal coupler, series memory) under its own groups. Vectors of n items with c
// values each are n × c (c = 1: n), scalars one-element datasets (long: int64, bool: int32).
#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/runner.hpp>

#include "run/checkpoint_checks.hpp"
#include "run/checkpoint_io.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <cstdio>
#include <limits>
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
  // The groups on the way, without time stamps (the 1.10 object headers would store them).
  for (std::size_t slash = name.find('/'); slash != std::string::npos; slash = name.find('/', slash + 1))
    if (H5Lexists(group, name.substr(0, slash).c_str(), H5P_DEFAULT) <= 0) create_group(group, file, name.substr(0, slash));
  const Handle lcpl{check_id(H5Pcreate(H5P_LINK_CREATE), file, "property list"), H5Pclose};
  const Handle dcpl{check_id(H5Pcreate(H5P_DATASET_CREATE), file, "property list"), H5Pclose};
  check(H5Pset_obj_track_times(dcpl.get(), 0), file, "property list");  // equal states give equal files
  if (n > 0) {  // a Fletcher32 checksum per chunk (chunked layout: one chunk up to kChunkBytes; issue 34)
    const hsize_t item = H5Tget_size(type) * static_cast<hsize_t>(components);
    const hsize_t chunk[2] = {std::min<hsize_t>(n, std::max<hsize_t>(1, kChunkBytes / item)),
                              static_cast<hsize_t>(components)};
    check(H5Pset_chunk(dcpl.get(), components == 1 ? 1 : 2, chunk), file, "property list");
    check(H5Pset_fletcher32(dcpl.get()), file, "property list");
  }
  const Handle d{check_id(H5Dcreate2(group, name.c_str(), file_type(type), space.get(), lcpl.get(), dcpl.get(),
                                     H5P_DEFAULT),
                          file, "cannot create '" + name + "'"),
                 H5Dclose};
  if (n > 0) check(H5Dwrite(d.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), file, "cannot write '" + name + "'");
}

namespace {

std::string type_text(H5T_class_t cls, std::size_t size, H5T_sign_t sign) {
  const std::string bits = std::to_string(8 * size) + "-bit ";
  if (cls == H5T_FLOAT) return bits + "float";
  if (cls == H5T_INTEGER) return bits + (sign == H5T_SGN_NONE ? "unsigned integer" : "integer");
  if (cls == H5T_STRING) return "string";
  return "HDF5 type class " + std::to_string(static_cast<int>(cls));
}

}  // namespace

Handle open_array(hid_t group, const std::string& file, const std::string& name, int components, hsize_t& n,
                  hid_t memory_type, const std::string& shown_name) {
  const std::string shown = shown_name.empty() ? name : shown_name;
  if (H5Lexists(group, name.c_str(), H5P_DEFAULT) <= 0)  // also false when a group on the way is missing
    throw std::runtime_error("checkpoint '" + file + "' has no '" + shown + "'; the checkpoint is damaged");
  Handle d{check_id(H5Dopen2(group, name.c_str(), H5P_DEFAULT), file, "checkpoint has no dataset '" + shown + "'"),
           H5Dclose};
  const Handle space{check_id(H5Dget_space(d.get()), file, "dataspace of '" + shown + "'"), H5Sclose};
  hsize_t dims[2] = {0, 1};
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank >= 1 && rank <= 2) H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  if (rank < 1 || rank > 2 || static_cast<int>(dims[1]) != (rank == 1 ? 1 : components) ||
      (rank == 1) != (components == 1))
    throw std::runtime_error("checkpoint '" + file + "': '" + shown + "' has the wrong shape (expected " +
                             (components == 1 ? std::string("a list of values") :
                                                "items of " + std::to_string(components) + " values") +
                             ", found rank " + std::to_string(rank) + ")");
  if (memory_type != H5I_INVALID_HID) {
    const Handle t{check_id(H5Dget_type(d.get()), file, "type of '" + shown + "'"), H5Tclose};
    const H5T_class_t cls = H5Tget_class(t.get()), want_cls = H5Tget_class(memory_type);
    const std::size_t size = H5Tget_size(t.get()), want_size = H5Tget_size(memory_type);
    const H5T_sign_t sign = cls == H5T_INTEGER ? H5Tget_sign(t.get()) : H5T_SGN_ERROR;
    const H5T_sign_t want_sign = want_cls == H5T_INTEGER ? H5Tget_sign(memory_type) : H5T_SGN_ERROR;
    if (cls != want_cls || size != want_size || sign != want_sign)
      throw std::runtime_error("checkpoint '" + file + "': '" + shown + "' is stored as " +
                               type_text(cls, size, sign) + ", expected " + type_text(want_cls, want_size, want_sign) +
                               "; the checkpoint is damaged");
  }
  n = dims[0];
  if (n > 0 && !has_checksum(d.get()))
    throw std::runtime_error("checkpoint '" + file + "': '" + shown +
                             "' has no checksum (Fletcher32 filter; every non-empty dataset of a checkpoint has one "
                             "since format 3); the checkpoint is damaged");
  return d;
}

namespace {
herr_t note_object(hid_t, const char* name, const H5O_info_t*, void* last) {
  *static_cast<std::string*>(last) = name;
  return 0;
}
}  // namespace

void check_objects(hid_t f, const std::string& file) {
  // Every object header read (H5O_INFO_ALL loads all its chunks): the 1.10 format checksums them, so
  // a damaged header of an object the reader would not open by name (a group's continuation chunk,
  // an index) is found too, not only the datasets' data (Fletcher32).
  std::string last;
  if (H5Ovisit2(f, H5_INDEX_NAME, H5_ITER_NATIVE, note_object, &last, H5O_INFO_ALL) < 0)
    h5detail::fail(file, "cannot read every object of the checkpoint (the last read: '/" + last + "'); the file is damaged");
}

Handle create_group(hid_t parent, const std::string& file, const std::string& name) {
  const Handle gcpl{check_id(H5Pcreate(H5P_GROUP_CREATE), file, "property list"), H5Pclose};
  check(H5Pset_obj_track_times(gcpl.get(), 0), file, "property list");  // equal states give equal files
  return Handle{check_id(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), file,
                         "cannot create the group '" + name + "'"),
                H5Gclose};
}

Handle create_file(const std::string& file) {
  const Handle fcpl{check_id(H5Pcreate(H5P_FILE_CREATE), file, "property list"), H5Pclose};
  check(H5Pset_obj_track_times(fcpl.get(), 0), file, "property list");  // the root group's
  const Handle fapl = file_access(file);
  return Handle{check_id(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), file,
                         "cannot create the checkpoint"),
                H5Fclose};
}

Handle file_access(const std::string& file) {
  Handle fapl{check_id(H5Pcreate(H5P_FILE_ACCESS), file, "property list"), H5Pclose};
  // The 1.10 file format: a dataset of one chunk is indexed by its object header alone (no B-tree),
  // which keeps the checksums' chunked layout about as small as the contiguous one.
  check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V110, H5F_LIBVER_V110), file, "property list");
  return fapl;
}

bool has_checksum(hid_t dataset) {
  const Handle dcpl{H5Dget_create_plist(dataset), H5Pclose};
  if (dcpl.get() < 0) return false;
  unsigned flags = 0;
  std::size_t count = 0;
  unsigned config = 0;
  return H5Pget_filter_by_id2(dcpl.get(), H5Z_FILTER_FLETCHER32, &flags, &count, nullptr, 0, nullptr, &config) >= 0;
}

void require_finite(const std::string& file, const std::string& shown, const double* values, std::size_t count,
                    bool (*allowed)(const std::string&, double)) {
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i]) && !(allowed && allowed(shown, values[i])))
      throw std::runtime_error("checkpoint '" + file + "': '" + shown + "' holds a non-finite value (" +
                               std::to_string(values[i]) + " at value " + std::to_string(i) +
                               "); the checkpoint is damaged");
}

bool allowed_sentinel(const std::string& shown, double value) {
  // EnergyBooks::min_window: +inf until a window closes; Simulation's WaveSpeeds::speed: -inf for
  // rigid particles (never a CFL speed); ContactNodeState::lagged_normal_traction: NaN where a node
  // had no contact yet; WorkBooks::initial_energy: NaN before the first step (check_arrays requires
  // it finite after).
  // A decomposed run's global file: the result's series rows as written (NaN where a column is
  // undefined, e.g. the first row's rates).
  if (shown == "/output/series_rows") return true;
  if (value == std::numeric_limits<double>::infinity()) return shown == "/books/min_window";
  // A decomposed rank file's /interface/max_temperature: −∞ before any heat (DecomposedHeat).
  if (value == -std::numeric_limits<double>::infinity())
    return shown == "/mechanics/wave_speed" || shown == "/interface/max_temperature";
  return std::isnan(value) &&
         (shown == "/mechanics/initial_energy" || shown == "/mechanics/contact/lagged_normal_traction");
}

// Integer attributes of a checkpoint (int as 32-bit, long as 64-bit), serial and decomposed.
template <class Int>
void write_integer_attribute(hid_t obj, const std::string& file, const char* name, Int value, hid_t file_type,
                             hid_t memory_type) {
  const Handle space{check_id(H5Screate(H5S_SCALAR), file, "dataspace"), H5Sclose};
  const Handle a{check_id(H5Acreate2(obj, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT), file,
                          std::string("attribute ") + name),
                 H5Aclose};
  check(H5Awrite(a.get(), memory_type, &value), file, std::string("attribute ") + name);
}

void write_int_attribute(hid_t obj, const std::string& file, const char* name, int value) {
  write_integer_attribute(obj, file, name, value, H5T_STD_I32LE, H5T_NATIVE_INT);
}

void write_int_attribute(hid_t obj, const std::string& file, const char* name, long value) {
  write_integer_attribute(obj, file, name, value, H5T_STD_I64LE, H5T_NATIVE_LONG);
}

long read_int_attribute(hid_t obj, const std::string& file, const char* name) {
  if (H5Aexists(obj, name) <= 0)
    throw std::runtime_error("checkpoint '" + file + "': not a checkpoint, or damaged: no attribute '" + name + "'");
  const Handle a{check_id(H5Aopen(obj, name, H5P_DEFAULT), file, std::string("not a checkpoint: no attribute ") + name),
                 H5Aclose};
  const Handle type{check_id(H5Aget_type(a.get()), file, std::string("attribute ") + name), H5Tclose};
  const Handle space{check_id(H5Aget_space(a.get()), file, std::string("attribute ") + name), H5Sclose};
  if (H5Tget_class(type.get()) != H5T_INTEGER || H5Sget_simple_extent_npoints(space.get()) != 1)
    throw std::runtime_error("checkpoint '" + file + "': attribute '" + name +
                             "' is not one integer; the checkpoint is damaged");
  long value = 0;
  check(H5Aread(a.get(), H5T_NATIVE_LONG, &value), file, std::string("attribute ") + name);
  return value;
}

}  // namespace ckpt

namespace {

using ckpt::open_array;
using ckpt::write_array;
using h5detail::check;
using h5detail::check_id;
using h5detail::Handle;

// A checkpoint that cannot be read, or does not fit, is a bad input (exit code 2, OutputError), never a
// failed run: every reading entry point turns its errors into OutputError naming the file and the
// dataset (issue 34). SceneError (a --set of `continue`) passes through.
template <class F> auto refusing(const std::string& path, F&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const SceneError&) {
    throw;
  } catch (const OutputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw OutputError("checkpoint '" + path + "': a dataset's size is out of all proportion; the checkpoint is damaged");
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
}


Handle open_checkpoint(const std::string& path, int dimension) {
  Handle f{check_id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), path, "cannot open the checkpoint"), H5Fclose};
  const long format = ckpt::read_int_attribute(f.get(), path, "format");
  if (format == ckpt::kFormat) ckpt::check_objects(f.get(), path);
  if (const std::string why = ckpt::older_format_reason(format); !why.empty())
    throw std::runtime_error("checkpoint '" + path + "': " + why + " (expected format " +
                             std::to_string(ckpt::kFormat) + "); resume it with the version that wrote it, "
                             "or run the scene again");
  if (format != ckpt::kFormat)
    throw std::runtime_error("checkpoint '" + path + "': format " + std::to_string(format) + " (expected " +
                             std::to_string(ckpt::kFormat) + "; written by another frictherm version)");
  if (dimension > 0 && ckpt::read_int_attribute(f.get(), path, "dimension") != dimension)
    throw std::runtime_error("checkpoint '" + path + "': written by a " +
                             std::to_string(ckpt::read_int_attribute(f.get(), path, "dimension")) +
                             "D simulation (its attribute 'dimension'), restored into a " + std::to_string(dimension) +
                             "D one");
  return f;
}

void write_text(hid_t f, const std::string& file, const char* name, const std::string& text) {
  write_array(f, file, name, H5T_NATIVE_CHAR, text.data(), text.size(), 1);
}

std::string read_text(hid_t f, const std::string& path, const char* name) {
  hsize_t n = 0;
  const Handle d = open_array(f, path, name, 1, n, H5T_NATIVE_CHAR, std::string("/") + name);
  std::string text(n, '\0');
  if (n > 0)
    check(H5Dread(d.get(), H5T_NATIVE_CHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()), path,
          std::string("cannot read '/") + name + "'");
  return text;
}

std::string read_text(const std::string& path, const char* name) {
  return refusing(path, [&] {
    const h5detail::Quiet quiet;
    const Handle f = open_checkpoint(path, 0);
    return read_text(f.get(), path, name);
  });
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
    const Handle f = ckpt::create_file(tmp);
    ckpt::write_int_attribute(f.get(), tmp, "format", ckpt::kFormat);
    ckpt::write_int_attribute(f.get(), tmp, "dimension", Dim);
    write_text(f.get(), tmp, "scene", scene_text);
    write_text(f.get(), tmp, "scene_source", source);
    write_text(f.get(), tmp, "scene_overrides", overrides);
    {
      const Handle g = ckpt::create_group(f.get(), tmp, "mechanics");
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
  return refusing(path, [&] {
    const h5detail::Quiet quiet;
    const Handle f = open_checkpoint(path, 0);
    if (H5Aexists(f.get(), "ranks") <= 0) return 0;
    const long ranks = ckpt::read_int_attribute(f.get(), path, "ranks");
    if (ranks < 1)
      throw std::runtime_error("checkpoint '" + path + "': attribute 'ranks' is " + std::to_string(ranks) +
                               ", expected a number of ranks >= 1; the checkpoint is damaged");
    return static_cast<int>(ranks);
  });
}

template <int Dim>
void write_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim, const Scene& scene,
                      const CheckpointMarks& marks, const std::function<void(const ckpt::Writer&)>& extra) {
  write_file(path, sim, scene.text, scene.source, joined_overrides(scene.overrides), marks, extra);
}


template <int Dim>
void read_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim,
                     const std::function<void(const ckpt::Reader&)>& extra) {
  refusing(path, [&] {
  const h5detail::Quiet quiet;
  const Handle f = open_checkpoint(path, Dim);
  sim.finalize();  // penalty contact samples its boundary points here
  ckpt::SceneSizes sizes{static_cast<long>(sim.particles().size()),    static_cast<long>(sim.grid().node_count()),
                         static_cast<long>(sim.materials().size()),    static_cast<long>(sim.bodies().size()),
                         static_cast<long>(sim.boundary_points().size()), static_cast<long>(sim.penalty_pairs().size()),
                         sim.contact_enabled(),
                         static_cast<long>(sim.contact_pairs().size()),
                         {}, {}, {}, {}, {}};
  for (const auto& m : sim.materials()) sizes.rigid.push_back(m.is_rigid());
  for (int d = 0; d < Dim; ++d) {  // Grid::contains
    sizes.lo.push_back(sim.grid().lo()[d]);
    sizes.hi.push_back(sim.grid().lo()[d] + sim.grid().cell_size()[d] * sim.grid().cells()[d]);
    sizes.cell.push_back(sim.grid().cell_size()[d]);
    double half = 0.5 * sim.grid().cell_size()[d];
    for (const auto& l : sim.particles().half_size) half = std::max(half, l[d]);
    sizes.max_half.push_back(half);
  }
  ckpt::check_arrays(f.get(), path, sizes);
  {
    const Handle g{check_id(H5Gopen2(f.get(), "mechanics", H5P_DEFAULT), path, "checkpoint has no /mechanics"),
                   H5Gclose};
    sim.finalize();
    sim.visit_state(ckpt::Reader{g.get(), path, sim.particles().size(), "/mechanics/", true});
  }
  if (extra) extra(ckpt::Reader{f.get(), path, sim.particles().size(), "/", true});
  });
}

CheckpointMarks checkpoint_marks(const std::string& path) {
  return refusing(path, [&] {
    const h5detail::Quiet quiet;
    const Handle f = open_checkpoint(path, 0);
    const ckpt::Reader r{f.get(), path, 0, "/", true};
    CheckpointMarks m;
    r("marks/step", m.step);
    r("marks/time", m.time);
    r("marks/series_rows", m.series_rows);
    r("marks/snapshots", m.snapshots);
    r("marks/end_of_loading", m.end_of_loading);
    auto damaged = [&](const char* name, const std::string& what) {
      throw std::runtime_error("checkpoint '" + path + "': /marks/" + name + " " + what + "; the checkpoint is damaged");
    };
    for (auto [name, x] : {std::pair<const char*, long>{"step", m.step}, {"series_rows", m.series_rows},
                           {"snapshots", m.snapshots}})
      if (x < 0) damaged(name, "is " + std::to_string(x) + ", expected a count >= 0");
    if (m.time < 0.0) damaged("time", "is negative");
    if (H5Lexists(f.get(), "marks", H5P_DEFAULT) > 0 && H5Lexists(f.get(), "marks/run_id", H5P_DEFAULT) > 0) {
      // Any text (RunOptions::run_id; a run draws 32 hex digits); a result of another id is refused
      // by check_appendable, an empty one is an older version's checkpoint.
      m.run_id = read_text(f.get(), path, "marks/run_id");
    }
    const std::string names = read_text(f.get(), path, "marks/table_names");
    std::vector<long> rows;
    r("marks/table_rows", rows);
    std::size_t k = 0;
    for (std::size_t a = 0, b; a < names.size(); a = b + 1, ++k) {
      b = names.find('\n', a);
      if (b == std::string::npos) b = names.size();
      if (k >= rows.size()) damaged("table_names", "names more tables than /marks/table_rows counts");
      const std::string table = names.substr(a, b - a);
      if (table != "hotspots" && table != "hotspot_fates")
        damaged("table_names", "names a table '" + table + "' (expected hotspots or hotspot_fates)");
      for (const auto& [other, count] : m.table_rows)
        if (other == table) damaged("table_names", "names " + table + " twice");
      if (rows[k] < 0) damaged("table_rows", "counts " + std::to_string(rows[k]) + " rows of /" + names.substr(a, b - a));
      m.table_rows.emplace_back(names.substr(a, b - a), rows[k]);
    }
    if (k != rows.size()) damaged("table_rows", "counts " + std::to_string(rows.size()) + " tables, /marks/table_names names " + std::to_string(k));
    return m;
  });
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
  const std::size_t slash = source.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : source.substr(0, slash));
  std::string name = slash == std::string::npos ? source : source.substr(slash + 1);
  if (const std::size_t dot = name.find_last_of('.'); dot != std::string::npos && dot > 0) name = name.substr(0, dot);
  if (name.empty()) name = "scene";
  const std::string shown = source.empty() ? "<string>" : source;
  // The stored scene must parse as it was run: a refusal here is a damaged checkpoint (exit code 2
  // naming /scene), not a bad --set of `continue` (a SceneError naming the key, checked after).
  std::vector<SceneOverride> overrides;
  try {
    overrides = checkpoint_overrides(path);
    if (more.empty()) return parse_scene(text, shown, dir, name, overrides);
    parse_scene(text, shown, dir, name, overrides);
  } catch (const OutputError&) {
    throw;
  } catch (const std::exception& e) {
    // A file the scene reads (an image body's shape.file), relative to the scene's folder, that is
    // gone or unreadable now: the checkpoint is intact, the file has to come back.
    const std::string what = e.what();
    if (what.find(".file: ") != std::string::npos)
      throw OutputError("checkpoint '" + path + "': the scene stored in /scene reads a file that cannot be read now (" +
                        what + "); the checkpoint itself is intact: restore that file, relative to '" + dir + "'");
    throw OutputError("checkpoint '" + path + "': the scene stored in /scene with /scene_overrides does not parse (" +
                      what + "); the checkpoint is damaged");
  }
  overrides.insert(overrides.end(), more.begin(), more.end());
  return parse_scene(text, shown, dir, name, overrides);
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
