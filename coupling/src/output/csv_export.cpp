#include <frictherm/coupling/csv_export.hpp>

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
  write_series_csv(read_series(h5_path), out);
  out.flush();
  if (!out) throw std::runtime_error("export of the series of '" + h5_path + "': writing the CSV failed");
}

}  // namespace frictherm::coupling
