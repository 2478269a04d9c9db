// Private HDF5 helpers shared by the coupling sources (h5_output.cpp, csv_export.cpp).
#pragma once

#include <hdf5.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace frictherm::coupling::h5detail {

// Owns one hid_t and closes it with the matching H5?close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept : id_(other.id_), closer_(other.closer_) { other.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      std::swap(id_, other.id_);
      closer_ = other.closer_;
    }
    return *this;
  }
  ~Handle() { reset(); }
  void reset() {
    if (id_ >= 0 && closer_ != nullptr) closer_(id_);
    id_ = H5I_INVALID_HID;
  }
  hid_t get() const { return id_; }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

// Silences HDF5's automatic error printing for one library call sequence; errors become
// exceptions carrying the innermost HDF5 descriptions instead.
class Quiet {
 public:
  Quiet() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~Quiet() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  Quiet(const Quiet&) = delete;
  Quiet& operator=(const Quiet&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// One error-stack description on one line; the file driver's long report of a failed read or write
// ("file write failed: time = ..., errno = 28, error message = 'No space left on device', ...")
// shortened to its first words and the system's reason ("file write failed: No space left on device").
inline std::string error_description(const char* desc) {
  std::string d(desc);
  const std::string tag = "error message = '";
  if (const auto m = d.find(tag); m != std::string::npos) {
    const auto end = d.find('\'', m + tag.size());
    const std::string reason = d.substr(m + tag.size(), end == std::string::npos ? std::string::npos : end - m - tag.size());
    d = d.substr(0, std::min(d.find(':'), m)) + ": " + reason;
  }
  for (char& c : d)
    if (c == '\n') c = ' ';
  return d;
}

// H5Ewalk2 callback: joins the descriptions of the two innermost error-stack entries.
inline herr_t collect_error(unsigned n, const H5E_error2_t* err, void* out) {
  auto& text = *static_cast<std::string*>(out);
  if (n < 2 && err->desc != nullptr && *err->desc != '\0') {
    text += (text.empty() ? "" : "; ") + error_description(err->desc);
  }
  return 0;
}

// Throws "HDF5 file '<file>': <what> (<HDF5 reason>)".
[[noreturn]] inline void fail(const std::string& file, const std::string& what) {
  std::string reason;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, collect_error, &reason);  // innermost cause first
  if (reason.find("Fletcher32") != std::string::npos)  // H5Pset_fletcher32: a chunk's bytes changed since written
    reason = "its Fletcher32 checksum does not match the stored data: the file is damaged; HDF5: " + reason;
  throw std::runtime_error("HDF5 file '" + file + "': " + what + (reason.empty() ? "" : " (" + reason + ")"));
}
inline hid_t check_id(hid_t id, const std::string& file, const std::string& what) {
  if (id < 0) fail(file, what);
  return id;
}
inline void check(herr_t status, const std::string& file, const std::string& what) {
  if (status < 0) fail(file, what);
}

}  // namespace frictherm::coupling::h5detail
