// Reading run and ensemble files back (results.hpp).
#include <frictherm/coupling/results.hpp>

#include <hdf5.h>

#include "output/h5_util.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace frictherm::coupling {

using h5detail::check;
using h5detail::check_id;
using h5detail::fail;
using h5detail::Handle;
using h5detail::Quiet;

bool SeriesTable::has(const std::string& name) const {
  return std::find(names.begin(), names.end(), name) != names.end();
}

const std::vector<double>& SeriesTable::column(const std::string& name) const {
  for (std::size_t j = 0; j < names.size(); ++j)
    if (names[j] == name) return columns[j];
  std::string all;
  for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
  throw std::out_of_range("no column '" + name + "' (columns: " + (all.empty() ? "none" : all) + ")");
}

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

namespace {

// /meta/<key> opened, or an error naming the file and key.
Handle open_meta(const Handle& f, const std::string& h5_path, const std::string& key) {
  const std::string path = "/meta/" + key;
  if (H5Lexists(f.get(), "meta", H5P_DEFAULT) <= 0 || H5Lexists(f.get(), path.c_str(), H5P_DEFAULT) <= 0)
    fail(h5_path, "no metadata " + path);
  return {check_id(H5Dopen2(f.get(), path.c_str(), H5P_DEFAULT), h5_path, "cannot open " + path), H5Dclose};
}

}  // namespace

double read_metadata_number(const std::string& h5_path, const std::string& key) {
  const Quiet quiet;
  const Handle f{check_id(H5Fopen(h5_path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), h5_path, "cannot open the file"),
                 H5Fclose};
  const Handle d = open_meta(f, h5_path, key);
  const Handle t{check_id(H5Dget_type(d.get()), h5_path, "cannot read the type of /meta/" + key), H5Tclose};
  const H5T_class_t c = H5Tget_class(t.get());
  if (c != H5T_INTEGER && c != H5T_FLOAT) fail(h5_path, "/meta/" + key + " is not a number");
  double v = 0.0;
  check(H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &v), h5_path, "cannot read /meta/" + key);
  return v;
}

std::string read_metadata_string(const std::string& h5_path, const std::string& key) {
  const Quiet quiet;
  const Handle f{check_id(H5Fopen(h5_path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), h5_path, "cannot open the file"),
                 H5Fclose};
  const Handle d = open_meta(f, h5_path, key);
  const Handle t{check_id(H5Dget_type(d.get()), h5_path, "cannot read the type of /meta/" + key), H5Tclose};
  if (H5Tget_class(t.get()) != H5T_STRING || H5Tis_variable_str(t.get()) > 0)
    fail(h5_path, "/meta/" + key + " is not a fixed-length string");
  std::string v(H5Tget_size(t.get()), '\0');
  check(H5Dread(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), h5_path, "cannot read /meta/" + key);
  v.resize(std::min(v.size(), v.find('\0')));
  return v;
}

}  // namespace frictherm::coupling
