#pragma once
// Reading one double dataset of a run's HDF5 file in tests (empty when the file or path is absent).
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

}  // namespace frictherm::test
