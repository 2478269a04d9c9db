#pragma once
// Private: the HDF5 visitors of checkpoints (checkpoint.cpp). A visitor is called as v(name, member)
// for every member of a state (Simulation::visit_state, Coupler::visit_state, the run's marks); names
// with '/' make groups. Members: std::vector<T> (T double, int32, long, uint64 or a fixed-size Eigen
// type of doubles) stored n × components, and double, long, bool scalars stored as one-element
// datasets. `reading` tells a state whether it is being written (false) or restored (true), for
// members it must convert (Eigen::VectorXd, structures of nested vectors).
#include "output/h5_util.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace frictherm::coupling::ckpt {

/// 4: the energy books' stored-energy lead and the stress power it follows (energy_books.hpp);
/// 3: every non-empty dataset carries a Fletcher32 checksum (chunked), /reaction/enabled (issue 34);
/// 2: thermal coupler, penalty contact and output marks; 1: mechanics only. Serial and decomposed.
constexpr int kFormat = 4;
/// Why a checkpoint of an older format is refused (empty for a format this version never wrote).
inline std::string older_format_reason(long format) {
  if (format == 3)
    return "format 3 was written before the energy books kept the stored energy's lead over the velocities";
  if (format == 2) return "format 2 was written before checkpoints carried checksums";
  return "";
}
/// A checkpoint dataset is one chunk (and one checksum) up to this size, more chunks beyond.
constexpr hsize_t kChunkBytes = hsize_t{64} << 20;

namespace detail {

template <class T> struct Layout {  // fixed-size Eigen vector or matrix of doubles
  static_assert(std::is_same_v<typename T::Scalar, double>, "checkpoint: Eigen members must hold doubles");
  static_assert(sizeof(T) == sizeof(double) * T::SizeAtCompileTime, "checkpoint: padded Eigen type");
  static constexpr int components = T::SizeAtCompileTime;
  using Scalar = double;
  static hid_t type() { return H5T_NATIVE_DOUBLE; }
};
template <> struct Layout<double> {
  static constexpr int components = 1;
  using Scalar = double;
  static hid_t type() { return H5T_NATIVE_DOUBLE; }
};
template <> struct Layout<std::int32_t> {
  static constexpr int components = 1;
  using Scalar = std::int32_t;
  static hid_t type() { return H5T_NATIVE_INT32; }
};
template <> struct Layout<long> {
  static constexpr int components = 1;
  using Scalar = long;
  static hid_t type() { return H5T_NATIVE_LONG; }
};
template <> struct Layout<std::uint64_t> {
  static constexpr int components = 1;
  using Scalar = std::uint64_t;
  static hid_t type() { return H5T_NATIVE_UINT64; }
};

}  // namespace detail

/// Writes `n` items of `components` values of `type` as `name` under `group` (no time stamps: equal
/// states give byte-equal files).
void write_array(hid_t group, const std::string& file, const std::string& name, hid_t type, const void* data,
                 hsize_t n, int components);
/// Opens `name`, checks that it holds items of `components` values and returns their count in `n`;
/// with `memory_type` (not H5I_INVALID_HID) also that it is stored as that type's class, size and sign
/// (issue 34: a float32 or integer copy of a double array had been converted silently). `shown` names
/// the dataset in messages (its path in the file; `name` if empty).
h5detail::Handle open_array(hid_t group, const std::string& file, const std::string& name, int components, hsize_t& n,
                            hid_t memory_type = H5I_INVALID_HID, const std::string& shown = "");
/// The file access list checkpoints are created with (the HDF5 1.10 format).
h5detail::Handle file_access(const std::string& file);
/// A new checkpoint file (truncated) in that format, and a group in it, without time stamps.
h5detail::Handle create_file(const std::string& file);
h5detail::Handle create_group(hid_t parent, const std::string& file, const std::string& name);
/// Reads every object header of the open checkpoint `f` (their metadata checksums); throws
/// std::runtime_error naming `file` when one is damaged.
void check_objects(hid_t f, const std::string& file);
/// Whether the dataset carries the Fletcher32 checksum filter (its reads then verify every chunk).
bool has_checksum(hid_t dataset);
/// Refuses (std::runtime_error naming `shown`) a non-finite value among `values` unless `allowed`
/// (a sentinel of that member: +inf "no window yet", NaN "not computed before the first step").
void require_finite(const std::string& file, const std::string& shown, const double* values, std::size_t count,
                    bool (*allowed)(const std::string&, double));
/// The non-finite sentinels a serial checkpoint may hold (checkpoint.cpp).
bool allowed_sentinel(const std::string& shown, double value);

struct Writer {
  static constexpr bool reading = false;
  hid_t group;
  const std::string& file;
  template <class T> void operator()(const char* name, std::vector<T>& data) const {
    using L = detail::Layout<T>;
    write_array(group, file, name, L::type(), data.data(), data.size(), L::components);
  }
  void operator()(const char* name, double& x) const { write_array(group, file, name, H5T_NATIVE_DOUBLE, &x, 1, 1); }
  void operator()(const char* name, long& x) const { write_array(group, file, name, H5T_NATIVE_LONG, &x, 1, 1); }
  void operator()(const char* name, bool& x) const {
    const std::int32_t b = x ? 1 : 0;
    write_array(group, file, name, H5T_NATIVE_INT32, &b, 1, 1);
  }
  void operator()(const char* name, std::string& text) const {  // bytes
    write_array(group, file, name, H5T_NATIVE_CHAR, text.data(), text.size(), 1);
  }
};

struct Reader {
  static constexpr bool reading = true;
  hid_t group;
  const std::string& file;
  std::size_t particles;  // "particles/..." arrays must hold this many items
  std::string prefix = "";  // the group's path in the file ("/mechanics/"): messages name "/mechanics/time"
  bool finite = false;      // refuse non-finite doubles other than allowed_sentinel (serial checkpoints)
  std::string shown(const char* name) const { return prefix.empty() ? std::string(name) : prefix + name; }
  template <class T> void operator()(const char* name, std::vector<T>& data) const {
    using L = detail::Layout<T>;
    hsize_t n = 0;
    const h5detail::Handle d = open_array(group, file, name, L::components, n, L::type(), shown(name));
    const std::string key(name);
    if (key.rfind("particles/", 0) == 0 && n != particles)
      throw std::runtime_error("checkpoint '" + file + "': '" + shown(name) + "' holds " + std::to_string(n) +
                               " particles, the simulation built from the scene has " + std::to_string(particles));
    data.resize(n);
    if (n > 0)
      h5detail::check(H5Dread(d.get(), L::type(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), file,
                      "cannot read '" + shown(name) + "'");
    if constexpr (std::is_same_v<typename L::Scalar, double>)
      if (finite && n > 0)
        require_finite(file, shown(name), reinterpret_cast<const double*>(data.data()), n * L::components,
                       allowed_sentinel);
  }
  template <class T> void scalar(const char* name, hid_t type, T& x) const {
    hsize_t n = 0;
    const h5detail::Handle d = open_array(group, file, name, 1, n, type, shown(name));
    if (n != 1)
      throw std::runtime_error("checkpoint '" + file + "': '" + shown(name) + "' holds " + std::to_string(n) +
                               " values, expected one");
    h5detail::check(H5Dread(d.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &x), file,
                    "cannot read '" + shown(name) + "'");
  }
  void operator()(const char* name, double& x) const {
    scalar(name, H5T_NATIVE_DOUBLE, x);
    if (finite) require_finite(file, shown(name), &x, 1, allowed_sentinel);
  }
  void operator()(const char* name, long& x) const { scalar(name, H5T_NATIVE_LONG, x); }
  void operator()(const char* name, bool& x) const {
    std::int32_t b = 0;
    scalar(name, H5T_NATIVE_INT32, b);
    if (b != 0 && b != 1)
      throw std::runtime_error("checkpoint '" + file + "': '" + shown(name) + "' holds " + std::to_string(b) +
                               ", expected 0 or 1 (false or true); the checkpoint is damaged");
    x = b != 0;
  }
  void operator()(const char* name, std::string& text) const {
    hsize_t n = 0;
    const h5detail::Handle d = open_array(group, file, name, 1, n, H5T_NATIVE_CHAR, shown(name));
    text.assign(n, '\0');
    if (n > 0)
      h5detail::check(H5Dread(d.get(), H5T_NATIVE_CHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()), file,
                      "cannot read '" + shown(name) + "'");
  }
};

}  // namespace frictherm::coupling::ckpt

namespace frictherm::coupling {
struct CheckpointMarks;
namespace ckpt {
/// The run's marks under /marks of the checkpoint `f` (`w` writes at its root), as checkpoint_marks
/// reads them: serial and decomposed checkpoints (checkpoint.cpp).
void write_marks(const Writer& w, hid_t f, const std::string& file, CheckpointMarks m);
/// Integer attribute `name` of `obj` in checkpoint `file`: int written as 32-bit, long as 64-bit;
/// read as long, a missing attribute or one that is not one integer throwing (the checkpoint is damaged).
void write_int_attribute(hid_t obj, const std::string& file, const char* name, int value);
void write_int_attribute(hid_t obj, const std::string& file, const char* name, long value);
long read_int_attribute(hid_t obj, const std::string& file, const char* name);
}  // namespace ckpt
}  // namespace frictherm::coupling
