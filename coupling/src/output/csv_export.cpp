#include <frictherm/coupling/csv_export.hpp>

#include "output/h5_util.hpp"

#include <charconv>
#include <cmath>
#include <ostream>
#include <stdexcept>

namespace frictherm::coupling {
namespace {

std::string csv_name(const std::string& name) {
  if (name.find_first_of(",\"\r\n") == std::string::npos) return name;
  std::string quoted = "\"";
  for (const char c : name) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + '"';
}

void put_number(std::ostream& out, double value) {
  if (std::isnan(value)) {
    out << "nan";
  } else if (std::isinf(value)) {
    out << (value > 0 ? "inf" : "-inf");
  } else {
    char buf[64];
    const auto result = std::to_chars(buf, buf + sizeof buf, value);
    out.write(buf, result.ptr - buf);
  }
}

}  // namespace

void write_series_csv(const SeriesTable& table, std::ostream& out) {
  if (table.names.empty()) return;
  for (std::size_t j = 0; j < table.names.size(); ++j) out << (j ? "," : "") << csv_name(table.names[j]);
  out << '\n';
  const std::size_t rows = table.rows();
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t j = 0; j < table.columns.size(); ++j) {
      if (j) out << ',';
      put_number(out, table.columns[j][r]);
    }
    out << '\n';
  }
}

void export_series_csv(const std::string& h5_path, std::ostream& out) {
  const bool hdf5 = [&] {
    const h5detail::Quiet quiet;
    return H5Fis_hdf5(h5_path.c_str()) > 0;
  }();
  if (!hdf5)
    throw std::runtime_error("'" + h5_path + "' is not an HDF5 file; export-csv reads a result of frictherm run (RUN.h5)");
  const SeriesTable table = read_series(h5_path);
  if (table.names.empty()) {  // issue 34: a foreign file or a checkpoint gave exit code 0 and nothing written
    bool checkpoint = false, result = false;
    {
      const h5detail::Quiet quiet;
      const h5detail::Handle f{H5Fopen(h5_path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
      checkpoint = f.get() >= 0 && H5Lexists(f.get(), "mechanics", H5P_DEFAULT) > 0 && H5Lexists(f.get(), "marks", H5P_DEFAULT) > 0;
      result = f.get() >= 0 && H5Aexists(f.get(), "format") > 0 && H5Lexists(f.get(), "meta", H5P_DEFAULT) > 0;
    }
    if (result && !checkpoint) return;  // a result without series rows: nothing to write
    throw std::runtime_error("'" + h5_path + "' has no time series (/series): " +
                             (checkpoint ? "it is a checkpoint (read by frictherm resume and continue); export the result it belongs to"
                                         : "not a result of frictherm run"));
  }
  write_series_csv(table, out);
  out.flush();
  if (!out) throw std::runtime_error("export of the series of '" + h5_path + "': writing the CSV failed");
}

}  // namespace frictherm::coupling
