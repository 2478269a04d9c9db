// Particle snapshots of a decomposed run (frictherm/coupling/distributed.hpp): one HDF5 file per rank
// and one XDMF file joining them (a temporal collection of spatial collections of the ranks' grids).
#include <frictherm/coupling/distributed.hpp>
#include <frictherm/coupling/xdmf.hpp>

#include "output/h5_io.hpp"
#include "output/h5_util.hpp"

#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace frictherm::coupling {

namespace h5 = h5detail;

namespace {

// Every rank learns whether any rank failed, and why (the first failing rank's message), so no rank
// is left waiting in the next collective call.
void agree(MPI_Comm comm, const std::string& local_error) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int mine = local_error.empty() ? size : rank;
  int first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return;
  int length = rank == first ? static_cast<int>(local_error.size()) : 0;
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  std::string text = rank == first ? local_error : std::string(static_cast<std::size_t>(length), ' ');
  MPI_Bcast(text.data(), length, MPI_CHAR, first, comm);
  throw std::runtime_error("decomposed output (rank " + std::to_string(first) + "): " + text);
}

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// `dim`: the run's (units and long_name as the serial file's; a particle's vectors are padded to 3).
void write_dataset(hid_t group, const std::string& file, const std::string& name, hid_t type, const void* data,
                   hsize_t rows, hsize_t columns, int dim = 3) {
  const std::array<hsize_t, 2> dims{rows, columns};
  const h5::Handle space{h5::check_id(H5Screate_simple(columns > 1 ? 2 : 1, dims.data(), nullptr), file,
                                      "cannot create a dataspace"),
                         H5Sclose};
  const h5::Handle d{h5::check_id(H5Dcreate2(group, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT,
                                             H5P_DEFAULT),
                                  file, "cannot create dataset " + name),
                     H5Dclose};
  if (rows > 0) h5::check(H5Dwrite(d.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), file, "cannot write " + name);
  h5::Io{file}.describe(d.get(), name, dim, false, name);  // units, long_name
}

// A scalar attribute of the snapshot group (the serial file's `step` and `time`, docs/output.md).
void write_attribute(hid_t group, const std::string& file, const char* name, hid_t type, const void* value) {
  const h5::Handle space{h5::check_id(H5Screate(H5S_SCALAR), file, "cannot create a dataspace"), H5Sclose};
  const h5::Handle a{h5::check_id(H5Acreate2(group, name, type, space.get(), H5P_DEFAULT, H5P_DEFAULT), file,
                                  std::string("cannot create attribute ") + name),
                     H5Aclose};
  h5::check(H5Awrite(a.get(), type, value), file, std::string("cannot write attribute ") + name);
}

// A snapshot's group `path` (particles or thermal nodes) in a rank file: the serial group's step and
// time attributes and the polyvertex connectivity 0..n−1 its XDMF grid draws.
h5::Handle drawn_group(hid_t f, const std::string& file, const std::string& path, long step, double time,
                       std::size_t n, int dim) {
  h5::Handle g{h5::check_id(H5Gcreate2(f, path.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), file,
                            "cannot create " + path),
               H5Gclose};
  const std::int64_t step64 = step;
  write_attribute(g.get(), file, "step", H5T_NATIVE_INT64, &step64);
  write_attribute(g.get(), file, "time", H5T_NATIVE_DOUBLE, &time);
  std::vector<int> connectivity(n);
  for (std::size_t k = 0; k < n; ++k) connectivity[k] = static_cast<int>(k);
  write_dataset(g.get(), file, "connectivity", H5T_NATIVE_INT, connectivity.data(), n, 1, dim);
  return g;
}

// Every rank's row count on rank 0 (collective).
std::vector<unsigned long long> counts_on_root(MPI_Comm comm, std::size_t n) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  const unsigned long long mine = n;
  std::vector<unsigned long long> counts(static_cast<std::size_t>(size));
  MPI_Gather(&mine, 1, MPI_UNSIGNED_LONG_LONG, counts.data(), 1, MPI_UNSIGNED_LONG_LONG, 0, comm);
  return counts;
}

// n × dim values padded to n × 3 (ParaView's vectors).
std::vector<double> padded(const std::vector<double>& v, std::size_t n, int dim) {
  std::vector<double> out(3 * n, 0.0);
  for (std::size_t k = 0; k < n; ++k)
    for (int d = 0; d < dim; ++d) out[3 * k + static_cast<std::size_t>(d)] = v[static_cast<std::size_t>(dim) * k + static_cast<std::size_t>(d)];
  return out;
}

// One snapshot's spatial collection of the ranks' grids `group` (ranks with count 0 have none) drawn
// at `geometry`, each rank's in its file `file_of(r)` with its own connectivity (group/connectivity).
template <class FileOf>
std::string spatial_collection(const std::string& index, long step, double time,
                               const std::vector<unsigned long long>& counts, const std::string& group,
                               const std::string& geometry, const std::vector<XdmfField>& fields, int dim,
                               FileOf file_of) {
  std::string xml = "    <Grid Name=\"" + index + "\" GridType=\"Collection\" CollectionType=\"Spatial\">\n";
  // The shortest text that reads back to the same double (as every rank's grid's time).
  char time_text[32];
  const auto printed = std::to_chars(time_text, time_text + sizeof time_text, time);
  xml += "      <Time Value=\"" + std::string(time_text, printed.ptr) + "\"/>\n";
  for (std::size_t r = 0; r < counts.size(); ++r) {
    if (counts[r] == 0) continue;
    XdmfGrid grid;
    grid.name = "rank" + std::to_string(r);
    grid.h5_group = group;
    grid.connectivity = group + "/connectivity";
    grid.step = step;
    grid.time = time;
    grid.geometry = geometry;
    grid.points = static_cast<std::size_t>(counts[r]);
    grid.fields = fields;
    const std::string g = xdmf_grid_xml(grid, base_name(file_of(static_cast<int>(r))), dim);
    // Indented one level deeper: inside this snapshot's spatial collection.
    std::size_t at = 0;
    while (at < g.size()) {
      const std::size_t end = g.find('\n', at);
      xml += "  " + g.substr(at, end - at + 1);
      at = end + 1;
    }
  }
  xml += "    </Grid>\n";
  return xml;
}

}  // namespace

std::string DecomposedOutput::rank_file(const std::string& base, int rank) {
  return base + ".rank" + std::to_string(rank) + ".h5";
}

std::string DecomposedOutput::rank_file(int rank) const { return rank_file(base_, rank); }

void DecomposedOutput::agree_or_close(const std::string& error) {
  try {
    agree(comm_, error);
  } catch (...) {
    close();
    throw;
  }
}

DecomposedOutput::DecomposedOutput(MPI_Comm comm, std::string base, int dim, bool overwrite, bool write_xdmf)
    : comm_(comm), dim_(dim), base_(std::move(base)), xdmf_path_(base_ + ".xdmf"), write_xdmf_(write_xdmf) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  std::string error;
  if (dim != 2 && dim != 3) error = "dimension " + std::to_string(dim) + " (expected 2 or 3)";
  const std::string file = rank_file(rank_);
  if (error.empty() && !overwrite && ::access(file.c_str(), F_OK) == 0)
    error = "'" + file + "' exists (pass --force to overwrite it)";
  if (error.empty() && rank_ == 0 && !overwrite && ::access(xdmf_path_.c_str(), F_OK) == 0)
    error = "'" + xdmf_path_ + "' exists (pass --force to overwrite it)";
  if (error.empty()) {
    try {
      const h5::Quiet quiet;
      file_ = h5::check_id(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), file,
                           "cannot create the file");
      const h5::Handle g{h5::check_id(H5Gcreate2(file_, "snapshots", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), file,
                                      "cannot create /snapshots"),
                         H5Gclose};
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  agree_or_close(error);
}

DecomposedOutput::DecomposedOutput(MPI_Comm comm, std::string base, int dim, long kept, std::vector<std::string> grids,
                                   bool create_missing, bool write_xdmf)
    : comm_(comm), dim_(dim), base_(std::move(base)), xdmf_path_(base_ + ".xdmf"), grids_(std::move(grids)),
      write_xdmf_(write_xdmf), snapshots_(kept) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  std::string error;
  const std::string file = rank_file(rank_);
  try {
    const h5::Quiet quiet;
    const bool missing = ::access(file.c_str(), F_OK) != 0;
    if (missing && !create_missing)
      throw std::runtime_error("'" + file + "' is missing (the run's snapshots of rank " + std::to_string(rank_) + ")");
    if (missing) {
      file_ = h5::check_id(H5Fcreate(file.c_str(), H5F_ACC_EXCL, H5P_DEFAULT, H5P_DEFAULT), file, "cannot create the file");
      h5::Handle{h5::check_id(H5Gcreate2(file_, "snapshots", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), file,
                              "cannot create /snapshots"),
                 H5Gclose};
    } else {
      file_ = h5::check_id(H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), file, "cannot open the file");
    }
    const h5::Handle g{h5::check_id(H5Gopen2(file_, "snapshots", H5P_DEFAULT), file, "cannot open /snapshots"), H5Gclose};
    H5G_info_t info;
    h5::check(H5Gget_info(g.get(), &info), file, "cannot list /snapshots");
    const hsize_t n = info.nlinks;
    if (static_cast<long>(n) < kept && !missing)
      throw std::runtime_error("'" + file + "' holds " + std::to_string(n) + " snapshots, the checkpoint " +
                               std::to_string(kept));
    for (long k = missing ? static_cast<long>(n) : kept; k < static_cast<long>(n); ++k) {  // snapshots are numbered 0, 1, ... in order
      char b[16];
      std::snprintf(b, sizeof b, "%06ld", k);
      h5::check(H5Ldelete(g.get(), b, H5P_DEFAULT), file, std::string("cannot remove snapshot ") + b);
    }
    if (H5Lexists(file_, "nodes", H5P_DEFAULT) > 0) {  // the thermal nodes of the removed snapshots
      const h5::Handle nodes{h5::check_id(H5Gopen2(file_, "nodes", H5P_DEFAULT), file, "cannot open /nodes"), H5Gclose};
      for (long k = kept; k < static_cast<long>(n); ++k) {
        char b[16];
        std::snprintf(b, sizeof b, "%06ld", k);
        if (H5Lexists(nodes.get(), b, H5P_DEFAULT) > 0)
          h5::check(H5Ldelete(nodes.get(), b, H5P_DEFAULT), file, std::string("cannot remove nodes ") + b);
      }
    }
    h5::check(H5Fflush(file_, H5F_SCOPE_GLOBAL), file, "cannot flush");
    if (rank_ == 0 && write_xdmf_) write_text_atomically(xdmf_path_, xdmf_document(grids_));
  } catch (const std::exception& e) {
    error = e.what();
  }
  agree_or_close(error);
}

DecomposedOutput::~DecomposedOutput() { close(); }

std::string DecomposedOutput::xdmf_text() const { return xdmf_document(grids_); }

std::string DecomposedOutput::nodes_xdmf_text() const {
  return node_grids_.empty() ? std::string() : xdmf_document(node_grids_, "thermal_nodes");
}

std::string DecomposedOutput::reference_xdmf_text() const {
  return reference_grids_.empty() ? std::string() : xdmf_document(reference_grids_, "particles_reference");
}

void DecomposedOutput::close() {
  if (file_ >= 0) H5Fclose(file_);
  file_ = -1;
}

void DecomposedOutput::write(long step, double time, const DecomposedSnapshot& s) {
  const std::size_t n = s.id.size();
  const auto dim = static_cast<std::size_t>(dim_);
  // Temperatures from every rank that has particles, or from none (the XDMF names the same fields
  // in every rank's grid).
  int temperature = s.temperature.empty() ? 0 : 1, any_temperature = 0;
  MPI_Allreduce(&temperature, &any_temperature, 1, MPI_INT, MPI_MAX, comm_);
  std::string error;
  if (file_ < 0) error = "the output is closed";
  else if (any_temperature && n > 0 && s.temperature.empty())
    error = "temperatures given on some ranks but not on this one";
  else if (s.position.size() != dim * n || s.velocity.size() != dim * n || s.material.size() != n ||
           (!s.temperature.empty() && s.temperature.size() != n) ||
           std::any_of(s.fields.begin(), s.fields.end(),
                       [n](const auto& f) { return f.components < 1 || f.values.size() != n * static_cast<std::size_t>(f.components); }) ||
           std::any_of(s.integer_fields.begin(), s.integer_fields.end(), [n](const auto& f) { return f.second.size() != n; }))
    error = "snapshot arrays of different lengths (" + std::to_string(n) + " ids)";
  const std::string index = [&] {
    char b[16];
    std::snprintf(b, sizeof b, "%06ld", snapshots_);
    return std::string(b);
  }();
  const std::string file = rank_file(rank_);
  if (error.empty()) {
    try {
      const h5::Quiet quiet;
      const h5::Handle g = drawn_group(file_, file, "/snapshots/" + index, step, time, n, 3);
      write_dataset(g.get(), file, "id", H5T_NATIVE_INT64, s.id.data(), n, 1);
      write_dataset(g.get(), file, "position", H5T_NATIVE_DOUBLE, s.position.data(), n, dim);
      const std::vector<double> v = padded(s.velocity, n, dim_);
      write_dataset(g.get(), file, "velocity", H5T_NATIVE_DOUBLE, v.data(), n, 3);
      // Every rank's group holds the same datasets (a rank without particles: 0 rows).
      if (any_temperature) write_dataset(g.get(), file, "temperature", H5T_NATIVE_DOUBLE, s.temperature.data(), n, 1);
      for (const DecomposedSnapshot::Field& f : s.fields)
        write_dataset(g.get(), file, f.name, H5T_NATIVE_DOUBLE, f.values.data(), n, static_cast<hsize_t>(f.components));
      for (const auto& [name, values] : s.integer_fields)
        write_dataset(g.get(), file, name, H5T_NATIVE_INT, values.data(), n, 1);
      write_dataset(g.get(), file, "material", H5T_NATIVE_INT, s.material.data(), n, 1);
      h5::check(H5Fflush(file_, H5F_SCOPE_GLOBAL), file, "cannot flush");
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  agree(comm_, error);

  // Rank 0 joins the ranks' grids (ranks without particles have none) and rewrites the XDMF file.
  const std::vector<unsigned long long> counts = counts_on_root(comm_, n);
  error.clear();
  if (rank_ == 0) {
    try {
      // The global id (int64: Int Precision 8) so ParaView can colour, select and threshold by the
      // serial particle index across ranks.
      std::vector<XdmfField> fields = {{"position", dim_, false}, {"id", 1, true, 8}, {"velocity", 3, false},
                                       {"material", 1, true}};
      if (any_temperature) fields.push_back({"temperature", 1, false});
      for (const auto& f : s.fields) fields.push_back({f.name, f.components, false});
      for (const auto& f : s.integer_fields) fields.push_back({f.first, 1, true});
      const auto file_of = [this](int r) { return rank_file(r); };
      auto collection = [&](const std::string& geometry) {
        return spatial_collection(index, step, time, counts, "/snapshots/" + index, geometry, fields, dim_, file_of);
      };
      grids_.push_back(collection("position"));
      if (std::any_of(s.fields.begin(), s.fields.end(),
                      [&](const DecomposedSnapshot::Field& f) { return f.name == "initial_position" && f.components == dim_; }))
        reference_grids_.push_back(collection("initial_position"));
      if (write_xdmf_) write_text_atomically(xdmf_path_, xdmf_document(grids_));
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  agree(comm_, error);
  write_nodes(step, time, index, s);
  ++snapshots_;
}

// The thermal grid's nodes of the snapshot: each rank's owned unknowns under /nodes/<index> of its
// file (every node once, on its owner), step and time as the serial /nodes group's, joined by
// BASE_nodes.xdmf as the particles are by BASE.xdmf.
void DecomposedOutput::write_nodes(long step, double time, const std::string& index, const DecomposedSnapshot& s) {
  int mine = s.node_fields.empty() ? 0 : 1, any = 0;
  MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, comm_);
  if (!any) return;
  const std::size_t n = s.nodes;
  const std::string file = rank_file(rank_);
  const std::string path = "/nodes/" + index;
  std::string error;
  if (!mine) error = "thermal nodes given on some ranks but not on this one";
  for (const DecomposedSnapshot::NodeField& f : s.node_fields)
    if ((f.integer ? f.integers.size() : f.values.size()) != n * static_cast<std::size_t>(f.components))
      error = "node field " + f.name + " of a length other than " + std::to_string(n) + " nodes";
  if (error.empty()) {
    try {
      const h5::Quiet quiet;
      if (H5Lexists(file_, "nodes", H5P_DEFAULT) <= 0)
        h5::Handle{h5::check_id(H5Gcreate2(file_, "nodes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), file,
                                "cannot create /nodes"),
                   H5Gclose};
      const h5::Handle g = drawn_group(file_, file, path, step, time, n, dim_);
      for (const DecomposedSnapshot::NodeField& f : s.node_fields)
        write_dataset(g.get(), file, f.name, f.integer ? H5T_NATIVE_INT32 : H5T_NATIVE_DOUBLE,
                      f.integer ? static_cast<const void*>(f.integers.data()) : f.values.data(), n,
                      static_cast<hsize_t>(f.components), dim_);
      h5::check(H5Fflush(file_, H5F_SCOPE_GLOBAL), file, "cannot flush");
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  agree(comm_, error);
  const std::vector<unsigned long long> counts = counts_on_root(comm_, n);
  if (rank_ == 0) {
    try {
      std::vector<XdmfField> fields;
      for (const DecomposedSnapshot::NodeField& f : s.node_fields) fields.push_back({f.name, f.components, f.integer});
      node_grids_.push_back(spatial_collection(index, step, time, counts, path, "position", fields, dim_,
                                               [this](int r) { return rank_file(r); }));
      if (write_xdmf_) write_text_atomically(base_ + "_nodes.xdmf", nodes_xdmf_text());
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  agree(comm_, error);
}

}  // namespace frictherm::coupling
