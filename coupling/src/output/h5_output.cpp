// HDF5 run output. Crash safety — what a run killed at any instant (even kill -9) leaves behind:
//
// * Every call that changes what the file shows ends with H5Fflush(H5F_SCOPE_GLOBAL):
//   end_snapshot, write_metadata, declare_series, each series batch, flush(). On disk the file is
//   then complete and consistent as of that flush, and nothing already flushed is touched again
//   until the next such call.
// * A snapshot is built as an anonymous group and linked into /snapshots only in end_snapshot, just
//   before the flush, so whatever reaches the disk mid-snapshot is unreachable from the root.
// * Metadata-cache evictions are disabled from begin_snapshot to the flush in end_snapshot, and
//   inside every other modifying call, so no dirty metadata (a half-updated link index, say) is
//   written between two flushes. HDF5 only allows that with a fixed-size cache, so adaptive
//   resizing is off. Evictions are enabled again right after each flush, when every cached entry
//   is clean, so memory stays bounded.
// * File-space strategy NONE: freed space is never reused, so new data cannot overwrite an object
//   (a replaced /meta entry, say) that the last flushed metadata still points at.
// * Format bounds low = 1.8, high = 1.10 — deliberately not low = LATEST: a 1.10-format superblock
//   (v3) records "open for writing" in the file, and after a crash every reader refuses the file
//   until someone runs h5clear. The 1.8 format still has checksummed object headers.
// * Not covered: a crash inside H5Fflush itself (HDF5 writes are not atomic) and power loss (no
//   fsync; a killed process loses nothing the kernel already received).
//
// The series and tables: h5_output_columns.cpp; snapshots and XDMF: h5_output_snapshots.cpp.
#include "output/h5_output_impl.hpp"

#include <frictherm/coupling/output_files.hpp>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <utility>

namespace frictherm::coupling {
namespace {

using h5detail::check;
using h5detail::check_id;
using h5detail::check_name;
using h5detail::Handle;
using h5detail::Io;
using h5detail::Quiet;

}  // namespace

void H5Output::Impl::metadata(const std::string& key, hid_t type, const void* value, std::size_t bytes) {
  check_name(key, "metadata");
  const Scoped held(*this);
  if (H5Lexists(meta.get(), key.c_str(), H5P_DEFAULT) > 0) {
    check(H5Ldelete(meta.get(), key.c_str(), H5P_DEFAULT), io.file, "cannot replace /meta/" + key);
  }
  const Handle d = io.scalar_dataset(meta.get(), key, type, value, bytes, "/meta/" + key);
  io.describe(d.get(), key, dim, H5Tget_class(type) == H5T_STRING, "/meta/" + key);
  flush_file();
}

void H5Output::Impl::metadata_array(const std::string& key, hid_t type, const void* values, std::size_t n, bool text) {
  check_name(key, "metadata");
  const Scoped held(*this);
  if (H5Lexists(meta.get(), key.c_str(), H5P_DEFAULT) > 0) {
    check(H5Ldelete(meta.get(), key.c_str(), H5P_DEFAULT), io.file, "cannot replace /meta/" + key);
  }
  const Handle d = io.array_dataset(meta.get(), key, type, values, n, "/meta/" + key);
  io.describe(d.get(), key, dim, text, "/meta/" + key);
  flush_file();
}

H5Output::H5Output(const std::string& path, int dim, H5OutputOptions options) : impl_(std::make_unique<Impl>()) {
  if (dim != 2 && dim != 3) throw std::invalid_argument("H5Output: dim must be 2 or 3");
  if (options.series_batch_rows == 0) options.series_batch_rows = 1;
  Impl& m = *impl_;
  m.final_path = path;
  m.io.file = options.via_temporary ? temporary_path(path) : path;
  m.xdmf_path = xdmf_path_for(path);
  m.reference_path = xdmf_reference_path_for(path);
  m.nodes_path = xdmf_nodes_path_for(path);
  m.dim = dim;
  m.options = options;
  const Quiet quiet;
  const Io& io = m.io;
  Handle fcpl{check_id(H5Pcreate(H5P_FILE_CREATE), path, "cannot create a property list"), H5Pclose};
  check(H5Pset_file_space_strategy(fcpl.get(), H5F_FSPACE_STRATEGY_NONE, 0, 1), path, "cannot set file space strategy");
  check(H5Pset_link_creation_order(fcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED), path,
        "cannot track creation order");
  Handle fapl{check_id(H5Pcreate(H5P_FILE_ACCESS), path, "cannot create a property list"), H5Pclose};
  check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_LATEST), path, "cannot set format bounds");
  const unsigned mode = options.via_temporary ? H5F_ACC_EXCL : H5F_ACC_TRUNC;  // EXCL: never truncate another's file
  m.file = Handle{check_id(H5Fcreate(m.io.file.c_str(), mode, fcpl.get(), fapl.get()), m.io.file, "cannot create the file"),
                  H5Fclose};
  m.cache.version = H5AC__CURR_CACHE_CONFIG_VERSION;
  check(H5Fget_mdc_config(m.file.get(), &m.cache), path, "cannot read the metadata cache configuration");
  m.cache.incr_mode = H5C_incr__off;
  m.cache.flash_incr_mode = H5C_flash_incr__off;
  m.cache.decr_mode = H5C_decr__off;
  m.cache.set_initial_size = true;
  m.cache.initial_size = std::clamp<std::size_t>(4u << 20, m.cache.min_size, m.cache.max_size);
  m.set_evictions(true);
  m.cache.set_initial_size = false;

  const std::int32_t version = 2, d = dim;  // 2: vectors (n, 3) and stress (n, 9) in 2D too; steps, ids, counts int64
  io.string_attribute(m.file.get(), "format", "frictherm-output", "/");
  io.attribute(m.file.get(), "format_version", H5T_STD_I32LE, H5T_NATIVE_INT32, &version, "/");
  io.attribute(m.file.get(), "dim", H5T_STD_I32LE, H5T_NATIVE_INT32, &d, "/");
  m.meta = io.group(m.file.get(), "meta", "/meta");
  m.snapshots = io.group(m.file.get(), "snapshots", "/snapshots");
  m.flush_file();
  m.write_xdmf();  // an empty collection; also proves early that the XDMF file can be written
}

void hdf5_program_setup() {
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

H5Output::~H5Output() {
  if (!impl_ || impl_->closed) return;
  try {
    close();
  } catch (const std::exception& e) {
    std::cerr << "frictherm: closing output: " << e.what() << '\n';
  }
}

H5Output::H5Output(H5Output&&) noexcept = default;
H5Output& H5Output::operator=(H5Output&&) noexcept = default;

H5Output::Impl& H5Output::live() const {
  if (!impl_ || impl_->closed) throw std::logic_error("H5Output: the output file is closed");
  return *impl_;
}

void H5Output::write_metadata(const std::string& key, const std::string& value) {
  Impl& m = live();
  const Quiet quiet;
  const Handle t = m.io.string_type(value.size());
  m.metadata(key, t.get(), value.c_str(), value.size());
}

void H5Output::write_metadata(const std::string& key, double value) {
  Impl& m = live();
  const Quiet quiet;
  m.metadata(key, H5T_IEEE_F64LE, &value, sizeof value);
}

void H5Output::write_metadata(const std::string& key, const std::vector<double>& values) {
  Impl& m = live();
  const Quiet quiet;
  m.metadata_array(key, H5T_IEEE_F64LE, values.data(), values.size(), false);
}

void H5Output::write_metadata(const std::string& key, const std::vector<std::int64_t>& values) {
  Impl& m = live();
  const Quiet quiet;
  m.metadata_array(key, H5T_STD_I64LE, values.data(), values.size(), false);
}

void H5Output::write_metadata(const std::string& key, const std::vector<std::string>& values) {
  Impl& m = live();
  const Quiet quiet;
  std::size_t longest = 1;
  for (const auto& v : values) longest = std::max(longest, v.size());
  std::string packed(values.size() * longest, '\0');  // fixed-length, NUL-padded
  for (std::size_t i = 0; i < values.size(); ++i) packed.replace(i * longest, values[i].size(), values[i]);
  const Handle t = m.io.string_type(longest);
  m.metadata_array(key, t.get(), packed.data(), values.size(), true);
}

void H5Output::write_integer_metadata(const std::string& key, std::int64_t value) {
  Impl& m = live();
  const Quiet quiet;
  m.metadata(key, H5T_NATIVE_INT64, &value, sizeof value);
}

void H5Output::sync() {
  flush();
  Impl& m = live();
  void* handle = nullptr;
  check(H5Fget_vfd_handle(m.file.get(), H5P_DEFAULT, &handle), m.io.file, "cannot get the file's descriptor");
  if (handle != nullptr && ::fsync(*static_cast<int*>(handle)) != 0)
    throw std::runtime_error("HDF5 file '" + m.io.file + "': cannot make the written rows durable (fsync: " +
                             std::strerror(errno) + ")");
}

void H5Output::abandon() noexcept {
  if (!impl_ || impl_->closed) return;
  const Quiet quiet;
  impl_->discard_snapshot();
  impl_->close_handles();
}

void H5Output::close() {
  Impl& m = live();
  m.discard_snapshot();
  flush();
  m.write_xdmf();
  const Quiet quiet;
  m.close_handles();
  if (m.io.file != m.final_path) m.publish();
}

void H5Output::publish_xdmf_with_result(std::string text, std::string reference, std::string nodes) {
  live().given_xdmf = std::move(text);
  live().given_reference_xdmf = std::move(reference);
  live().given_nodes_xdmf = std::move(nodes);
}

std::size_t H5Output::snapshot_count() const { return impl_ ? impl_->count : 0; }
const std::string& H5Output::path() const { return impl_->final_path; }
const std::string& H5Output::live_path() const { return impl_->io.file; }
const std::string& H5Output::xdmf_path() const { return impl_->xdmf_path; }
int H5Output::dim() const { return impl_->dim; }

}  // namespace frictherm::coupling
