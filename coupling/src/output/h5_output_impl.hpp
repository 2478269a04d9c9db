// H5Output's state and the steps its public calls are made of. Three files, one job each:
//   h5_output.cpp            the file (creation, metadata cache, crash-safety rules), /meta, closing
//   h5_output_columns.cpp    /series and the extra tables (extendible columns, buffered rows)
//   h5_output_snapshots.cpp  /snapshots, /failure, /nodes and the XDMF files beside the result
#pragma once

#include <frictherm/coupling/h5_output.hpp>
#include <frictherm/coupling/xdmf.hpp>

#include <hdf5.h>

#include "output/h5_io.hpp"
#include "output/h5_util.hpp"

#include <cstddef>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace frictherm::coupling {

struct H5Output::Impl {
  static constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  using Handle = h5detail::Handle;

  h5detail::Io io;         // io.file: the file being written
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
  // The thermal grid's nodes of the snapshot being written (/nodes/<number>, node_field), anonymous
  // until end_snapshot as the snapshot is; node_points is kNone while it has no field.
  Handle nodes, node_group;
  std::size_t node_points = kNone;
  std::vector<XdmfField> node_fields;

  std::size_t count = 0;
  std::vector<std::string> grid_xml;
  std::string failure_xml;
  // RUN_reference.xdmf: the same snapshots drawn at the reference positions X (`initial_position`),
  // for ParaView's Warp By Vector on `displacement`; written once a snapshot has that field.
  std::string reference_path;
  std::vector<std::string> reference_xml;
  std::string reference_failure_xml;
  // RUN_nodes.xdmf (collection "thermal_nodes"): the thermal grid's nodes of each snapshot that has them.
  std::string nodes_path;
  std::vector<std::string> node_xml;
  double last_time = -std::numeric_limits<double>::infinity();
  std::set<std::size_t> connectivity;

  std::vector<std::string> series_names;
  std::vector<Handle> series_sets;
  std::vector<double> pending;  // row-major rows not yet written
  hsize_t series_written = 0;

  // Evictions off while anything is modified between two flushes (h5_output.cpp, top of the file).
  void set_evictions(bool on) {
    cache.evictions_enabled = on;
    h5detail::check(H5Fset_mdc_config(file.get(), &cache), io.file, "cannot configure the metadata cache");
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

  void flush_file() { h5detail::check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), io.file, "cannot flush"); }
  std::string io_name() const { return h5detail::base_name(final_path); }

  // ---- series and extra tables (h5_output_columns.cpp) ----
  // /<name> with a `columns` attribute and one extendible 1-D double dataset per column (series, tables).
  void create_columns(const std::string& name, const std::vector<std::string>& columns, const char* what,
                      Handle& group_out, std::vector<Handle>& sets);
  // Extra append-only tables /<name>/<column> (hot spots, coupling), written with the series.
  struct Table {
    Handle group;
    std::vector<std::string> names;
    std::vector<Handle> sets;
    std::vector<double> pending;  // row-major rows not yet written
    hsize_t written = 0;
  };
  std::map<std::string, Table> tables;
  void write_table(const std::string& name, Table& t);
  void write_pending();  // buffered table and series rows

  // ---- snapshots and XDMF (h5_output_snapshots.cpp) ----
  // Written under the final names after every snapshot; through a temporary the XDMF files are
  // written only with the result (publish): until then they would describe a file that is not
  // under the name they give (issue 34: a second run had relabelled the first run's snapshots).
  // Every open handle closed, the file last (close and abandon).
  void close_handles() noexcept {
    series_sets.clear();
    tables.clear();
    series.reset();
    nodes.reset();
    snapshots.reset();
    meta.reset();
    file.reset();
    closed = true;
  }
  std::string given_xdmf;  // publish_xdmf_with_result: published with the result (write_xdmf off)
  std::string given_reference_xdmf;  // and its reference document ("" if none)
  std::string given_nodes_xdmf;      // and its thermal nodes' document ("" if none)
  void write_xdmf();
  // The result renamed onto its name with its XDMF files (publish_with_xdmf, output_files.hpp).
  void publish();
  static std::string document(std::vector<std::string> grids, const std::string& failure, const std::string& name);
  bool has_reference() const { return !reference_xml.empty() || !reference_failure_xml.empty(); }
  void discard_snapshot() noexcept;
  void begin(Kind k, long s, double t);
  void field(const std::string& name, bool integer, const void* data, std::size_t n, int components);
  void node_field(const std::string& name, bool integer, const void* data, std::size_t n, int components);
  // Creates the dataset `name` (n x components, int32 or float64) in `g` with units and long_name.
  void write_dataset(hid_t g, const std::string& name, bool integer, const void* data, std::size_t n, int components,
                     const std::string& where);
  std::string ensure_connectivity(std::size_t n);
  void end();

  // ---- /meta (h5_output.cpp) ----
  void metadata(const std::string& key, hid_t type, const void* value, std::size_t bytes);
  // /meta/<key> as a small 1-D dataset (numbers or fixed-length strings).
  void metadata_array(const std::string& key, hid_t type, const void* values, std::size_t n, bool text);
};

}  // namespace frictherm::coupling
