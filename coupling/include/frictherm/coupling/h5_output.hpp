#pragma once
// One HDF5 file per run, written so that a run that dies keeps what it already wrote.
//
// Layout (all datasets little-endian; names are the contract the plotting scripts rely on):
//   /                      attrs: format = "frictherm-output", format_version = 2, dim
//   /meta/<key>            scalar datasets: fixed-length UTF-8 strings, int64 (steps, counts) or doubles
//   /snapshots/000000 ...  one group per snapshot, attrs step (int64) and time (double);
//                          datasets (n) for one component, (n, components) otherwise
//   /failure               the state a failed run stopped in (same shape), attr message
//   /series/<column>       extendible 1-D datasets, /series/time first; attr columns on /series
//                          lists the column names in declared order. Count and id columns
//                          (is_count_column) are int64, every other column double.
//   /<table>/<column>      extra tables of the same layout (declare_table), e.g. /hotspots
// Format version 2 (frictherm 0.1, issue 14): integers (steps, ids, counts) are int64, in /meta
// and in tables; version 1 stored them as doubles. Readers: frictherm/coupling/results.hpp (C++),
// the Python package `frictherm` (python/frictherm).
//   /nodes/000000 ...      the thermal grid's nodes at snapshot 000000 ... (runs with heat; node_field):
//                          attrs step and time; position (n, dim) of the nodes that are thermal unknowns,
//                          temperature T_i (n) at the snapshot time, heat_capacity M_i (n), lattice
//                          (n, dim) int32 node coordinates i (position = grid lo + i * cell size);
//                          same numbering as /snapshots
//   /xdmf/polyvertex_<n>   int32 0..n-1, the Polyvertex connectivity the XDMF file points at
// Every dataset carries the attributes units (SI, temperatures K; "1" counts, "" text) and long_name
// (output_quantities.hpp); categorical columns (hot-spot fate) also flag_values and flag_meanings.
// Beside RUN.h5 an XDMF file RUN.xdmf (ParaView: Xdmf3ReaderS) lists every ended snapshot;
// RUN_reference.xdmf draws them at their reference positions and, when snapshots have /nodes,
// RUN_nodes.xdmf draws the thermal grid's nodes.
//
// Not thread-safe (the serial HDF5 library is not): use one thread for all output calls.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace frictherm::coupling {

struct H5OutputOptions {
  /// Series rows kept in memory before they are written (and the file flushed).
  std::size_t series_batch_rows = 64;
  /// Write RUN.xdmf beside RUN.h5 (rewritten after every ended snapshot; with via_temporary written
  /// once, with the result in close(), so that it never describes another file than the one named).
  bool write_xdmf = true;
  /// Write the file under a temporary name in the same folder ("<path>.<pid>.part", created
  /// exclusively, never truncating another file) and rename it onto `path` in close() (issue 15:
  /// a second run writing the same file cannot destroy the first one's). path() is the final name,
  /// live_path() the file being written; the XDMF file refers to the final name.
  bool via_temporary = false;
  /// With via_temporary: close() may replace an existing `path`. When false and `path` appeared
  /// meanwhile, close() keeps the result under live_path() and throws std::runtime_error saying so.
  bool replace_existing = true;
};

/// For a program rather than a library user, first thing in main (before any other HDF5 call): HDF5's
/// automatic error-stack dumps off (every failure becomes an exception that carries the library's own
/// description, h5_util.hpp), and no HDF5 clean-up at exit, where HDF5 1.10 crashes on a file whose
/// close failed (a full disk: exit code 139 after the run had reported the failure). Files are closed
/// by their owners before exit either way.
void hdf5_program_setup();

class H5Output {
 public:
  /// Creates or truncates `path` (or creates a temporary sibling, options.via_temporary). dim is 2 or 3. Throws std::runtime_error naming the file when it
  /// cannot be created (missing directory, no permission, ...).
  H5Output(const std::string& path, int dim, H5OutputOptions options = {});
  /// Calls close(); errors are reported on std::cerr, never thrown. An unfinished snapshot
  /// (begin_* without end_snapshot) is discarded.
  ~H5Output();
  H5Output(const H5Output&) = delete;
  H5Output& operator=(const H5Output&) = delete;
  H5Output(H5Output&&) noexcept;
  H5Output& operator=(H5Output&&) noexcept;

  /// Run metadata under /meta/<key> (key: no '/', not empty). Writing a key again replaces it.
  /// The file is flushed after each call.
  void write_metadata(const std::string& key, const std::string& value);
  void write_metadata(const std::string& key, double value);
  /// Small 1-D arrays under /meta/<key> (grid corners, cell counts, material names): doubles, int64
  /// or fixed-length UTF-8 strings.
  void write_metadata(const std::string& key, const std::vector<double>& values);
  void write_metadata(const std::string& key, const std::vector<std::int64_t>& values);
  void write_metadata(const std::string& key, const std::vector<std::string>& values);
  /// Integers (steps, counts) are stored as int64.
  void write_integer_metadata(const std::string& key, std::int64_t value);
  template <class I, std::enable_if_t<std::is_integral_v<I> && !std::is_same_v<I, bool>, int> = 0>
  void write_metadata(const std::string& key, I value) {
    write_integer_metadata(key, static_cast<std::int64_t>(value));
  }

  /// Starts particle snapshot number snapshot_count(). Fields follow, then end_snapshot().
  void begin_snapshot(long step, double time);
  /// n rows x components doubles, row-major. Conventional names: position (n x dim, required for
  /// the XDMF geometry), velocity, displacement (n x 3, z = 0 in 2D), stress (n x 9, the 3x3 tensor),
  /// mass, volume, temperature, ... The XDMF file calls 3 components a Vector, 9 a Tensor, 6 a
  /// Tensor6 (docs/output.md). Every field of one snapshot must have the same n.
  void snapshot_field(const std::string& name, const double* data, std::size_t n, int components);
  /// Integer per-particle field (material id, body id).
  void snapshot_field(const std::string& name, const std::int32_t* data, std::size_t n);
  /// The thermal grid's nodes at this snapshot (/nodes/<the snapshot's number>): n rows x components,
  /// like snapshot_field; every node field of one snapshot has the same n (independent of the particles'),
  /// and `position` (n x dim) is the geometry of RUN_nodes.xdmf's grid. Regular snapshots only
  /// (std::logic_error for the failure state); linked and flushed with the snapshot in end_snapshot.
  void node_field(const std::string& name, const double* data, std::size_t n, int components);
  void node_field(const std::string& name, const std::int32_t* data, std::size_t n, int components = 1);
  /// Links the snapshot into the file, writes pending series rows, flushes the file (H5Fflush)
  /// and rewrites the XDMF file (temporary file, then rename). Only ended snapshots are visible
  /// in the file: one interrupted mid-way is never half-present.
  void end_snapshot();
  /// Starts the failure snapshot /failure (fields as for begin_snapshot, then end_snapshot()).
  /// Discards an unfinished regular snapshot. A second failure replaces the first.
  void begin_failure(long step, double time, const std::string& message);
  bool in_snapshot() const;

  /// Declares the series columns once; names.front() must be "time".
  void declare_series(const std::vector<std::string>& names);
  /// One row, in declared column order. Buffered; written every series_batch_rows rows, at
  /// end_snapshot() and at flush().
  void append_series(const std::vector<double>& row);
  std::size_t series_rows() const;  // rows appended so far (written or buffered)

  /// An extra append-only table /<name>/<column> laid out like /series (extendible 1-D doubles, attr
  /// columns on the group), e.g. /hotspots. Rows are buffered and written with the series rows.
  void declare_table(const std::string& name, const std::vector<std::string>& columns);
  void append_table_row(const std::string& name, const std::vector<double>& row);
  std::size_t table_rows(const std::string& name) const;  // appended so far

  /// Columns of series and tables stored as int64 rather than double: step, id, fate, seed,
  /// status, steps, runaway, dying, material_mask, names ending in _count, _nodes, _windows, and
  /// hotspots (the per-member count of an ensemble), and penalty_contacts.* ; names holding a '.' other than
  /// penalty_contacts.* are double. Values given as doubles
  /// are rounded to the nearest integer when written.
  static bool is_count_column(const std::string& name);

  /// Writes buffered series rows and flushes the file to the operating system.
  void flush();
  /// flush() and then fsync(2): the rows and snapshots written so far are durable (a checkpoint that
  /// counts them is written after this). Throws std::runtime_error with the system's reason.
  void sync();
  /// Closes the file without writing anything more and without publishing it: after a write failed
  /// (a full disk), what was written stays under live_path(). Further calls throw std::logic_error.
  void abandon() noexcept;
  /// With via_temporary and write_xdmf false: `text` is the XDMF document published with the result
  /// in close() under xdmf_path_for(path()) (publish_with_xdmf), e.g. a decomposed run's OUT.xdmf that
  /// joins its rank files (issue 34: written with the result, never before it).
  /// `reference` (may be ""): RUN_reference.xdmf published with it (xdmf_reference_path_for);
  /// `nodes` (may be ""): RUN_nodes.xdmf (xdmf_nodes_path_for), the thermal grid's nodes.
  void publish_xdmf_with_result(std::string text, std::string reference = "", std::string nodes = "");
  /// Flushes, rewrites the XDMF file and closes the file. Further calls throw std::logic_error.
  void close();

  std::size_t snapshot_count() const;  // ended regular snapshots
  const std::string& path() const;       // the final name
  const std::string& live_path() const;  // the file being written (path() unless via_temporary)
  const std::string& xdmf_path() const;
  int dim() const;

 private:
  struct Impl;
  Impl& live() const;  // throws std::logic_error once closed or moved from
  std::unique_ptr<Impl> impl_;
};

}  // namespace frictherm::coupling
