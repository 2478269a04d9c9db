// H5Output's snapshots (h5_output_impl.hpp): /snapshots/NNNNNN and /failure built as anonymous groups
// and linked in end_snapshot with the thermal grid's /nodes, then RUN.xdmf, RUN_reference.xdmf and
// RUN_nodes.xdmf rewritten (xdmf.hpp).
#include "output/h5_output_impl.hpp"

#include <frictherm/coupling/output_files.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace frictherm::coupling {
namespace {

using h5detail::check;
using h5detail::check_id;
using h5detail::check_name;
using h5detail::fail;
using h5detail::Handle;
using h5detail::Quiet;

}  // namespace

std::string H5Output::Impl::document(std::vector<std::string> grids, const std::string& failure,
                                     const std::string& name) {
  if (!failure.empty()) grids.push_back(failure);
  return xdmf_document(grids, name);
}

void H5Output::Impl::write_xdmf() {
  if (!options.write_xdmf || options.via_temporary) return;
  write_text_atomically(xdmf_path, document(grid_xml, failure_xml, "particles"));
  if (has_reference())
    write_text_atomically(reference_path, document(reference_xml, reference_failure_xml, "particles_reference"));
  if (!node_xml.empty()) write_text_atomically(nodes_path, xdmf_document(node_xml, "thermal_nodes"));
}

void H5Output::Impl::publish() {
  if (!options.write_xdmf && !given_xdmf.empty())
    return publish_with_xdmf(io.file, final_path, options.replace_existing, given_xdmf, given_reference_xdmf,
                             given_nodes_xdmf);
  if (!options.write_xdmf) return publish_file(io.file, final_path, options.replace_existing);
  publish_with_xdmf(io.file, final_path, options.replace_existing, document(grid_xml, failure_xml, "particles"),
                    has_reference() ? document(reference_xml, reference_failure_xml, "particles_reference") : "",
                    node_xml.empty() ? "" : xdmf_document(node_xml, "thermal_nodes"));
}

void H5Output::Impl::discard_snapshot() noexcept {
  if (kind == Kind::none) return;
  group.reset();  // an anonymous group that was never linked is deleted when closed
  node_group.reset();
  kind = Kind::none;
  fields.clear();
  node_points = kNone;
  node_fields.clear();
  release();
}

void H5Output::Impl::begin(Kind k, long s, double t) {
  if (kind != Kind::none) throw std::logic_error("H5Output: begin_snapshot while a snapshot is open");
  hold();
  Handle g{H5Gcreate_anon(file.get(), H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
  if (g.get() < 0) {
    release();
    fail(io.file, "cannot create a snapshot group");
  }
  group = std::move(g);
  kind = k;
  step = s;
  time = t;
  points = kNone;
  fields.clear();
}

void H5Output::Impl::field(const std::string& name, bool integer, const void* data, std::size_t n, int components) {
  if (kind == Kind::none) throw std::logic_error("H5Output: snapshot_field outside begin/end_snapshot");
  check_name(name, "snapshot field");
  if (components < 1) throw std::invalid_argument("snapshot field " + name + ": components must be >= 1");
  if (points != kNone && n != points) {
    throw std::invalid_argument("snapshot field " + name + " has " + std::to_string(n) + " rows, earlier fields " +
                                std::to_string(points));
  }
  if (name == "position" && components != dim) {
    throw std::invalid_argument("snapshot field position needs " + std::to_string(dim) + " components");
  }
  if (n > 0 && data == nullptr) throw std::invalid_argument("snapshot field " + name + ": null data");
  write_dataset(group.get(), name, integer, data, n, components,
                "snapshot field " + name + " (step " + std::to_string(step) + ")");
  points = n;
  fields.push_back({name, components, integer});
}

void H5Output::Impl::write_dataset(hid_t g, const std::string& name, bool integer, const void* data, std::size_t n,
                                   int components, const std::string& where) {
  const hsize_t dims[2] = {n, static_cast<hsize_t>(components)};
  const Handle s = io.space(components == 1 ? 1 : 2, dims);
  const hid_t file_type = integer ? H5T_STD_I32LE : H5T_IEEE_F64LE;
  const hid_t mem_type = integer ? H5T_NATIVE_INT32 : H5T_NATIVE_DOUBLE;
  const Handle d{check_id(H5Dcreate2(g, name.c_str(), file_type, s.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                          io.file, "cannot create " + where),
                 H5Dclose};
  if (n > 0) check(H5Dwrite(d.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), io.file, "cannot write " + where);
  io.describe(d.get(), name, dim, false, where);
}

void H5Output::Impl::node_field(const std::string& name, bool integer, const void* data, std::size_t n,
                                int components) {
  if (kind != Kind::snapshot) throw std::logic_error("H5Output: node_field outside begin_snapshot/end_snapshot");
  check_name(name, "node field");
  if (components < 1) throw std::invalid_argument("node field " + name + ": components must be >= 1");
  if (node_points != kNone && n != node_points)
    throw std::invalid_argument("node field " + name + " has " + std::to_string(n) + " rows, earlier node fields " +
                                std::to_string(node_points));
  if (name == "position" && components != dim)
    throw std::invalid_argument("node field position needs " + std::to_string(dim) + " components");
  if (n > 0 && data == nullptr) throw std::invalid_argument("node field " + name + ": null data");
  if (node_group.get() < 0)  // anonymous until end_snapshot links it, as the snapshot's own group
    node_group = Handle{check_id(H5Gcreate_anon(file.get(), H5P_DEFAULT, H5P_DEFAULT), io.file,
                                 "cannot create a node group"),
                        H5Gclose};
  write_dataset(node_group.get(), name, integer, data, n, components,
                "node field " + name + " (step " + std::to_string(step) + ")");
  node_points = n;
  node_fields.push_back({name, components, integer});
}

std::string H5Output::Impl::ensure_connectivity(std::size_t n) {
  const std::string name = "polyvertex_" + std::to_string(n);
  if (connectivity.insert(n).second) {
    if (connectivity.size() == 1) io.group(file.get(), "xdmf", "/xdmf");
    std::vector<std::int32_t> ids(n);
    for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<std::int32_t>(i);
    const hsize_t dims[1] = {n};
    const Handle s = io.space(1, dims);
    const std::string path = "/xdmf/" + name;
    const Handle d{check_id(H5Dcreate2(file.get(), path.c_str(), H5T_STD_I32LE, s.get(), H5P_DEFAULT,
                                       H5P_DEFAULT, H5P_DEFAULT),
                            io.file, "cannot create " + path),
                   H5Dclose};
    check(H5Dwrite(d.get(), H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, ids.data()), io.file,
          "cannot write " + path);
    io.describe(d.get(), name, dim, false, path);
  }
  return "/xdmf/" + name;
}

void H5Output::Impl::end() {
  if (kind == Kind::none) throw std::logic_error("H5Output: end_snapshot without begin_snapshot");
  const bool failure = kind == Kind::failure;
  char name[32];
  std::snprintf(name, sizeof name, "%06zu", count);
  const std::string path = failure ? std::string("/failure") : "/snapshots/" + std::string(name);
  try {
    const std::int64_t s = step;
    io.attribute(group.get(), "step", H5T_STD_I64LE, H5T_NATIVE_INT64, &s, path);
    io.attribute(group.get(), "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &time, path);
    if (failure) io.string_attribute(group.get(), "message", message, path);
    XdmfGrid grid{failure ? "failure" : name, path, "", step, time, points == kNone ? 0 : points, fields};
    const bool drawable = grid.points > 0 && std::any_of(fields.begin(), fields.end(), [](const XdmfField& f) {
                            return f.name == "position";
                          });
    if (drawable && options.write_xdmf) grid.connectivity = ensure_connectivity(grid.points);
    if (failure && H5Lexists(file.get(), "failure", H5P_DEFAULT) > 0) {
      check(H5Ldelete(file.get(), "failure", H5P_DEFAULT), io.file, "cannot replace /failure");
    }
    check(H5Olink(group.get(), failure ? file.get() : snapshots.get(), failure ? "failure" : name, H5P_DEFAULT,
                  H5P_DEFAULT),
          io.file, "cannot link " + path);
    // The thermal grid's nodes: /nodes/<name>, linked with the snapshot before the same flush.
    const std::string node_path = "/nodes/" + std::string(name);
    XdmfGrid node_grid{name, node_path, "", step, time, node_points == kNone ? 0 : node_points, node_fields};
    const bool nodes_drawable = node_grid.points > 0 && std::any_of(node_fields.begin(), node_fields.end(),
                                                                    [](const XdmfField& f) { return f.name == "position"; });
    if (node_group.get() >= 0) {
      io.attribute(node_group.get(), "step", H5T_STD_I64LE, H5T_NATIVE_INT64, &s, node_path);
      io.attribute(node_group.get(), "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &time, node_path);
      if (nodes_drawable && options.write_xdmf) node_grid.connectivity = ensure_connectivity(node_grid.points);
      if (nodes.get() < 0) nodes = io.group(file.get(), "nodes", "/nodes");
      check(H5Olink(node_group.get(), nodes.get(), name, H5P_DEFAULT, H5P_DEFAULT), io.file, "cannot link " + node_path);
    }
    write_pending();
    flush_file();
    discard_snapshot();  // closes the (now linked) group and lifts the eviction hold
    if (drawable && options.write_xdmf) {
      XdmfGrid reference = grid;
      reference.geometry = "initial_position";
      const bool has_reference = std::any_of(grid.fields.begin(), grid.fields.end(), [&](const XdmfField& f) {
        return f.name == reference.geometry && f.components == dim && !f.integer;
      });
      if (!failure) {
        grid_xml.push_back(xdmf_grid_xml(grid, io_name(), dim));
        if (has_reference) reference_xml.push_back(xdmf_grid_xml(reference, io_name(), dim));
        if (nodes_drawable) node_xml.push_back(xdmf_grid_xml(node_grid, io_name(), dim));
        last_time = time;
      } else {
        failure_xml = time > last_time ? xdmf_grid_xml(grid, io_name(), dim) : std::string();
        reference_failure_xml =
            time > last_time && has_reference ? xdmf_grid_xml(reference, io_name(), dim) : std::string();
      }
    }
    if (!failure) ++count;
  } catch (...) {
    discard_snapshot();
    throw;
  }
  write_xdmf();
}

void H5Output::begin_snapshot(long step, double time) {
  Impl& m = live();
  const Quiet quiet;
  m.begin(Impl::Kind::snapshot, step, time);
}

void H5Output::begin_failure(long step, double time, const std::string& message) {
  Impl& m = live();
  const Quiet quiet;
  m.discard_snapshot();
  m.begin(Impl::Kind::failure, step, time);
  m.message = message.size() > 16384 ? message.substr(0, 16384) : message;
}

void H5Output::snapshot_field(const std::string& name, const double* data, std::size_t n, int components) {
  Impl& m = live();
  const Quiet quiet;
  m.field(name, false, data, n, components);
}

void H5Output::snapshot_field(const std::string& name, const std::int32_t* data, std::size_t n) {
  Impl& m = live();
  const Quiet quiet;
  m.field(name, true, data, n, 1);
}

void H5Output::end_snapshot() {
  Impl& m = live();
  const Quiet quiet;
  m.end();
}

void H5Output::node_field(const std::string& name, const double* data, std::size_t n, int components) {
  Impl& m = live();
  const Quiet quiet;
  m.node_field(name, false, data, n, components);
}

void H5Output::node_field(const std::string& name, const std::int32_t* data, std::size_t n, int components) {
  Impl& m = live();
  const Quiet quiet;
  m.node_field(name, true, data, n, components);
}

bool H5Output::in_snapshot() const { return impl_ && impl_->kind != Impl::Kind::none; }

}  // namespace frictherm::coupling
