#pragma once
// The CSV export of a run's /series table (what `frictherm export-csv` prints). Reading the table
// itself: frictherm/coupling/results.hpp (included here for older code).
#include <frictherm/coupling/results.hpp>

#include <iosfwd>
#include <string>

namespace frictherm::coupling {

/// Header line of column names, then one line per row. Numbers are written in the shortest form
/// that reads back to the same double ("nan", "inf", "-inf" for non-finite values). Names holding
/// ',', '"' or a line break are quoted (RFC 4180).
void write_series_csv(const SeriesTable& table, std::ostream& out);

/// read_series + write_series_csv. A run without series writes nothing. Throws
/// std::runtime_error naming the file on an HDF5 failure, when `out` fails, and for a file that is
/// not HDF5, a checkpoint or another program's HDF5 file (issue 34: they had given nothing, exit 0).
void export_series_csv(const std::string& h5_path, std::ostream& out);

}  // namespace frictherm::coupling
