#pragma once
// Reading the /series table of a run written by H5Output, and its CSV export (what
// `frictherm export-csv` prints).
#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

namespace frictherm::coupling {

/// The /series table of a finished or crashed run, columns in declared order.
struct SeriesTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  // columns[j][row]; all the same length
  std::size_t rows() const { return columns.empty() ? 0 : columns.front().size(); }
};

/// Reads /series of `h5_path`. A file without /series yields an empty table. Columns come in the
/// order of the `columns` attribute of /series (files from other writers: by name, "time"
/// first). Columns of unequal length are cut to the shortest. Throws std::runtime_error naming the
/// file and object on any HDF5 failure.
SeriesTable read_series(const std::string& h5_path);
/// The same for any column group written like /series (e.g. "hotspots"); empty when absent.
SeriesTable read_table(const std::string& h5_path, const std::string& group);

/// Header line of column names, then one line per row. Numbers are written in the shortest form
/// that reads back to the same double ("nan", "inf", "-inf" for non-finite values). Names holding
/// ',', '"' or a line break are quoted (RFC 4180).
void write_series_csv(const SeriesTable& table, std::ostream& out);

/// read_series + write_series_csv. A run without series writes nothing. Throws
/// std::runtime_error naming the file on an HDF5 failure or when `out` fails.
void export_series_csv(const std::string& h5_path, std::ostream& out);

}  // namespace frictherm::coupling
