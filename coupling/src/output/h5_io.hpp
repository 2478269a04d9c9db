// The dataset and attribute writers of the run output (h5_output.cpp): every error names the file.
#pragma once

#include <hdf5.h>

#include <frictherm/coupling/output_quantities.hpp>

#include "output/h5_util.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace frictherm::coupling::h5detail {

inline void check_name(const std::string& name, const char* kind) {
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..") {
    throw std::invalid_argument(std::string(kind) + " name '" + name +
                                "' is invalid: it must be non-empty and contain no '/'");
  }
}

struct Io {  // the file name every error message carries, plus small helpers
  std::string file;

  Handle space(int rank, const hsize_t* dims, const hsize_t* maxdims = nullptr) const {
    return {check_id(H5Screate_simple(rank, dims, maxdims), file, "cannot create a dataspace"), H5Sclose};
  }
  Handle scalar_space() const {
    return {check_id(H5Screate(H5S_SCALAR), file, "cannot create a dataspace"), H5Sclose};
  }
  Handle string_type(std::size_t size) const {
    Handle t{check_id(H5Tcopy(H5T_C_S1), file, "cannot create a string type"), H5Tclose};
    check(H5Tset_size(t.get(), std::max<std::size_t>(size, 1)), file, "cannot size a string type");
    check(H5Tset_strpad(t.get(), H5T_STR_NULLPAD), file, "cannot set string padding");
    check(H5Tset_cset(t.get(), H5T_CSET_UTF8), file, "cannot set string encoding");
    return t;
  }
  Handle group(hid_t loc, const std::string& name, const std::string& where) const {
    Handle gcpl{check_id(H5Pcreate(H5P_GROUP_CREATE), file, "cannot create a property list"), H5Pclose};
    check(H5Pset_link_creation_order(gcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED), file,
          "cannot track creation order");
    return {check_id(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), file,
                     "cannot create group " + where),
            H5Gclose};
  }
  void attribute(hid_t obj, const std::string& name, hid_t file_type, hid_t mem_type, const void* value,
                 const std::string& where) const {
    const Handle s = scalar_space();
    const Handle a{check_id(H5Acreate2(obj, name.c_str(), file_type, s.get(), H5P_DEFAULT, H5P_DEFAULT),
                            file, "cannot create attribute " + name + " of " + where),
                   H5Aclose};
    check(H5Awrite(a.get(), mem_type, value), file, "cannot write attribute " + name + " of " + where);
  }
  void string_attribute(hid_t obj, const std::string& name, const std::string& value,
                        const std::string& where) const {
    const Handle t = string_type(value.size());
    attribute(obj, name, t.get(), t.get(), value.c_str(), where);
  }
  // 1-D attribute of int32 values.
  void int_array_attribute(hid_t obj, const std::string& name, const std::vector<std::int32_t>& values,
                           const std::string& where) const {
    const hsize_t n = values.size();
    const Handle s = space(1, &n);
    const Handle a{check_id(H5Acreate2(obj, name.c_str(), H5T_STD_I32LE, s.get(), H5P_DEFAULT, H5P_DEFAULT), file,
                            "cannot create attribute " + name + " of " + where),
                   H5Aclose};
    check(H5Awrite(a.get(), H5T_NATIVE_INT32, values.data()), file, "cannot write attribute " + name + " of " + where);
  }
  // The attributes units and long_name of the dataset `obj` holding `name` (output_quantities.hpp),
  // and for categorical columns flag_values / flag_meanings (CF conventions). Text has units "".
  // A name the catalogue does not know gets no attributes.
  void describe(hid_t obj, const std::string& name, int dim, bool text, const std::string& where) const {
    std::optional<OutputQuantity> q = output_quantity(name, dim);
    if (text) q = OutputQuantity{"", q ? q->long_name : name, {}};
    if (!q) return;
    string_attribute(obj, "units", q->units, where);
    string_attribute(obj, "long_name", q->long_name, where);
    if (q->flags.empty()) return;
    std::vector<std::int32_t> codes;
    std::string meanings;
    for (const auto& [code, meaning] : q->flags) {
      codes.push_back(code);
      meanings += (meanings.empty() ? "" : " ") + meaning;
    }
    int_array_attribute(obj, "flag_values", codes, where);
    string_attribute(obj, "flag_meanings", meanings, where);
  }
  // Scalar dataset, compact (stored in its object header) when small.
  Handle scalar_dataset(hid_t loc, const std::string& name, hid_t type, const void* value, std::size_t bytes,
                        const std::string& where) const {
    Handle dcpl{check_id(H5Pcreate(H5P_DATASET_CREATE), file, "cannot create a property list"), H5Pclose};
    if (bytes < 16384) check(H5Pset_layout(dcpl.get(), H5D_COMPACT), file, "cannot set compact layout");
    const Handle s = scalar_space();
    Handle d{check_id(H5Dcreate2(loc, name.c_str(), type, s.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT), file,
                      "cannot create dataset " + where),
             H5Dclose};
    check(H5Dwrite(d.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, value), file, "cannot write dataset " + where);
    return d;
  }
  // 1-D dataset of `n` values of `type` (compact: small metadata arrays).
  Handle array_dataset(hid_t loc, const std::string& name, hid_t type, const void* values, std::size_t n,
                       const std::string& where) const {
    Handle dcpl{check_id(H5Pcreate(H5P_DATASET_CREATE), file, "cannot create a property list"), H5Pclose};
    check(H5Pset_layout(dcpl.get(), H5D_COMPACT), file, "cannot set compact layout");
    const hsize_t dims = n;
    const Handle s = space(1, &dims);
    Handle d{check_id(H5Dcreate2(loc, name.c_str(), type, s.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT), file,
                      "cannot create dataset " + where),
             H5Dclose};
    if (n > 0) check(H5Dwrite(d.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values), file, "cannot write dataset " + where);
    return d;
  }
};

inline std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace frictherm::coupling::h5detail
