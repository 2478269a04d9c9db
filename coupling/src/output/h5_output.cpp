// HDF5 run output. Crash safety — what a run killed at any instant (even kill -9) leaves behind:
//
// * Every call that changes what the file shows ends with H5Fflush(H5F_SCOPE_GLOBAL):
//   end_snapshot, write_metadata, declare_series, each series batch, flush(). On disk the file is
//   then complete and consistent as of that flush, and nothing already flushed is touched again
//   until the next such call.
// * A snapshot is built as an anonymous group and linked into /snapshots only in end_snapshot, just
//   before the flush, so whatever reaches the disk mid-snapshot is unreachable from the root.
// * Metadata-cache evictions are disabled from begin_snapshot to the flush in end_snapshot, and
//   inside every other modifying call, so no dirty metadata (a half-updated link index, say) is
//   written between two flushes. HDF5 only allows that with a fixed-size cache, so adaptive
//   resizing is off. Evictions are enabled again right after each flush, when every cached entry
//   is clean, so memory stays bounded.
// * File-space strategy NONE: freed space is never reused, so new data cannot overwrite an object
//   (a replaced /meta entry, say) that the last flushed metadata still points at.
// * Format bounds low = 1.8, high = 1.10 — deliberately not low = LATEST: a 1.10-format superblock
//   (v3) records "open for writing" in the file, and after a crash every reader refuses the file
//   until someone runs h5clear. The 1.8 format still has checksummed object headers.
// * Not covered: a crash inside H5Fflush itself (HDF5 writes are not atomic) and power loss (no
//   fsync; a killed process loses nothing the kernel already received).
#include <frictherm/coupling/h5_output.hpp>
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/xdmf.hpp>

#include <hdf5.h>

#include "output/h5_io.hpp"
#include "output/h5_util.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

namespace frictherm::coupling {
namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

using h5detail::check;
using h5detail::check_id;
using h5detail::fail;
using h5detail::Handle;
using h5detail::Quiet;
using h5detail::Io;
using h5detail::check_name;
using h5detail::base_name;

}  // namespace

struct H5Output::Impl {
  Io io;                   // io.file: the file being written
  std::string final_path;  // where close() puts it (io.file unless options.via_temporary)
  std::string xdmf_path;
  int dim = 2;
  H5OutputOptions options;
  Handle file, meta, snapshots, series;
  H5AC_cache_config_t cache{};
  int holds = 0;
  bool closed = false;

  enum class Kind { none, snapshot, failure } kind = Kind::none;
  Handle group;  // the snapshot being written (anonymous until end_snapshot)
  long step = 0;
  double time = 0.0;
  std::string message;
  std::size_t points = kNone;
  std::vector<XdmfField> fields;

  std::size_t count = 0;
  std::vector<std::string> grid_xml;
  std::string failure_xml;
  // RUN_reference.xdmf: the same snapshots drawn at the reference positions X (`initial_position`),
  // for ParaView's Warp By Vector on `displacement`; written once a snapshot has that field.
  std::string reference_path;
  std::vector<std::string> reference_xml;
  std::string reference_failure_xml;
  double last_time = -std::numeric_limits<double>::infinity();
  std::set<std::size_t> connectivity;

  std::vector<std::string> series_names;
  std::vector<Handle> series_sets;
  std::vector<double> pending;  // row-major rows not yet written
  hsize_t series_written = 0;

  // Evictions off while anything is modified between two flushes (see the top of the file).
  void set_evictions(bool on) {
    cache.evictions_enabled = on;
    check(H5Fset_mdc_config(file.get(), &cache), io.file, "cannot configure the metadata cache");
  }
  void hold() {
    if (holds++ == 0) set_evictions(false);
  }
  void release() noexcept {
    if (holds > 0 && --holds == 0) {
      cache.evictions_enabled = true;
      H5Fset_mdc_config(file.get(), &cache);
    }
  }
  struct Scoped {
    Impl& m;
    explicit Scoped(Impl& impl) : m(impl) { m.hold(); }
    ~Scoped() { m.release(); }
    Scoped(const Scoped&) = delete;
    Scoped& operator=(const Scoped&) = delete;
  };

  // /<name> with a `columns` attribute and one extendible 1-D double dataset per column (series, tables).
  void create_columns(const std::string& name, const std::vector<std::string>& columns, const char* what,
                      Handle& group_out, std::vector<Handle>& sets) {
    std::set<std::string> seen;
    std::size_t longest = 1;
    for (const auto& n : columns) {
      check_name(n, what);
      if (!seen.insert(n).second) throw std::invalid_argument(std::string(what) + " '" + n + "' declared twice");
      longest = std::max(longest, n.size());
    }
    const Quiet quiet;
    const Scoped hold_cache(*this);
    group_out = io.group(file.get(), name, "/" + name);
    std::string packed(columns.size() * longest, '\0');  // fixed-length, NUL-padded names
    for (std::size_t i = 0; i < columns.size(); ++i) packed.replace(i * longest, columns[i].size(), columns[i]);
    {
      const Handle type = io.string_type(longest);
      const hsize_t n_columns = columns.size();
      const Handle s = io.space(1, &n_columns);
      const Handle a{check_id(H5Acreate2(group_out.get(), "columns", type.get(), s.get(), H5P_DEFAULT, H5P_DEFAULT),
                              io.file, "cannot create /" + name + " attribute columns"),
                     H5Aclose};
      check(H5Awrite(a.get(), type.get(), packed.data()), io.file, "cannot write /" + name + " attribute columns");
    }
    const hsize_t zero = 0, unlimited = H5S_UNLIMITED, chunk = 1024;
    const Handle space = io.space(1, &zero, &unlimited);
    Handle dcpl{check_id(H5Pcreate(H5P_DATASET_CREATE), io.file, "cannot create a property list"), H5Pclose};
    check(H5Pset_chunk(dcpl.get(), 1, &chunk), io.file, "cannot set chunking");
    for (const auto& n : columns) {
      sets.emplace_back(check_id(H5Dcreate2(group_out.get(), n.c_str(),
                                            H5Output::is_count_column(n) ? H5T_STD_I64LE : H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                                            dcpl.get(), H5P_DEFAULT),
                                 io.file, "cannot create /" + name + "/" + n),
                        H5Dclose);
      io.describe(sets.back().get(), n, dim, false, "/" + name + "/" + n);  // units, long_name
    }
    flush_file();
  }

  // ---- extra append-only tables /<name>/<column> (hot spots, coupling), written with the series ----
  struct Table {
    Handle group;
    std::vector<std::string> names;
    std::vector<Handle> sets;
    std::vector<double> pending;  // row-major rows not yet written
    hsize_t written = 0;
  };
  std::map<std::string, Table> tables;

  void write_table(const std::string& name, Table& t) {
    const std::size_t cols = t.names.size();
    if (cols == 0 || t.pending.empty()) return;
    hsize_t rows = t.pending.size() / cols;
    std::vector<double> column(rows);
    const hsize_t total = t.written + rows;
    for (std::size_t j = 0; j < cols; ++j) {
      for (hsize_t r = 0; r < rows; ++r) column[r] = t.pending[r * cols + j];
      if (H5Output::is_count_column(t.names[j]))  // int64 on disk: round, do not truncate
        for (double& v : column) v = std::nearbyint(v);
      const std::string where = "/" + name + "/" + t.names[j];
      const hid_t ds = t.sets[j].get();
      check(H5Dset_extent(ds, &total), io.file, "cannot extend " + where);
      const Handle fs{check_id(H5Dget_space(ds), io.file, "cannot get the dataspace of " + where), H5Sclose};
      check(H5Sselect_hyperslab(fs.get(), H5S_SELECT_SET, &t.written, nullptr, &rows, nullptr), io.file,
            "cannot select rows of " + where);
      const Handle ms = io.space(1, &rows);
      check(H5Dwrite(ds, H5T_NATIVE_DOUBLE, ms.get(), fs.get(), H5P_DEFAULT, column.data()), io.file,
            "cannot write " + where);
    }
    t.written = total;
    t.pending.clear();
  }
  // ---- end of extra tables ----

  void write_pending() {
    for (auto& [name, table] : tables) write_table(name, table);  // extra tables
    const std::size_t cols = series_names.size();
    if (cols == 0 || pending.empty()) return;
    hsize_t rows = pending.size() / cols;
    std::vector<double> column(rows);
    const hsize_t total = series_written + rows;
    for (std::size_t j = 0; j < cols; ++j) {
      for (hsize_t r = 0; r < rows; ++r) column[r] = pending[r * cols + j];
      if (H5Output::is_count_column(series_names[j]))  // int64 on disk: round, do not truncate
        for (double& v : column) v = std::nearbyint(v);
      const std::string where = "/series/" + series_names[j];
      const hid_t ds = series_sets[j].get();
      check(H5Dset_extent(ds, &total), io.file, "cannot extend " + where);
      const Handle fs{check_id(H5Dget_space(ds), io.file, "cannot get the dataspace of " + where), H5Sclose};
      check(H5Sselect_hyperslab(fs.get(), H5S_SELECT_SET, &series_written, nullptr, &rows, nullptr), io.file,
            "cannot select rows of " + where);
      const Handle ms = io.space(1, &rows);
      check(H5Dwrite(ds, H5T_NATIVE_DOUBLE, ms.get(), fs.get(), H5P_DEFAULT, column.data()), io.file,
            "cannot write " + where);
    }
    series_written = total;
    pending.clear();
  }

  void flush_file() { check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), io.file, "cannot flush"); }

  static std::string document(std::vector<std::string> grids, const std::string& failure, const std::string& name) {
    if (!failure.empty()) grids.push_back(failure);
    return xdmf_document(grids, name);
  }
  bool has_reference() const { return !reference_xml.empty() || !reference_failure_xml.empty(); }

  // Written under the final names after every snapshot; through a temporary the XDMF files are
  // written only with the result (publish): until then they would describe a file that is not
  // under the name they give (issue 34: a second run had relabelled the first run's snapshots).
  void write_xdmf() {
    if (!options.write_xdmf || options.via_temporary) return;
    write_text_atomically(xdmf_path, document(grid_xml, failure_xml, "particles"));
    if (has_reference())
      write_text_atomically(reference_path, document(reference_xml, reference_failure_xml, "particles_reference"));
  }

  // The result renamed onto its name with its XDMF files (publish_with_xdmf, output_files.hpp).
  void publish() {
    if (!options.write_xdmf) return publish_file(io.file, final_path, options.replace_existing);
    publish_with_xdmf(io.file, final_path, options.replace_existing, document(grid_xml, failure_xml, "particles"),
                      has_reference() ? document(reference_xml, reference_failure_xml, "particles_reference") : "");
  }

  void discard_snapshot() noexcept {
    if (kind == Kind::none) return;
    group.reset();  // an anonymous group that was never linked is deleted when closed
    kind = Kind::none;
    fields.clear();
    release();
  }

  void begin(Kind k, long s, double t) {
    if (kind != Kind::none) throw std::logic_error("H5Output: begin_snapshot while a snapshot is open");
    hold();
    Handle g{H5Gcreate_anon(file.get(), H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
    if (g.get() < 0) {
      release();
      fail(io.file, "cannot create a snapshot group");
    }
    group = std::move(g);
    kind = k;
    step = s;
    time = t;
    points = kNone;
    fields.clear();
  }

  void field(const std::string& name, bool integer, const void* data, std::size_t n, int components) {
    if (kind == Kind::none) throw std::logic_error("H5Output: snapshot_field outside begin/end_snapshot");
    check_name(name, "snapshot field");
    if (components < 1) throw std::invalid_argument("snapshot field " + name + ": components must be >= 1");
    if (points != kNone && n != points) {
      throw std::invalid_argument("snapshot field " + name + " has " + std::to_string(n) + " rows, earlier fields " +
                                  std::to_string(points));
    }
    if (name == "position" && components != dim) {
      throw std::invalid_argument("snapshot field position needs " + std::to_string(dim) + " components");
    }
    if (n > 0 && data == nullptr) throw std::invalid_argument("snapshot field " + name + ": null data");
    const std::string where = "snapshot field " + name + " (step " + std::to_string(step) + ")";
    const hsize_t dims[2] = {n, static_cast<hsize_t>(components)};
    const Handle s = io.space(components == 1 ? 1 : 2, dims);
    const hid_t file_type = integer ? H5T_STD_I32LE : H5T_IEEE_F64LE;
    const hid_t mem_type = integer ? H5T_NATIVE_INT32 : H5T_NATIVE_DOUBLE;
    const Handle d{check_id(H5Dcreate2(group.get(), name.c_str(), file_type, s.get(), H5P_DEFAULT, H5P_DEFAULT,
                                       H5P_DEFAULT),
                            io.file, "cannot create " + where),
                   H5Dclose};
    if (n > 0) check(H5Dwrite(d.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), io.file, "cannot write " + where);
    io.describe(d.get(), name, dim, false, where);
    points = n;
    fields.push_back({name, components, integer});
  }

  std::string ensure_connectivity(std::size_t n) {
    const std::string name = "polyvertex_" + std::to_string(n);
    if (connectivity.insert(n).second) {
      if (connectivity.size() == 1) io.group(file.get(), "xdmf", "/xdmf");
      std::vector<std::int32_t> ids(n);
      for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<std::int32_t>(i);
      const hsize_t dims[1] = {n};
      const Handle s = io.space(1, dims);
      const std::string path = "/xdmf/" + name;
      const Handle d{check_id(H5Dcreate2(file.get(), path.c_str(), H5T_STD_I32LE, s.get(), H5P_DEFAULT,
                                         H5P_DEFAULT, H5P_DEFAULT),
                              io.file, "cannot create " + path),
                     H5Dclose};
      check(H5Dwrite(d.get(), H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, ids.data()), io.file,
            "cannot write " + path);
      io.describe(d.get(), name, dim, false, path);
    }
    return "/xdmf/" + name;
  }

  void end() {
    if (kind == Kind::none) throw std::logic_error("H5Output: end_snapshot without begin_snapshot");
    const bool failure = kind == Kind::failure;
    char name[32];
    std::snprintf(name, sizeof name, "%06zu", count);
    const std::string path = failure ? std::string("/failure") : "/snapshots/" + std::string(name);
    try {
      const std::int64_t s = step;
      io.attribute(group.get(), "step", H5T_STD_I64LE, H5T_NATIVE_INT64, &s, path);
      io.attribute(group.get(), "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &time, path);
      if (failure) io.string_attribute(group.get(), "message", message, path);
      XdmfGrid grid{failure ? "failure" : name, path, "", step, time, points == kNone ? 0 : points, fields};
      const bool drawable = grid.points > 0 && std::any_of(fields.begin(), fields.end(), [](const XdmfField& f) {
                              return f.name == "position";
                            });
      if (drawable && options.write_xdmf) grid.connectivity = ensure_connectivity(grid.points);
      if (failure && H5Lexists(file.get(), "failure", H5P_DEFAULT) > 0) {
        check(H5Ldelete(file.get(), "failure", H5P_DEFAULT), io.file, "cannot replace /failure");
      }
      check(H5Olink(group.get(), failure ? file.get() : snapshots.get(), failure ? "failure" : name, H5P_DEFAULT,
                    H5P_DEFAULT),
            io.file, "cannot link " + path);
      write_pending();
      flush_file();
      discard_snapshot();  // closes the (now linked) group and lifts the eviction hold
      if (drawable && options.write_xdmf) {
        XdmfGrid reference = grid;
        reference.geometry = "initial_position";
        const bool has_reference = std::any_of(grid.fields.begin(), grid.fields.end(), [&](const XdmfField& f) {
          return f.name == reference.geometry && f.components == dim && !f.integer;
        });
        if (!failure) {
          grid_xml.push_back(xdmf_grid_xml(grid, io_name(), dim));
          if (has_reference) reference_xml.push_back(xdmf_grid_xml(reference, io_name(), dim));
          last_time = time;
        } else {
          failure_xml = time > last_time ? xdmf_grid_xml(grid, io_name(), dim) : std::string();
          reference_failure_xml =
              time > last_time && has_reference ? xdmf_grid_xml(reference, io_name(), dim) : std::string();
        }
      }
      if (!failure) ++count;
    } catch (...) {
      discard_snapshot();
      throw;
    }
    write_xdmf();
  }

  std::string io_name() const { return base_name(final_path); }

  void metadata(const std::string& key, hid_t type, const void* value, std::size_t bytes) {
    check_name(key, "metadata");
    const Scoped held(*this);
    if (H5Lexists(meta.get(), key.c_str(), H5P_DEFAULT) > 0) {
      check(H5Ldelete(meta.get(), key.c_str(), H5P_DEFAULT), io.file, "cannot replace /meta/" + key);
    }
    const Handle d = io.scalar_dataset(meta.get(), key, type, value, bytes, "/meta/" + key);
    io.describe(d.get(), key, dim, H5Tget_class(type) == H5T_STRING, "/meta/" + key);
    flush_file();
  }

  // /meta/<key> as a small 1-D dataset (numbers or fixed-length strings).
  void metadata_array(const std::string& key, hid_t type, const void* values, std::size_t n, bool text) {
    check_name(key, "metadata");
    const Scoped held(*this);
    if (H5Lexists(meta.get(), key.c_str(), H5P_DEFAULT) > 0) {
      check(H5Ldelete(meta.get(), key.c_str(), H5P_DEFAULT), io.file, "cannot replace /meta/" + key);
    }
    const Handle d = io.array_dataset(meta.get(), key, type, values, n, "/meta/" + key);
    io.describe(d.get(), key, dim, text, "/meta/" + key);
    flush_file();
  }
};

H5Output::H5Output(const std::string& path, int dim, H5OutputOptions options) : impl_(std::make_unique<Impl>()) {
  if (dim != 2 && dim != 3) throw std::invalid_argument("H5Output: dim must be 2 or 3");
  if (options.series_batch_rows == 0) options.series_batch_rows = 1;
  Impl& m = *impl_;
  m.final_path = path;
  m.io.file = options.via_temporary ? temporary_path(path) : path;
  m.xdmf_path = xdmf_path_for(path);
  m.reference_path = xdmf_reference_path_for(path);
  m.dim = dim;
  m.options = options;
  const Quiet quiet;
  const Io& io = m.io;
  Handle fcpl{check_id(H5Pcreate(H5P_FILE_CREATE), path, "cannot create a property list"), H5Pclose};
  check(H5Pset_file_space_strategy(fcpl.get(), H5F_FSPACE_STRATEGY_NONE, 0, 1), path, "cannot set file space strategy");
  check(H5Pset_link_creation_order(fcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED), path,
        "cannot track creation order");
  Handle fapl{check_id(H5Pcreate(H5P_FILE_ACCESS), path, "cannot create a property list"), H5Pclose};
  check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_LATEST), path, "cannot set format bounds");
  const unsigned mode = options.via_temporary ? H5F_ACC_EXCL : H5F_ACC_TRUNC;  // EXCL: never truncate another's file
  m.file = Handle{check_id(H5Fcreate(m.io.file.c_str(), mode, fcpl.get(), fapl.get()), m.io.file, "cannot create the file"),
                  H5Fclose};
  m.cache.version = H5AC__CURR_CACHE_CONFIG_VERSION;
  check(H5Fget_mdc_config(m.file.get(), &m.cache), path, "cannot read the metadata cache configuration");
  m.cache.incr_mode = H5C_incr__off;
  m.cache.flash_incr_mode = H5C_flash_incr__off;
  m.cache.decr_mode = H5C_decr__off;
  m.cache.set_initial_size = true;
  m.cache.initial_size = std::clamp<std::size_t>(4u << 20, m.cache.min_size, m.cache.max_size);
  m.set_evictions(true);
  m.cache.set_initial_size = false;

  const std::int32_t version = 2, d = dim;  // 2: vectors (n, 3) and stress (n, 9) in 2D too; steps, ids, counts int64
  io.string_attribute(m.file.get(), "format", "frictherm-output", "/");
  io.attribute(m.file.get(), "format_version", H5T_STD_I32LE, H5T_NATIVE_INT32, &version, "/");
  io.attribute(m.file.get(), "dim", H5T_STD_I32LE, H5T_NATIVE_INT32, &d, "/");
  m.meta = io.group(m.file.get(), "meta", "/meta");
  m.snapshots = io.group(m.file.get(), "snapshots", "/snapshots");
  m.flush_file();
  m.write_xdmf();  // an empty collection; also proves early that the XDMF file can be written (not via_temporary)
}

void hdf5_program_setup() {
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

H5Output::~H5Output() {
  if (!impl_ || impl_->closed) return;
  try {
    close();
  } catch (const std::exception& e) {
    std::cerr << "frictherm: closing output: " << e.what() << '\n';
  }
}

H5Output::H5Output(H5Output&&) noexcept = default;
H5Output& H5Output::operator=(H5Output&&) noexcept = default;

H5Output::Impl& H5Output::live() const {
  if (!impl_ || impl_->closed) throw std::logic_error("H5Output: the output file is closed");
  return *impl_;
}

void H5Output::write_metadata(const std::string& key, const std::string& value) {
  Impl& m = live();
  const Quiet quiet;
  const Handle t = m.io.string_type(value.size());
  m.metadata(key, t.get(), value.c_str(), value.size());
}

void H5Output::write_metadata(const std::string& key, double value) {
  Impl& m = live();
  const Quiet quiet;
  m.metadata(key, H5T_IEEE_F64LE, &value, sizeof value);
}

void H5Output::write_metadata(const std::string& key, const std::vector<double>& values) {
  Impl& m = live();
  const Quiet quiet;
  m.metadata_array(key, H5T_IEEE_F64LE, values.data(), values.size(), false);
}

void H5Output::write_metadata(const std::string& key, const std::vector<std::int64_t>& values) {
  Impl& m = live();
  const Quiet quiet;
  m.metadata_array(key, H5T_STD_I64LE, values.data(), values.size(), false);
}

void H5Output::write_metadata(const std::string& key, const std::vector<std::string>& values) {
  Impl& m = live();
  const Quiet quiet;
  std::size_t longest = 1;
  for (const auto& v : values) longest = std::max(longest, v.size());
  std::string packed(values.size() * longest, '\0');  // fixed-length, NUL-padded
  for (std::size_t i = 0; i < values.size(); ++i) packed.replace(i * longest, values[i].size(), values[i]);
  const Handle t = m.io.string_type(longest);
  m.metadata_array(key, t.get(), packed.data(), values.size(), true);
}

void H5Output::write_integer_metadata(const std::string& key, std::int64_t value) {
  Impl& m = live();
  const Quiet quiet;
  m.metadata(key, H5T_NATIVE_INT64, &value, sizeof value);
}

bool H5Output::is_count_column(const std::string& name) {
  static const std::set<std::string> exact{"step", "id", "fate", "seed", "status", "steps", "runaway", "dying",
                                           "material_mask", "hotspots"};
  auto ends_with = [&name](const std::string& tail) {
    return name.size() >= tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (name.rfind("penalty_contacts.", 0) == 0) return true;
  if (name.find('.') != std::string::npos) return false;  // per-body or per-pair columns carry user names
  return exact.count(name) > 0 || ends_with("_count") || ends_with("_nodes") || ends_with("_windows");
}

void H5Output::begin_snapshot(long step, double time) {
  Impl& m = live();
  const Quiet quiet;
  m.begin(Impl::Kind::snapshot, step, time);
}

void H5Output::begin_failure(long step, double time, const std::string& message) {
  Impl& m = live();
  const Quiet quiet;
  m.discard_snapshot();
  m.begin(Impl::Kind::failure, step, time);
  m.message = message.size() > 16384 ? message.substr(0, 16384) : message;
}

void H5Output::snapshot_field(const std::string& name, const double* data, std::size_t n, int components) {
  Impl& m = live();
  const Quiet quiet;
  m.field(name, false, data, n, components);
}

void H5Output::snapshot_field(const std::string& name, const std::int32_t* data, std::size_t n) {
  Impl& m = live();
  const Quiet quiet;
  m.field(name, true, data, n, 1);
}

void H5Output::end_snapshot() {
  Impl& m = live();
  const Quiet quiet;
  m.end();
}

bool H5Output::in_snapshot() const { return impl_ && impl_->kind != Impl::Kind::none; }

void H5Output::declare_series(const std::vector<std::string>& names) {
  Impl& m = live();
  if (!m.series_names.empty()) throw std::logic_error("H5Output: series already declared");
  if (names.empty() || names.front() != "time") {
    throw std::invalid_argument("series columns must start with \"time\"");
  }
  m.create_columns("series", names, "series column", m.series, m.series_sets);
  m.series_names = names;
}

void H5Output::append_series(const std::vector<double>& row) {
  Impl& m = live();
  if (m.series_names.empty()) throw std::logic_error("H5Output: append_series before declare_series");
  if (row.size() != m.series_names.size()) {
    throw std::invalid_argument("series row has " + std::to_string(row.size()) + " values, " +
                                std::to_string(m.series_names.size()) + " columns declared");
  }
  m.pending.insert(m.pending.end(), row.begin(), row.end());
  if (m.pending.size() >= m.options.series_batch_rows * row.size()) flush();
}

// ---- extra tables (declare_table / append_table_row) ----
void H5Output::declare_table(const std::string& name, const std::vector<std::string>& columns) {
  Impl& m = live();
  check_name(name, "table");
  if (name == "meta" || name == "snapshots" || name == "series" || name == "failure" || name == "xdmf" ||
      m.tables.count(name) != 0)
    throw std::logic_error("H5Output: table /" + name + " already exists or is reserved");
  if (columns.empty()) throw std::invalid_argument("table /" + name + " needs at least one column");
  Impl::Table t;
  m.create_columns(name, columns, "table column", t.group, t.sets);
  t.names = columns;
  m.tables.emplace(name, std::move(t));
}

void H5Output::append_table_row(const std::string& name, const std::vector<double>& row) {
  Impl& m = live();
  const auto it = m.tables.find(name);
  if (it == m.tables.end()) throw std::logic_error("H5Output: append_table_row before declare_table(" + name + ")");
  Impl::Table& t = it->second;
  if (row.size() != t.names.size())
    throw std::invalid_argument("table /" + name + " row has " + std::to_string(row.size()) + " values, " +
                                std::to_string(t.names.size()) + " columns declared");
  t.pending.insert(t.pending.end(), row.begin(), row.end());
  if (t.pending.size() >= m.options.series_batch_rows * row.size()) flush();
}

std::size_t H5Output::table_rows(const std::string& name) const {
  if (!impl_) return 0;
  const auto it = impl_->tables.find(name);
  if (it == impl_->tables.end() || it->second.names.empty()) return 0;
  return it->second.written + it->second.pending.size() / it->second.names.size();
}
// ---- end of extra tables ----

std::size_t H5Output::series_rows() const {
  if (!impl_) return 0;
  const Impl& m = *impl_;
  return m.series_names.empty() ? 0 : m.series_written + m.pending.size() / m.series_names.size();
}

void H5Output::flush() {
  Impl& m = live();
  const Quiet quiet;
  const Impl::Scoped hold(m);
  m.write_pending();
  m.flush_file();
}

void H5Output::sync() {
  flush();
  Impl& m = live();
  void* handle = nullptr;
  check(H5Fget_vfd_handle(m.file.get(), H5P_DEFAULT, &handle), m.io.file, "cannot get the file's descriptor");
  if (handle != nullptr && ::fsync(*static_cast<int*>(handle)) != 0)
    throw std::runtime_error("HDF5 file '" + m.io.file + "': cannot make the written rows durable (fsync: " +
                             std::strerror(errno) + ")");
}

void H5Output::abandon() noexcept {
  if (!impl_ || impl_->closed) return;
  Impl& m = *impl_;
  const Quiet quiet;
  m.discard_snapshot();
  m.series_sets.clear();
  m.tables.clear();
  m.series.reset();
  m.snapshots.reset();
  m.meta.reset();
  m.file.reset();
  m.closed = true;
}

void H5Output::close() {
  Impl& m = live();
  m.discard_snapshot();
  flush();
  m.write_xdmf();
  const Quiet quiet;
  m.series_sets.clear();
  m.tables.clear();
  m.series.reset();
  m.snapshots.reset();
  m.meta.reset();
  m.file.reset();
  m.closed = true;
  if (m.io.file != m.final_path) m.publish();
}

std::size_t H5Output::snapshot_count() const { return impl_ ? impl_->count : 0; }
const std::string& H5Output::path() const { return impl_->final_path; }
const std::string& H5Output::live_path() const { return impl_->io.file; }
const std::string& H5Output::xdmf_path() const { return impl_->xdmf_path; }
int H5Output::dim() const { return impl_->dim; }

}  // namespace frictherm::coupling
