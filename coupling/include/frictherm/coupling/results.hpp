#pragma once
// Reading results back: the column tables of a run file written by H5Output (/series, /hotspots,
// /hotspot_fates) or of an ensemble file (/members, /hotspots), and its metadata.
//
//   RunResult r = run_scene(load_scene("scene.json"), options);
//   SeriesTable s = read_series(r.output);
//   const std::vector<double>& ke = s.column("kinetic_energy");
//   double heat = read_metadata_number(r.output, "heat_delivered");
//
// Python: the `frictherm` package (python/frictherm, docs/python.md) reads the same files.
#include <cstddef>
#include <string>
#include <vector>

namespace frictherm::coupling {

/// The /series table of a finished or crashed run, columns in declared order.
struct SeriesTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  // columns[j][row]; all the same length (counts as exact doubles)
  std::size_t rows() const { return columns.empty() ? 0 : columns.front().size(); }
  bool has(const std::string& name) const;
  /// The column called `name`; throws std::out_of_range naming it and the columns there are.
  const std::vector<double>& column(const std::string& name) const;
};

/// Reads /series of `h5_path`. A file without /series yields an empty table. Columns come in the
/// order of the `columns` attribute of /series (files from other writers: by name, "time"
/// first). Columns of unequal length are cut to the shortest. Throws std::runtime_error naming the
/// file and object on any HDF5 failure.
SeriesTable read_series(const std::string& h5_path);
/// The same for any column group written like /series (e.g. "hotspots"); empty when absent.
SeriesTable read_table(const std::string& h5_path, const std::string& group);

/// A number in /meta (a double or an integer dataset) of a run file; throws std::runtime_error naming
/// the file and key when it is missing or not a number.
double read_metadata_number(const std::string& h5_path, const std::string& key);
/// A string in /meta; throws std::runtime_error naming the file and key when missing or not a string.
std::string read_metadata_string(const std::string& h5_path, const std::string& key);

}  // namespace frictherm::coupling
