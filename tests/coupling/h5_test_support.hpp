#pragma once
// Reading one dataset of a run's HDF5 file in tests, doubles or a string (empty when the file or path
// is absent).
#include <hdf5.h>

#include <string>
#include <vector>

namespace frictherm::test {

inline std::vector<double> read_doubles(const std::string& file, const std::string& path) {
  std::vector<double> out;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return out;
  const hid_t d = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
  if (d >= 0) {
    const hid_t sp = H5Dget_space(d);
    out.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(sp)));
    if (!out.empty()) H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
    H5Sclose(sp);
    H5Dclose(d);
  }
  H5Fclose(f);
  return out;
}

/// The names of the links in `group` of `file`, in name order (empty when the file is absent).
inline std::vector<std::string> names_in(const std::string& file, const std::string& group) {
  std::vector<std::string> names;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return names;
  auto add = [](hid_t, const char* name, const H5L_info_t*, void* out) -> herr_t {
    static_cast<std::vector<std::string>*>(out)->emplace_back(name);
    return 0;
  };
  hsize_t idx = 0;
  H5Literate_by_name(f, group.c_str(), H5_INDEX_NAME, H5_ITER_INC, &idx, add, &names, H5P_DEFAULT);
  H5Fclose(f);
  return names;
}

/// A string dataset (/meta/status, /meta/failure, /meta/run_id) or a checkpoint's text (an array of
/// chars: /marks/run_id), "" when absent.
inline std::string read_text(const std::string& file, const std::string& path) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return "";
  std::string s;
  if (const hid_t d = H5Dopen2(f, path.c_str(), H5P_DEFAULT); d >= 0) {
    const hid_t t = H5Dget_type(d);
    if (H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) <= 0) {
      s.assign(H5Tget_size(t), '\0');
      H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.data());
      s.resize(s.find('\0') == std::string::npos ? s.size() : s.find('\0'));
    } else if (H5Tget_class(t) == H5T_INTEGER && H5Tget_size(t) == 1) {
      const hid_t sp = H5Dget_space(d);
      s.assign(static_cast<std::size_t>(H5Sget_simple_extent_npoints(sp)), '\0');
      if (!s.empty()) H5Dread(d, H5T_NATIVE_CHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.data());
      H5Sclose(sp);
    }
    H5Tclose(t);
    H5Dclose(d);
  }
  H5Fclose(f);
  return s;
}

}  // namespace frictherm::test
