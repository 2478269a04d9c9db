// Output of a decomposed run (frictherm/coupling/distributed.hpp, DecomposedOutput) under mpirun with 2
// and 4 ranks: every rank writes its particles to its own HDF5 file and rank 0 one XDMF file joining
// them. Checks, read back on rank 0 through the XDMF file's own references: every particle of every
// snapshot appears exactly once over the ranks' grids with the values written (ids, positions,
// velocities padded to 3 components, temperatures, materials), including a snapshot after particles
// changed rank and one rank was left empty (no grid for it); times are exact; an existing output is
// refused on every rank without overwrite, and inconsistent temperature arrays make every rank throw.
// In 2D (geometry XY) and 3D (geometry XYZ, what ParaView's Xdmf3 reader needs for 3-component points).
#include <frictherm/coupling/distributed.hpp>

#include "../mpi_ranks.hpp"
#include "../mpi_scratch.hpp"
#include "../mpi_test_main.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <unistd.h>

namespace fc = frictherm::coupling;
using frictherm::test::comm_rank;
using frictherm::test::comm_size;

namespace {

double x_of(std::int64_t id, int d, int snapshot) { return 1e-3 * static_cast<double>(id) + 0.1 * d + 1e-4 * snapshot; }
double v_of(std::int64_t id, int d) { return 0.5 * static_cast<double>(id) - d; }

// Snapshot 0: rank r holds 3 + 2r particles (ids in rank order). Snapshot 1: every rank's first
// particle goes to the next rank and the last rank gives all of its particles to rank 0.
fc::DecomposedSnapshot particles(int snapshot, int rank, int ranks, std::int64_t& total, int dim) {
  std::vector<std::vector<std::int64_t>> owned(static_cast<std::size_t>(ranks));
  std::int64_t id = 0;
  for (int r = 0; r < ranks; ++r)
    for (int k = 0; k < 3 + 2 * r; ++k) owned[static_cast<std::size_t>(r)].push_back(id++);
  total = id;
  if (snapshot == 1) {
    auto moved = owned;
    for (int r = 0; r + 1 < ranks - 1; ++r) {  // first particle of r to r + 1
      moved[static_cast<std::size_t>(r + 1)].push_back(owned[static_cast<std::size_t>(r)].front());
      moved[static_cast<std::size_t>(r)].erase(moved[static_cast<std::size_t>(r)].begin());
    }
    auto& last = moved[static_cast<std::size_t>(ranks - 1)];
    moved[0].insert(moved[0].end(), last.begin(), last.end());
    last.clear();
    owned = moved;
  }
  fc::DecomposedSnapshot s;
  for (std::int64_t i : owned[static_cast<std::size_t>(rank)]) {
    s.id.push_back(i);
    for (int d = 0; d < dim; ++d) s.position.push_back(x_of(i, d, snapshot));
    for (int d = 0; d < dim; ++d) s.velocity.push_back(v_of(i, d));
    s.temperature.push_back(300.0 + static_cast<double>(i));
    s.material.push_back(static_cast<int>(i % 3));
  }
  return s;
}

template <class T>
std::vector<T> read(const std::string& file, const std::string& path, hid_t type, std::size_t expected) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0) << file;
  const hid_t d = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(d, 0) << file << ":" << path;
  const hid_t space = H5Dget_space(d);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  EXPECT_EQ(static_cast<std::size_t>(n), expected) << file << ":" << path;
  std::vector<T> out(static_cast<std::size_t>(n));
  if (n > 0) H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(f);
  return out;
}

// A scalar double attribute of an HDF5 group (the snapshot's `time`).
double read_time(const std::string& file, const std::string& group) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0) << file;
  const hid_t a = H5Aopen_by_name(f, group.c_str(), "time", H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(a, 0) << file << ":" << group << " time";
  double t = -1.0;
  H5Aread(a, H5T_NATIVE_DOUBLE, &t);
  H5Aclose(a);
  H5Fclose(f);
  return t;
}

}  // namespace

class DecomposedOutputDims : public ::testing::TestWithParam<int> {};

TEST_P(DecomposedOutputDims, XdmfJoinsEveryRanksFileAndEveryParticleAppearsOnce) {
  const int rank = comm_rank(), ranks = comm_size(), dim = GetParam();
  const std::string dir = frictherm::test::scratch_folder("/tmp/frictherm_decomposed_");
  const std::string base = dir + "/run";
  std::int64_t total = 0;
  const double times[2] = {0.0, 1.2345678901234567e-6};
  {
    fc::DecomposedOutput out(MPI_COMM_WORLD, base, dim, false);
    for (int s = 0; s < 2; ++s) out.write(10 * s, times[s], particles(s, rank, ranks, total, dim));
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0) {
    std::ifstream in(base + ".xdmf");
    std::stringstream text;
    text << in.rdbuf();
    const std::string xml = text.str();
    // The grids of each snapshot, through the references of their position items.
    std::map<std::string, std::vector<std::pair<std::string, std::size_t>>> grids;  // snapshot -> (file, points)
    const std::string tag = "Format=\"HDF\">";
    for (std::size_t at = xml.find(tag); at != std::string::npos; at = xml.find(tag, at + 1)) {
      const std::size_t start = at + tag.size(), end = xml.find('<', start);
      const std::string ref = xml.substr(start, end - start);  // FILE:/snapshots/IDX/name
      if (ref.size() < 9 || ref.compare(ref.size() - 9, 9, "/position") != 0) continue;
      const std::size_t colon = ref.find(':');
      const std::string file = ref.substr(0, colon), group = ref.substr(colon + 1, ref.size() - colon - 10);
      const std::size_t dims_at = xml.rfind("Dimensions=\"", at) + 12;
      const std::size_t points = std::stoul(xml.substr(dims_at));
      grids[group].push_back({file, points});
    }
    ASSERT_EQ(grids.size(), 2u);
    EXPECT_EQ(grids["/snapshots/000000"].size(), static_cast<std::size_t>(ranks));
    EXPECT_EQ(grids["/snapshots/000001"].size(), static_cast<std::size_t>(ranks - 1));  // the empty rank has none
    EXPECT_NE(xml.find("<Time Value=\"1.2345678901234567e-06\"/>"), std::string::npos);
    // The global ids as a 64-bit attribute (ParaView colours and selects by them across ranks).
    EXPECT_NE(xml.find("<Attribute Name=\"id\" AttributeType=\"Scalar\" Center=\"Node\">\n"
                       "          <DataItem Dimensions=\"3\" NumberType=\"Int\" Precision=\"8\""),
              std::string::npos);
    EXPECT_NE(xml.find(dim == 2 ? "GeometryType=\"XY\"" : "GeometryType=\"XYZ\""), std::string::npos);
    int s = 0;
    for (const auto& [group, parts] : grids) {
      std::vector<int> seen(static_cast<std::size_t>(total), 0);
      for (const auto& [file, n] : parts) {
        const std::string path = dir + "/" + file;
        const auto id = read<std::int64_t>(path, group + "/id", H5T_NATIVE_INT64, n);
        const auto x = read<double>(path, group + "/position", H5T_NATIVE_DOUBLE, static_cast<std::size_t>(dim) * n);
        const auto v = read<double>(path, group + "/velocity", H5T_NATIVE_DOUBLE, 3 * n);
        const auto T = read<double>(path, group + "/temperature", H5T_NATIVE_DOUBLE, n);
        const auto m = read<int>(path, group + "/material", H5T_NATIVE_INT, n);
        EXPECT_EQ(read_time(path, group), times[s]) << path << ":" << group;  // as the serial file's snapshots
        for (std::size_t k = 0; k < n; ++k) {
          ASSERT_GE(id[k], 0);
          ASSERT_LT(id[k], total);
          ++seen[static_cast<std::size_t>(id[k])];
          for (int d = 0; d < dim; ++d) {
            EXPECT_EQ(x[static_cast<std::size_t>(dim) * k + static_cast<std::size_t>(d)], x_of(id[k], d, s));
            EXPECT_EQ(v[3 * k + static_cast<std::size_t>(d)], v_of(id[k], d));
          }
          if (dim == 2) {
            EXPECT_EQ(v[3 * k + 2], 0.0);
          }
          EXPECT_EQ(T[k], 300.0 + static_cast<double>(id[k]));
          EXPECT_EQ(m[k], static_cast<int>(id[k] % 3));
        }
      }
      for (std::int64_t i = 0; i < total; ++i) EXPECT_EQ(seen[static_cast<std::size_t>(i)], 1) << group << " id " << i;
      ++s;
    }
    // The empty rank's group holds the same datasets with 0 rows (temperature included).
    const std::string empty = fc::DecomposedOutput::rank_file(base, ranks - 1);
    EXPECT_TRUE(read<double>(empty, "/snapshots/000001/temperature", H5T_NATIVE_DOUBLE, 0).empty());
    EXPECT_EQ(read_time(empty, "/snapshots/000001"), times[1]);
    std::cout << "[decomposed output " << dim << "D] " << ranks << " ranks, " << total << " particles: " << grids.size()
              << " snapshots read back through " << base << ".xdmf\n";
  }
  // An existing output is refused on every rank without overwrite; with it, it is replaced.
  EXPECT_THROW(fc::DecomposedOutput(MPI_COMM_WORLD, base, dim, false), std::runtime_error);
  EXPECT_NO_THROW(fc::DecomposedOutput(MPI_COMM_WORLD, base, dim, true));
  // Temperatures on some ranks only: every rank throws.
  {
    fc::DecomposedOutput out(MPI_COMM_WORLD, base, dim, true);
    fc::DecomposedSnapshot p = particles(0, rank, ranks, total, dim);
    if (rank == 1) p.temperature.clear();
    EXPECT_THROW(out.write(0, 0.0, p), std::runtime_error);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0 && !std::getenv("FRICTHERM_TEST_KEEP")) std::system(("rm -rf '" + dir + "'").c_str());
}

INSTANTIATE_TEST_SUITE_P(Dims, DecomposedOutputDims, ::testing::Values(2, 3),
                         [](const auto& p) { return std::to_string(p.param) + "D"; });

int main(int argc, char** argv) { return frictherm::test::run_tests_under_mpi(argc, argv); }
