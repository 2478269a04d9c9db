#include <frictherm/coupling/csv_export.hpp>

#include <hdf5.h>

#include "h5_util.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <ostream>
#include <stdexcept>

namespace frictherm::coupling {
namespace {

using h5detail::check;
using h5detail::check_id;
using h5detail::fail;
using h5detail::Handle;
using h5detail::Quiet;

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

SeriesTable read_series(const std::string& h5_path) { return read_table(h5_path, "series"); }

SeriesTable read_table(const std::string& h5_path, const std::string& group) {
  const Quiet quiet;
  SeriesTable table;
  const std::string at = "/" + group;
  const Handle f{check_id(H5Fopen(h5_path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), h5_path, "cannot open the file"),
                 H5Fclose};
  if (H5Lexists(f.get(), group.c_str(), H5P_DEFAULT) <= 0) return table;
  const Handle g{check_id(H5Gopen2(f.get(), group.c_str(), H5P_DEFAULT), h5_path, "cannot open " + at), H5Gclose};
  if (H5Aexists(g.get(), "columns") > 0) {
    const std::string attr = at + " attribute columns";
    const Handle a{check_id(H5Aopen(g.get(), "columns", H5P_DEFAULT), h5_path, "cannot open " + attr), H5Aclose};
    const Handle t{check_id(H5Aget_type(a.get()), h5_path, "cannot read the type of " + attr), H5Tclose};
    const Handle s{check_id(H5Aget_space(a.get()), h5_path, "cannot read " + attr), H5Sclose};
    const std::size_t size = H5Tget_size(t.get());
    const hssize_t count = H5Sget_simple_extent_npoints(s.get());
    if (H5Tget_class(t.get()) != H5T_STRING || H5Tis_variable_str(t.get()) > 0 || size == 0 || count < 0) {
      fail(h5_path, attr + " is not a fixed-length string array");
    }
    std::string packed(size * static_cast<std::size_t>(count), '\0');
    check(H5Aread(a.get(), t.get(), packed.data()), h5_path, "cannot read " + attr);
    for (hssize_t i = 0; i < count; ++i) {
      std::string name = packed.substr(static_cast<std::size_t>(i) * size, size);
      name.resize(std::min(name.size(), name.find('\0')));
      table.names.push_back(name);
    }
  } else {  // a file not written by H5Output: every dataset, "time" first
    hsize_t idx = 0;
    check(H5Literate(g.get(), H5_INDEX_NAME, H5_ITER_INC, &idx,
                     [](hid_t, const char* name, const H5L_info_t*, void* out) -> herr_t {
                       static_cast<std::vector<std::string>*>(out)->emplace_back(name);
                       return 0;
                     },
                     &table.names),
          h5_path, "cannot list " + at);
    std::stable_partition(table.names.begin(), table.names.end(), [](const std::string& n) { return n == "time"; });
  }
  std::size_t rows = std::numeric_limits<std::size_t>::max();
  for (const auto& name : table.names) {
    const std::string where = at + "/" + name;
    const Handle d{check_id(H5Dopen2(g.get(), name.c_str(), H5P_DEFAULT), h5_path, "cannot open " + where), H5Dclose};
    const Handle s{check_id(H5Dget_space(d.get()), h5_path, "cannot read the shape of " + where), H5Sclose};
    const hssize_t n = H5Sget_simple_extent_npoints(s.get());
    if (n < 0 || H5Sget_simple_extent_ndims(s.get()) != 1) fail(h5_path, where + " is not a 1-D dataset");
    std::vector<double> column(static_cast<std::size_t>(n));
    if (n > 0) {
      check(H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, column.data()), h5_path,
            "cannot read " + where);
    }
    rows = std::min(rows, column.size());
    table.columns.push_back(std::move(column));
  }
  for (auto& c : table.columns) c.resize(rows);
  return table;
}

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
