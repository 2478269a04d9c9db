// Appending a resumed run's output to the interrupted result (result_append.hpp).
#include <frictherm/coupling/result_append.hpp>

#include "output/h5_util.hpp"

#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/xdmf.hpp>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <algorithm>
#include <filesystem>
#include <utility>
#include <stdexcept>
#include <vector>

namespace frictherm::coupling {

namespace {

using h5detail::check;
using h5detail::check_id;
using h5detail::Handle;

herr_t collect_name(hid_t, const char* name, const H5L_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->emplace_back(name);
  return 0;
}

// Link names of a group in creation order (names sort the same for snapshots).
std::vector<std::string> members(hid_t group) {
  std::vector<std::string> names;
  hsize_t idx = 0;
  H5Literate(group, H5_INDEX_NAME, H5_ITER_INC, &idx, collect_name, &names);
  return names;
}

bool exists(hid_t loc, const std::string& path) { return H5Lexists(loc, path.c_str(), H5P_DEFAULT) > 0; }

hsize_t rows_of(hid_t d, const std::string& file, const std::string& where) {
  const Handle s{check_id(H5Dget_space(d), file, "dataspace of " + where), H5Sclose};
  hsize_t n = 0;
  if (H5Sget_simple_extent_ndims(s.get()) != 1) throw std::runtime_error("'" + file + "': " + where + " is not a column");
  H5Sget_simple_extent_dims(s.get(), &n, nullptr);
  return n;
}

void copy_object(hid_t from, const std::string& src, hid_t to, const std::string& dst, const std::string& file) {
  check(H5Ocopy(from, src.c_str(), to, dst.c_str(), H5P_DEFAULT, H5P_DEFAULT), file, "cannot copy " + src + " to " + dst);
}

// The names in a column group's `columns` attribute (the order the writer declared), or none.
std::vector<std::string> declared_columns(hid_t group, const std::string& file, const std::string& where) {
  std::vector<std::string> names;
  if (H5Aexists(group, "columns") <= 0) return names;
  const std::string attr = where + " attribute columns";
  const Handle a{check_id(H5Aopen(group, "columns", H5P_DEFAULT), file, attr), H5Aclose};
  const Handle t{check_id(H5Aget_type(a.get()), file, "type of " + attr), H5Tclose};
  const Handle s{check_id(H5Aget_space(a.get()), file, attr), H5Sclose};
  const std::size_t size = H5Tget_size(t.get());
  const hssize_t count = H5Sget_simple_extent_npoints(s.get());
  if (H5Tget_class(t.get()) != H5T_STRING || H5Tis_variable_str(t.get()) > 0 || size == 0 || count < 0)
    throw std::runtime_error("'" + file + "': " + attr + " is not a fixed-length string array");
  std::string packed(size * static_cast<std::size_t>(count), '\0');
  check(H5Aread(a.get(), t.get(), packed.data()), file, "cannot read " + attr);
  for (hssize_t i = 0; i < count; ++i) {
    std::string name = packed.substr(static_cast<std::size_t>(i) * size, size);
    name.resize(std::min(name.size(), name.find('\0')));
    names.push_back(name);
  }
  return names;
}

// Replaces the `columns` attribute of `group` (fixed-length, NUL-padded, as H5Output writes it).
void declare_columns(hid_t group, const std::vector<std::string>& names, const std::string& file, const std::string& where) {
  std::size_t longest = 1;
  for (const std::string& n : names) longest = std::max(longest, n.size());
  std::string packed(names.size() * longest, '\0');
  for (std::size_t i = 0; i < names.size(); ++i) packed.replace(i * longest, names[i].size(), names[i]);
  if (H5Aexists(group, "columns") > 0) check(H5Adelete(group, "columns"), file, "cannot replace " + where + " attribute columns");
  const Handle t{check_id(H5Tcopy(H5T_C_S1), file, "string type"), H5Tclose};
  check(H5Tset_size(t.get(), longest), file, "string type");
  check(H5Tset_strpad(t.get(), H5T_STR_NULLPAD), file, "string type");
  check(H5Tset_cset(t.get(), H5T_CSET_UTF8), file, "string type");
  const hsize_t n = names.size();
  const Handle s{check_id(H5Screate_simple(1, &n, nullptr), file, "dataspace"), H5Sclose};
  const Handle a{check_id(H5Acreate2(group, "columns", t.get(), s.get(), H5P_DEFAULT, H5P_DEFAULT), file,
                          "cannot create " + where + " attribute columns"),
                 H5Aclose};
  check(H5Awrite(a.get(), t.get(), packed.data()), file, "cannot write " + where + " attribute columns");
}

// What a joined column holds in the rows of the part that did not write it (`continue` with other
// thermal settings, issue 34). The loading's rows of a column only the continuation has: 0 for the
// quantities that were exactly 0 there (a reaction or plastic heating the loading did not have:
// nothing released, λ = 0, which is where the continuation starts), NaN (undefined) for the others,
// e.g. an interface temperature. The continuation's rows of a column only the loading has: NaN (not
// computed by the continuation).
double absent_value(const std::string& column, bool in_loading_rows) {
  if (in_loading_rows)
    for (const char* zero : {"reaction_heat", "max_reaction_progress", "max_interface_reaction_progress", "plastic_work",
                             "plastic_heat"})
      if (column == zero) return 0.0;
  return std::numeric_limits<double>::quiet_NaN();
}

// /<group>/<column>: the original's first `keep` rows, then all of the continuation's rows. With
// `join_columns` (continue) a column only one of them has is kept, filled with absent_value in the
// other's rows, and the group's `columns` attribute becomes the continuation's order followed by the
// original's own columns; without it (resume: the same scene) differing columns are refused.
void append_columns(hid_t out, hid_t cont, const std::string& group, long keep, const std::string& file,
                    const std::string& cont_file, bool join_columns) {
  const bool in_out = exists(out, "/" + group), in_cont = exists(cont, "/" + group);
  if (!in_out && !in_cont) return;
  if (!in_out || !in_cont)
    throw std::runtime_error("'" + file + "' and '" + cont_file + "': only one of them has /" + group);
  const Handle go{check_id(H5Gopen2(out, group.c_str(), H5P_DEFAULT), file, "/" + group), H5Gclose};
  const Handle gc{check_id(H5Gopen2(cont, group.c_str(), H5P_DEFAULT), cont_file, "/" + group), H5Gclose};
  const std::vector<std::string> cols = members(go.get()), cont_cols = members(gc.get());
  if (cols != cont_cols && !join_columns)
    throw std::runtime_error("'" + file + "': the columns of /" + group + " differ from those of the resumed run");
  std::vector<std::string> all = cont_cols;  // sorted by name, as members() lists them
  for (const std::string& c : cols)
    if (!std::binary_search(cont_cols.begin(), cont_cols.end(), c)) all.push_back(c);
  for (const std::string& c : all) {
    const std::string where = "/" + group + "/" + c;
    const bool mine = std::binary_search(cols.begin(), cols.end(), c), theirs = std::binary_search(cont_cols.begin(), cont_cols.end(), c);
    hsize_t add = 0;
    Handle e;
    if (theirs) {
      e = Handle{check_id(H5Dopen2(gc.get(), c.c_str(), H5P_DEFAULT), cont_file, where), H5Dclose};
      add = rows_of(e.get(), cont_file, where);
    } else {  // as many rows as the continuation's other columns
      if (!cont_cols.empty()) {
        const std::string first = "/" + group + "/" + cont_cols.front();
        const Handle f{check_id(H5Dopen2(gc.get(), cont_cols.front().c_str(), H5P_DEFAULT), cont_file, first), H5Dclose};
        add = rows_of(f.get(), cont_file, first);
      }
    }
    // A column only the continuation has: its dataset (type, chunks, units) copied, then moved down
    // below `keep` filled rows.
    if (!mine) copy_object(gc.get(), c, go.get(), c, file);
    const Handle d{check_id(H5Dopen2(go.get(), c.c_str(), H5P_DEFAULT), file, where), H5Dclose};
    const hsize_t have = mine ? rows_of(d.get(), file, where) : static_cast<hsize_t>(keep);
    if (have < static_cast<hsize_t>(keep))
      throw std::runtime_error("'" + file + "': " + where + " has " + std::to_string(have) +
                               " rows, the checkpoint counts " + std::to_string(keep) +
                               " (the result was written after the checkpoint by another run?)");
    const Handle type{check_id(H5Dget_type(d.get()), file, "type of " + where), H5Tclose};
    const bool integer = H5Tget_class(type.get()) == H5T_INTEGER;
    if (integer && !(mine && theirs))
      throw std::runtime_error("'" + file + "' and '" + cont_file + "': only one of them has the count column " + where +
                               " (no value stands for its absence)");
    const hid_t mem = integer ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE;
    // Rows written from `start`: the continuation's after the kept ones, or all of them with the
    // filled rows first for a column the original lacks.
    const hsize_t start = mine ? static_cast<hsize_t>(keep) : 0, count = mine ? add : add + static_cast<hsize_t>(keep);
    std::vector<double> vd(integer ? 0 : count);
    std::vector<std::int64_t> vi(integer ? count : 0);
    if (!mine) std::fill(vd.begin(), vd.begin() + keep, absent_value(c, true));
    if (!theirs) std::fill(vd.begin(), vd.end(), absent_value(c, false));
    const hsize_t offset = mine ? 0 : static_cast<hsize_t>(keep);
    void* at = integer ? static_cast<void*>(vi.data() + offset) : static_cast<void*>(vd.data() + offset);
    if (theirs && add > 0) {
      const Handle ms{check_id(H5Screate_simple(1, &add, nullptr), cont_file, "dataspace"), H5Sclose};
      check(H5Dread(e.get(), mem, ms.get(), H5S_ALL, H5P_DEFAULT, at), cont_file, "cannot read " + where);
    }
    void* buf = integer ? static_cast<void*>(vi.data()) : static_cast<void*>(vd.data());
    const hsize_t total = static_cast<hsize_t>(keep) + add;
    check(H5Dset_extent(d.get(), &total), file, "cannot resize " + where);
    if (count == 0) continue;
    const Handle fs{check_id(H5Dget_space(d.get()), file, "dataspace of " + where), H5Sclose};
    check(H5Sselect_hyperslab(fs.get(), H5S_SELECT_SET, &start, nullptr, &count, nullptr), file, "rows of " + where);
    const Handle ms{check_id(H5Screate_simple(1, &count, nullptr), file, "dataspace"), H5Sclose};
    check(H5Dwrite(d.get(), mem, ms.get(), fs.get(), H5P_DEFAULT, buf), file, "cannot write " + where);
  }
  if (cols == cont_cols) return;
  // The declared order: the continuation's, then the columns only the original has, in its order.
  std::vector<std::string> order = declared_columns(gc.get(), cont_file, "/" + group);
  for (const std::string& c : declared_columns(go.get(), file, "/" + group))
    if (std::find(order.begin(), order.end(), c) == order.end()) order.push_back(c);
  if (!order.empty()) declare_columns(go.get(), order, file, "/" + group);
}

std::string snapshot_name(std::size_t k) {
  char name[32];
  std::snprintf(name, sizeof name, "%06zu", k);
  return name;
}

void append_snapshots(hid_t out, hid_t cont, long keep, const std::string& file, const std::string& cont_file) {
  if (exists(out, "/failure")) check(H5Ldelete(out, "/failure", H5P_DEFAULT), file, "cannot remove /failure");
  if (!exists(out, "/snapshots")) throw std::runtime_error("'" + file + "' has no /snapshots: not a frictherm result");
  const Handle so{check_id(H5Gopen2(out, "snapshots", H5P_DEFAULT), file, "/snapshots"), H5Gclose};
  const std::vector<std::string> have = members(so.get());
  if (have.size() < static_cast<std::size_t>(keep))
    throw std::runtime_error("'" + file + "' has " + std::to_string(have.size()) + " snapshots, the checkpoint counts " +
                             std::to_string(keep));
  for (const std::string& n : have)
    if (std::stol(n) >= keep) check(H5Ldelete(so.get(), n.c_str(), H5P_DEFAULT), file, "cannot remove a snapshot");
  if (exists(cont, "/snapshots")) {
    const Handle sc{check_id(H5Gopen2(cont, "snapshots", H5P_DEFAULT), cont_file, "/snapshots"), H5Gclose};
    std::size_t k = static_cast<std::size_t>(keep);
    for (const std::string& n : members(sc.get())) copy_object(sc.get(), n, so.get(), snapshot_name(k++), file);
  }
  if (exists(cont, "/failure")) copy_object(cont, "/failure", out, "/failure", file);
  // The thermal grid's nodes: numbered as the snapshots they belong to.
  if (exists(out, "/nodes")) {
    const Handle no{check_id(H5Gopen2(out, "nodes", H5P_DEFAULT), file, "/nodes"), H5Gclose};
    for (const std::string& n : members(no.get()))
      if (std::stol(n) >= keep) check(H5Ldelete(no.get(), n.c_str(), H5P_DEFAULT), file, "cannot remove /nodes/" + n);
  }
  if (exists(cont, "/nodes")) {
    if (!exists(out, "/nodes")) check_id(H5Gclose(H5Gcreate2(out, "nodes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)), file, "/nodes");
    const Handle nc{check_id(H5Gopen2(cont, "nodes", H5P_DEFAULT), cont_file, "/nodes"), H5Gclose};
    const Handle no{check_id(H5Gopen2(out, "nodes", H5P_DEFAULT), file, "/nodes"), H5Gclose};
    for (const std::string& n : members(nc.get()))
      copy_object(nc.get(), n, no.get(), snapshot_name(static_cast<std::size_t>(keep + std::stol(n))), file);
  }
  if (exists(cont, "/xdmf")) {  // Polyvertex connectivities of new particle counts
    if (!exists(out, "/xdmf")) check_id(H5Gclose(H5Gcreate2(out, "xdmf", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)), file, "/xdmf");
    const Handle xc{check_id(H5Gopen2(cont, "xdmf", H5P_DEFAULT), cont_file, "/xdmf"), H5Gclose};
    for (const std::string& n : members(xc.get()))
      if (!exists(out, "/xdmf/" + n)) copy_object(xc.get(), n, out, "/xdmf/" + n, file);
  }
}

void replace_meta(hid_t out, hid_t cont, const std::string& file, const std::string& cont_file) {
  if (!exists(cont, "/meta")) return;
  const Handle mc{check_id(H5Gopen2(cont, "meta", H5P_DEFAULT), cont_file, "/meta"), H5Gclose};
  const Handle mo{check_id(H5Gopen2(out, "meta", H5P_DEFAULT), file, "/meta"), H5Gclose};
  // How the interrupted part ended: true of the joined result only if the resumed part says so too.
  for (const char* stale : {"interruption", "failure"})
    if (exists(mo.get(), stale)) check(H5Ldelete(mo.get(), stale, H5P_DEFAULT), file, "cannot remove /meta/" + std::string(stale));
  for (const std::string& n : members(mc.get())) {
    if (exists(mo.get(), n)) check(H5Ldelete(mo.get(), n.c_str(), H5P_DEFAULT), file, "cannot replace /meta/" + n);
    copy_object(mc.get(), n, mo.get(), n, file);
  }
}

template <class T> T read_attribute(hid_t obj, const char* name, hid_t type, const std::string& file) {
  const Handle a{check_id(H5Aopen(obj, name, H5P_DEFAULT), file, std::string("attribute ") + name), H5Aclose};
  T value{};
  check(H5Aread(a.get(), type, &value), file, std::string("attribute ") + name);
  return value;
}

XdmfGrid grid_of(hid_t g, const std::string& name, const std::string& path, const std::string& file) {
  XdmfGrid grid;
  grid.name = name;
  grid.h5_group = path;
  grid.step = static_cast<long>(read_attribute<std::int64_t>(g, "step", H5T_NATIVE_INT64, file));
  grid.time = read_attribute<double>(g, "time", H5T_NATIVE_DOUBLE, file);
  for (const std::string& f : members(g)) {
    const Handle d{check_id(H5Dopen2(g, f.c_str(), H5P_DEFAULT), file, path + "/" + f), H5Dclose};
    const Handle s{check_id(H5Dget_space(d.get()), file, "dataspace"), H5Sclose};
    hsize_t dims[2] = {0, 1};
    const int rank = H5Sget_simple_extent_dims(s.get(), dims, nullptr);
    const Handle t{check_id(H5Dget_type(d.get()), file, "type"), H5Tclose};
    grid.points = static_cast<std::size_t>(dims[0]);
    grid.fields.push_back({f, rank == 2 ? static_cast<int>(dims[1]) : 1, H5Tget_class(t.get()) == H5T_INTEGER});
  }
  grid.connectivity = "/xdmf/polyvertex_" + std::to_string(grid.points);
  return grid;
}

}  // namespace

XdmfDocuments xdmf_documents_of_result(const std::string& h5_path, const std::string& h5_name) {
  const h5detail::Quiet quiet;
  const Handle f{check_id(H5Fopen(h5_path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), h5_path, "cannot open"), H5Fclose};
  const int dim = read_attribute<int>(f.get(), "dim", H5T_NATIVE_INT, h5_path);
  std::vector<std::string> xml, reference, nodes;
  // A grid drawn at `geometry` when the group has that field (dim float components) and its connectivity.
  const auto render = [&](const XdmfGrid& grid, const std::string& geometry, std::vector<std::string>& into) {
    bool drawable = false;
    for (const XdmfField& fd : grid.fields)
      drawable = drawable || (fd.name == geometry && fd.components == dim && !fd.integer);
    if (drawable && grid.points > 0 && exists(f.get(), grid.connectivity)) {
      XdmfGrid g = grid;
      g.geometry = geometry;
      into.push_back(xdmf_grid_xml(g, h5_name, dim));
    }
  };
  const auto add = [&](hid_t g, const std::string& name, const std::string& path) {
    const XdmfGrid grid = grid_of(g, name, path, h5_path);
    render(grid, "position", xml);
    render(grid, "initial_position", reference);  // RUN_reference.xdmf (displacement warp)
  };
  const auto each = [&](const char* group, const auto& visit) {
    if (!exists(f.get(), std::string("/") + group)) return;
    const Handle s{check_id(H5Gopen2(f.get(), group, H5P_DEFAULT), h5_path, std::string("/") + group), H5Gclose};
    for (const std::string& n : members(s.get())) {
      const std::string path = std::string("/") + group + "/" + n;
      const Handle g{check_id(H5Gopen2(s.get(), n.c_str(), H5P_DEFAULT), h5_path, path), H5Gclose};
      visit(g.get(), n, path);
    }
  };
  each("snapshots", add);
  if (exists(f.get(), "/failure")) {
    const Handle g{check_id(H5Gopen2(f.get(), "failure", H5P_DEFAULT), h5_path, "/failure"), H5Gclose};
    add(g.get(), "failure", "/failure");
  }
  each("nodes", [&](hid_t g, const std::string& n, const std::string& path) {
    render(grid_of(g, n, path, h5_path), "position", nodes);
  });
  XdmfDocuments d;
  d.current = xdmf_document(xml);
  if (!reference.empty()) d.reference = xdmf_document(reference, "particles_reference");
  if (!nodes.empty()) d.nodes = xdmf_document(nodes, "thermal_nodes");
  return d;
}

std::string xdmf_of_result(const std::string& h5_path, const std::string& h5_name) {
  return xdmf_documents_of_result(h5_path, h5_name).current;
}

std::string result_run_id(const std::string& result) {
  const h5detail::Quiet quiet;
  const Handle f{check_id(H5Fopen(result.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), result, "cannot open it"), H5Fclose};
  if (!exists(f.get(), "/meta/run_id")) return "";
  const Handle d{check_id(H5Dopen2(f.get(), "/meta/run_id", H5P_DEFAULT), result, "/meta/run_id"), H5Dclose};
  const Handle t{check_id(H5Dget_type(d.get()), result, "type of /meta/run_id"), H5Tclose};
  std::string id(H5Tget_size(t.get()), '\0');
  check(H5Dread(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, id.data()), result, "cannot read /meta/run_id");
  id.resize(id.find('\0') == std::string::npos ? id.size() : id.find('\0'));
  return id;
}

void check_same_run(const std::string& result, const CheckpointMarks& marks) {
  // The result the checkpoint belongs to (issue 34): a later run on the same output that did not
  // finish leaves its checkpoint beside the earlier run's result. Older files have no identity.
  if (marks.run_id.empty()) return;
  const std::string id = result_run_id(result);
  if (!id.empty() && id != marks.run_id)
    throw std::runtime_error("'" + result + "' is the result of run " + id + ", the checkpoint belongs to run " +
                             marks.run_id + " (its /marks/run_id: a later run on the same output that did not finish, or " +
                             "files of two runs put together)");
}

void check_appendable(const std::string& original, const CheckpointMarks& marks) {
  const h5detail::Quiet quiet;
  const Handle f{check_id(H5Fopen(original.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), original, "cannot open it"), H5Fclose};
  for (const char* group : {"/meta", "/series", "/snapshots"})
    if (!exists(f.get(), group)) throw std::runtime_error("'" + original + "': no " + group + " (not a frictherm result)");
  check_same_run(original, marks);
  const std::vector<std::string> cols = [&] {
    const Handle g{check_id(H5Gopen2(f.get(), "series", H5P_DEFAULT), original, "/series"), H5Gclose};
    return members(g.get());
  }();
  if (!cols.empty()) {
    const std::string where = "/series/" + cols.front();
    const Handle d{check_id(H5Dopen2(f.get(), where.c_str(), H5P_DEFAULT), original, where), H5Dclose};
    if (rows_of(d.get(), original, where) < static_cast<hsize_t>(marks.series_rows))
      throw std::runtime_error("'" + original + "': " + where + " has fewer rows than the checkpoint counts (" +
                               std::to_string(marks.series_rows) + " in its /marks/series_rows)");
  }
  // The tables' rows (/hotspots, /hotspot_fates) the checkpoint counts: there, before any step (issue
  // 34: a damaged /marks/table_rows had been found only after the resumed run, by the append).
  for (const auto& [table, rows] : marks.table_rows) {
    if (rows == 0) continue;
    const std::string group = "/" + table;
    if (table.empty() || table.find('/') != std::string::npos || !exists(f.get(), group.c_str()))
      throw std::runtime_error("'" + original + "': no table " + group + ", the checkpoint counts " + std::to_string(rows) +
                               " rows of it (its /marks/table_names and /marks/table_rows)");
    const Handle t{check_id(H5Gopen2(f.get(), group.c_str(), H5P_DEFAULT), original, group), H5Gclose};
    const std::vector<std::string> columns = members(t.get());
    if (columns.empty()) continue;
    const std::string where = group + "/" + columns.front();
    const Handle d{check_id(H5Dopen2(f.get(), where.c_str(), H5P_DEFAULT), original, where), H5Dclose};
    if (rows_of(d.get(), original, where) < static_cast<hsize_t>(rows))
      throw std::runtime_error("'" + original + "': " + where + " has fewer rows than the checkpoint counts (" +
                               std::to_string(rows) + " in its /marks/table_rows)");
  }
  const Handle g{check_id(H5Gopen2(f.get(), "snapshots", H5P_DEFAULT), original, "/snapshots"), H5Gclose};
  if (members(g.get()).size() < static_cast<std::size_t>(marks.snapshots))
    throw std::runtime_error("'" + original + "': fewer snapshots than the checkpoint counts (" +
                             std::to_string(marks.snapshots) + " in its /marks/snapshots)");
}

namespace {

// copy_file with read(2)/write(2), for the system's reason when a write fails (std::filesystem said
// "Input/output error" where the write had failed with "File too large").
void copy_bytes(const std::string& from, const std::string& to) {
  const int in = ::open(from.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0) throw std::runtime_error("cannot read '" + from + "': " + std::strerror(errno));
  const int out = ::open(to.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (out < 0) {
    const std::string reason = std::strerror(errno);
    ::close(in);
    throw std::runtime_error("cannot create '" + to + "': " + reason);
  }
  std::vector<char> buf(1 << 20);
  std::string error;
  for (;;) {
    const ssize_t n = ::read(in, buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) error = "cannot read '" + from + "': " + std::strerror(errno);
    if (n <= 0) break;
    for (ssize_t done = 0; done < n && error.empty();) {
      const ssize_t w = ::write(out, buf.data() + done, static_cast<std::size_t>(n - done));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) error = "cannot write '" + to + "': " + std::strerror(w < 0 ? errno : ENOSPC);
      done += w > 0 ? w : 0;
    }
    if (!error.empty()) break;
  }
  ::close(in);
  if (::close(out) != 0 && error.empty()) error = "cannot write '" + to + "': " + std::strerror(errno);
  if (!error.empty()) throw std::runtime_error(error);
}

// The joined result in `tmp`: the original's rows up to the marks, then the continuation's.
void append_into(const std::string& original, const std::string& continuation, const CheckpointMarks& marks,
                 const std::string& tmp, bool join_columns) {
  copy_bytes(original, tmp);
  const h5detail::Quiet quiet;
  const Handle out{check_id(H5Fopen(tmp.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), tmp, "cannot open the copy"), H5Fclose};
  const Handle cont{check_id(H5Fopen(continuation.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), continuation, "cannot open"),
                    H5Fclose};
  append_columns(out.get(), cont.get(), "series", marks.series_rows, original, continuation, join_columns);
  for (const auto& [table, rows] : marks.table_rows)
    append_columns(out.get(), cont.get(), table, rows, original, continuation, join_columns);
  append_snapshots(out.get(), cont.get(), marks.snapshots, original, continuation);
  replace_meta(out.get(), cont.get(), original, continuation);
  check(H5Fflush(out.get(), H5F_SCOPE_GLOBAL), tmp, "cannot flush");
}

// append_into in a child process: HDF5 1.10 crashes (SIGSEGV in H5Ocopy's clean-up) when a write
// fails under it, a full disk or the file-size limit (issue 34, found by the fault injection). The
// child's message comes back through a pipe; a crash is reported as a failed write.
void append_in_child(const std::string& original, const std::string& continuation, const CheckpointMarks& marks,
                     const std::string& tmp, bool join_columns) {
  int fds[2];
  if (::pipe(fds) != 0) return append_into(original, continuation, marks, tmp, join_columns);
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return append_into(original, continuation, marks, tmp, join_columns);
  }
  if (pid == 0) {
    ::close(fds[0]);
    int code = 0;
    try {
      append_into(original, continuation, marks, tmp, join_columns);
    } catch (const std::exception& e) {
      const std::string what = e.what();
      for (std::size_t done = 0; done < what.size();) {
        const ssize_t w = ::write(fds[1], what.data() + done, what.size() - done);
        if (w <= 0) break;
        done += static_cast<std::size_t>(w);
      }
      code = 1;
    }
    ::_exit(code);
  }
  ::close(fds[1]);
  std::string message;
  char buf[4096];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    message.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  if (WIFSIGNALED(status))
    throw std::runtime_error("writing '" + tmp + "' failed: the HDF5 library ended the process with signal " +
                             std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) +
                             "), as it does after a failed write (a full disk or the file-size limit)");
  throw std::runtime_error(message.empty() ? "writing '" + tmp + "' failed" : message);
}

}  // namespace

void append_result(const std::string& original, const std::string& continuation, const CheckpointMarks& marks,
                   const std::string& output, bool join_columns) {
  const std::string tmp = temporary_path(output);
  try {
    append_in_child(original, continuation, marks, tmp, join_columns);
    const std::size_t slash = output.find_last_of('/');
    const std::string name = slash == std::string::npos ? output : output.substr(slash + 1);
    const XdmfDocuments xdmf = xdmf_documents_of_result(tmp, name);
    // RUN_reference.xdmf and RUN_nodes.xdmf are written when the result has their grids; the old
    // ones are removed either way (publish_with_xdmf), so no stale file stays.
    publish_with_xdmf(tmp, output, true, xdmf.current, xdmf.reference, xdmf.nodes);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
}

}  // namespace frictherm::coupling
