// H5Output's series and extra tables (h5_output_impl.hpp): /<name>/<column> extendible 1-D datasets,
// rows buffered and written column by column with the next snapshot, batch or flush.
#include "output/h5_output_impl.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <utility>

namespace frictherm::coupling {
namespace {

using h5detail::check;
using h5detail::check_id;
using h5detail::check_name;
using h5detail::Handle;
using h5detail::Quiet;

}  // namespace

void H5Output::Impl::create_columns(const std::string& name, const std::vector<std::string>& columns, const char* what,
                    Handle& group_out, std::vector<Handle>& sets) {
  std::set<std::string> seen;
  std::size_t longest = 1;
  for (const auto& n : columns) {
    check_name(n, what);
    if (!seen.insert(n).second) throw std::invalid_argument(std::string(what) + " '" + n + "' declared twice");
    longest = std::max(longest, n.size());
  }
  const Quiet quiet;
  const Scoped hold_cache(*this);
  group_out = io.group(file.get(), name, "/" + name);
  std::string packed(columns.size() * longest, '\0');  // fixed-length, NUL-padded names
  for (std::size_t i = 0; i < columns.size(); ++i) packed.replace(i * longest, columns[i].size(), columns[i]);
  {
    const Handle type = io.string_type(longest);
    const hsize_t n_columns = columns.size();
    const Handle s = io.space(1, &n_columns);
    const Handle a{check_id(H5Acreate2(group_out.get(), "columns", type.get(), s.get(), H5P_DEFAULT, H5P_DEFAULT),
                            io.file, "cannot create /" + name + " attribute columns"),
                   H5Aclose};
    check(H5Awrite(a.get(), type.get(), packed.data()), io.file, "cannot write /" + name + " attribute columns");
  }
  const hsize_t zero = 0, unlimited = H5S_UNLIMITED, chunk = 1024;
  const Handle space = io.space(1, &zero, &unlimited);
  Handle dcpl{check_id(H5Pcreate(H5P_DATASET_CREATE), io.file, "cannot create a property list"), H5Pclose};
  check(H5Pset_chunk(dcpl.get(), 1, &chunk), io.file, "cannot set chunking");
  for (const auto& n : columns) {
    sets.emplace_back(check_id(H5Dcreate2(group_out.get(), n.c_str(),
                                          H5Output::is_count_column(n) ? H5T_STD_I64LE : H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                                          dcpl.get(), H5P_DEFAULT),
                               io.file, "cannot create /" + name + "/" + n),
                      H5Dclose);
    io.describe(sets.back().get(), n, dim, false, "/" + name + "/" + n);  // units, long_name
  }
  flush_file();
}

void H5Output::Impl::write_table(const std::string& name, Table& t) {
  const std::size_t cols = t.names.size();
  if (cols == 0 || t.pending.empty()) return;
  hsize_t rows = t.pending.size() / cols;
  std::vector<double> column(rows);
  const hsize_t total = t.written + rows;
  for (std::size_t j = 0; j < cols; ++j) {
    for (hsize_t r = 0; r < rows; ++r) column[r] = t.pending[r * cols + j];
    if (H5Output::is_count_column(t.names[j]))  // int64 on disk: round, do not truncate
      for (double& v : column) v = std::nearbyint(v);
    const std::string where = "/" + name + "/" + t.names[j];
    const hid_t ds = t.sets[j].get();
    check(H5Dset_extent(ds, &total), io.file, "cannot extend " + where);
    const Handle fs{check_id(H5Dget_space(ds), io.file, "cannot get the dataspace of " + where), H5Sclose};
    check(H5Sselect_hyperslab(fs.get(), H5S_SELECT_SET, &t.written, nullptr, &rows, nullptr), io.file,
          "cannot select rows of " + where);
    const Handle ms = io.space(1, &rows);
    check(H5Dwrite(ds, H5T_NATIVE_DOUBLE, ms.get(), fs.get(), H5P_DEFAULT, column.data()), io.file,
          "cannot write " + where);
  }
  t.written = total;
  t.pending.clear();
}

void H5Output::Impl::write_pending() {
  for (auto& [name, table] : tables) write_table(name, table);  // extra tables
  const std::size_t cols = series_names.size();
  if (cols == 0 || pending.empty()) return;
  hsize_t rows = pending.size() / cols;
  std::vector<double> column(rows);
  const hsize_t total = series_written + rows;
  for (std::size_t j = 0; j < cols; ++j) {
    for (hsize_t r = 0; r < rows; ++r) column[r] = pending[r * cols + j];
    if (H5Output::is_count_column(series_names[j]))  // int64 on disk: round, do not truncate
      for (double& v : column) v = std::nearbyint(v);
    const std::string where = "/series/" + series_names[j];
    const hid_t ds = series_sets[j].get();
    check(H5Dset_extent(ds, &total), io.file, "cannot extend " + where);
    const Handle fs{check_id(H5Dget_space(ds), io.file, "cannot get the dataspace of " + where), H5Sclose};
    check(H5Sselect_hyperslab(fs.get(), H5S_SELECT_SET, &series_written, nullptr, &rows, nullptr), io.file,
          "cannot select rows of " + where);
    const Handle ms = io.space(1, &rows);
    check(H5Dwrite(ds, H5T_NATIVE_DOUBLE, ms.get(), fs.get(), H5P_DEFAULT, column.data()), io.file,
          "cannot write " + where);
  }
  series_written = total;
  pending.clear();
}

bool H5Output::is_count_column(const std::string& name) {
  static const std::set<std::string> exact{"step", "id", "fate", "seed", "status", "steps", "runaway", "dying",
                                           "material_mask", "hotspots"};
  auto ends_with = [&name](const std::string& tail) {
    return name.size() >= tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (name.rfind("penalty_contacts.", 0) == 0) return true;
  if (name.find('.') != std::string::npos) return false;  // per-body or per-pair columns carry user names
  return exact.count(name) > 0 || ends_with("_count") || ends_with("_nodes") || ends_with("_windows");
}

void H5Output::declare_series(const std::vector<std::string>& names) {
  Impl& m = live();
  if (!m.series_names.empty()) throw std::logic_error("H5Output: series already declared");
  if (names.empty() || names.front() != "time") {
    throw std::invalid_argument("series columns must start with \"time\"");
  }
  m.create_columns("series", names, "series column", m.series, m.series_sets);
  m.series_names = names;
}

void H5Output::append_series(const std::vector<double>& row) {
  Impl& m = live();
  if (m.series_names.empty()) throw std::logic_error("H5Output: append_series before declare_series");
  if (row.size() != m.series_names.size()) {
    throw std::invalid_argument("series row has " + std::to_string(row.size()) + " values, " +
                                std::to_string(m.series_names.size()) + " columns declared");
  }
  m.pending.insert(m.pending.end(), row.begin(), row.end());
  if (m.pending.size() >= m.options.series_batch_rows * row.size()) flush();
}

// ---- extra tables (declare_table / append_table_row) ----
void H5Output::declare_table(const std::string& name, const std::vector<std::string>& columns) {
  Impl& m = live();
  check_name(name, "table");
  if (name == "meta" || name == "snapshots" || name == "series" || name == "failure" || name == "xdmf" || name == "nodes" ||
      m.tables.count(name) != 0)
    throw std::logic_error("H5Output: table /" + name + " already exists or is reserved");
  if (columns.empty()) throw std::invalid_argument("table /" + name + " needs at least one column");
  Impl::Table t;
  m.create_columns(name, columns, "table column", t.group, t.sets);
  t.names = columns;
  m.tables.emplace(name, std::move(t));
}

void H5Output::append_table_row(const std::string& name, const std::vector<double>& row) {
  Impl& m = live();
  const auto it = m.tables.find(name);
  if (it == m.tables.end()) throw std::logic_error("H5Output: append_table_row before declare_table(" + name + ")");
  Impl::Table& t = it->second;
  if (row.size() != t.names.size())
    throw std::invalid_argument("table /" + name + " row has " + std::to_string(row.size()) + " values, " +
                                std::to_string(t.names.size()) + " columns declared");
  t.pending.insert(t.pending.end(), row.begin(), row.end());
  if (t.pending.size() >= m.options.series_batch_rows * row.size()) flush();
}

std::size_t H5Output::table_rows(const std::string& name) const {
  if (!impl_) return 0;
  const auto it = impl_->tables.find(name);
  if (it == impl_->tables.end() || it->second.names.empty()) return 0;
  return it->second.written + it->second.pending.size() / it->second.names.size();
}
// ---- end of extra tables ----

std::size_t H5Output::series_rows() const {
  if (!impl_) return 0;
  const Impl& m = *impl_;
  return m.series_names.empty() ? 0 : m.series_written + m.pending.size() / m.series_names.size();
}

void H5Output::flush() {
  Impl& m = live();
  const Quiet quiet;
  const Impl::Scoped hold(m);
  m.write_pending();
  m.flush_file();
}

}  // namespace frictherm::coupling
