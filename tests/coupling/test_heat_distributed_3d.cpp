// Frictional heating, matrix-free conduction, hot spots and output of a decomposed run in 3D
// (frictherm/coupling/decomposed_heat.hpp on DecomposedMpm<3>), run by ctest under mpirun with 2 and 4
// ranks, against the serial Simulation<3> + Coupler<3> (a window every step, forward_euler taken
// matrix-free, the gather every window: reuse_distance 0), the 2D test's reference:
//   (a) the heated sliding block in 3D: base 10 × 4 × 2 mm fixed at z_min, block 4 × 4 × 2 mm sliding
//       along x at 10 m/s across the x cut, pressed by g = 2e4 m/s² along −z, Coulomb μ = 0.3 with the
//       specified normal (0, 0, 1), uGIMP, 2³ particles per cell, 12 × 6 × 5 cells of 1 mm, 150 steps
//       (the scene of test_distributed_3d.cpp (d)); both materials conduct. Asserted: the block's
//       velocity history and the second-order frictional work within 1e-9 of v0 and of the final
//       work at every step, every particle's temperature within 1e-9 of the run's largest rise every
//       25 steps and at the end, the same sub-step counts, the work on nodes that are not thermal
//       unknowns relocated to their neighbours as the serial run does; books summed over ranks: work received =
//       heat delivered = Σ_i M_i ΔT_i = Σ_p m_p C_p ΔT_p (and the change of Σ_p m_p C_p T_p) to 1e-9
//       of the work;
//   (b) its hot spots (rise above 0.3 of the largest rise) found across ranks from the decomposed
//       particles = a serial tracker's on the serial particles (same count, members by id, peaks,
//       centroids and excess energies within 1e-9 of their scales); the largest one, along the sliding
//       interface, holds particles of two or more ranks (on 2 and 4 ranks) and is one hot spot;
//   (c) one snapshot of the run written per rank (DecomposedOutput, dim 3) and read back on rank 0
//       through the XDMF's references with the HDF5 C API: the XDMF names every rank's file, its
//       geometry is XYZ, every particle appears once with the gathered position and temperature.
// No ASSERT before a collective call: a rank that returned early would leave the others waiting.
#include "frictherm/coupling/coupler.hpp"
#include "frictherm/coupling/decomposed_heat.hpp"
#include "frictherm/coupling/distributed.hpp"
#include "frictherm/mechanics/distributed.hpp"
#include "frictherm/mechanics/geometry.hpp"
#include "frictherm/mechanics/simulation.hpp"

#include "../decomposed_test_support.hpp"
#include "../mpi_ranks.hpp"
#include "../mpi_scratch.hpp"
#include "decomposed_heat_test_support.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>

namespace {

namespace fm = frictherm::mechanics;
namespace fc = frictherm::coupling;
using V3 = fm::Vec<3>;
using Mpm = fm::DecomposedMpm3D;
using frictherm::test::comm_rank;
using frictherm::test::comm_size;

constexpr double kT0 = 300.0;  // K

template <class T>
std::vector<T> read(const std::string& file, const std::string& path, hid_t type) {
  std::vector<T> out;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return out;
  const hid_t d = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
  if (d >= 0) {
    const hid_t space = H5Dget_space(d);
    out.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
    if (!out.empty()) H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
    H5Sclose(space);
    H5Dclose(d);
  }
  H5Fclose(f);
  return out;
}

// Ranks holding at least one of `ids` (collective).
int ranks_holding(const std::vector<std::size_t>& ids, const std::vector<std::int64_t>& local_ids) {
  const std::set<std::size_t> members(ids.begin(), ids.end());
  int mine = 0;
  for (std::int64_t id : local_ids) mine = mine || members.count(static_cast<std::size_t>(id)) > 0;
  int holding = 0;
  MPI_Allreduce(&mine, &holding, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  return holding;
}

TEST(DecomposedHeat3D, SlidingBlockEqualsTheSerialRunWithHotSpotsAndOutput) {
  // ---- the serial coupled run (the reference): the 3D sliding block of decomposed_test_support.hpp ----
  frictherm::test::SlidingBlock3D scene(fm::ShapeKind::ugimp);
  const double h = scene.h, rho = scene.rho, v0 = scene.v0;
  const fm::Grid<3>& grid = scene.grid;
  const std::vector<fm::Material>& mats = scene.materials;
  fm::Simulation<3>& serial = *scene.serial;
  const int blk = scene.block;
  fm::Particles<3>& sp = serial.particles();
  std::fill(sp.temperature.begin(), sp.temperature.end(), kT0);
  // Thermal: base C = 100 J/(kg K), k = 50 W/(m K) (α = 5e-4 m²/s), block C = 150, k = 20: heat spreads
  // ≈ 0.3 mm over the run's 2.3e-4 s and the interface warms by a fraction of a kelvin.
  const std::vector<fc::ThermalProperties> thermal{{true, 100.0, 50.0}, {true, 150.0, 20.0}};
  fc::Coupler<3> coupler(grid, fm::ShapeKind::ugimp, frictherm::test::serial_coupler_options(thermal));
  coupler.start(sp, 0.0);

  // ---- the decomposed run: temperature and its reference T0_p travel with the particles ----
  Mpm::Options opt = scene.options;
  opt.particle_scalars = {"temperature", "reference_temperature"};
  Mpm split(MPI_COMM_WORLD, grid, mats, opt);
  std::vector<Mpm::Particle> given = frictherm::test::decomposed(sp, true);
  for (Mpm::Particle& p : given) p.scalars.push_back(kT0);
  split.add_particles(given);
  fc::DecomposedHeat heat(split, frictherm::test::decomposed_heat_options(thermal, fm::HeatingOrder::second));
  const double content0 = heat.heat_content();

  const double c = std::sqrt(mats[0].p_wave_modulus(fm::Analysis::three_d) / rho);
  const double dt = 0.3 * h / (c + v0);
  const int steps = 150;
  // Temperatures (and T0_p, the second scalar) compared every 25 steps and at the end.
  const auto run = frictherm::test::run_heated_block(serial, coupler, split, heat, dt, steps, 25, blk, 2, kT0);
  const double dhist = run.dhist, dw = run.dw, dT = run.dT, rise = run.rise, time = run.time, ws = run.ws, v_end = run.v_end;
  const std::vector<Mpm::Particle>& a = run.last;
  const fc::DecomposedHeatBooks& b = heat.books();
  const double content = heat.heat_content() - content0;
  const fc::EnergyBooks& sb = coupler.books();

  EXPECT_EQ(heat.dim(), 3);
  frictherm::test::expect_heated_block_as_serial(run, b, sb, content, steps, v0);
  // Work on nodes that are not unknowns moved to their neighbouring unknowns, as the serial run moved it.
  EXPECT_LE(std::fabs(b.heat_relocated - sb.heat_relocated) / ws, 1e-9);
  EXPECT_GT(rise, 0.0);  // friction heated the interface
  if (comm_rank() == 0)
    std::printf("[heated sliding block 3D] %d ranks, %d steps: block %.3f -> %.3f m/s, W2 %.6e J, max rise %.4f K, "
                "%ld sub-steps, %ld dropped nodes at the end, relocated %.3e J (serial %.3e J); max over steps |dv|/v0 %.2e, |dW2|/W2 %.2e, |dT|/rise "
                "%.2e; books (/W2): delivered %.2e, nodal %.2e, particles %.2e, content %.2e; serial books: particles "
                "%.2e\n",
                comm_size(), steps, v0, v_end, ws, rise, b.substeps, b.dropped_nodes, b.heat_relocated,
                sb.heat_relocated, dhist / v0, dw / ws, dT / rise,
                (b.heat_delivered - b.work_received) / ws, (b.nodal_energy_change - b.work_received) / ws,
                (b.particle_energy_change - b.work_received) / ws, (content - b.work_received) / ws,
                (coupler.particle_energy_change(sp) - sb.work_received) / ws);

  // ---- (b) hot spots across ranks = the serial tracker's ----
  fc::HotSpotOptions hopt;
  hopt.threshold = 0.3 * rise;
  fc::HotSpotTracker serial_spots(3, hopt), split_spots(3, hopt);
  std::vector<double> T0(sp.size(), kT0);
  {
    fm::Particles<3> reference = sp;
    reference.temperature = T0;
    serial_spots.set_reference(reference);
  }
  serial_spots.update(sp, thermal, time);
  heat.update_hot_spots(split_spots, "reference_temperature", time);
  const std::vector<fc::HotSpot>& hs = serial_spots.hot_spots();
  const std::vector<fc::HotSpot>& hd = split_spots.hot_spots();
  EXPECT_EQ(hd.size(), hs.size());
  EXPECT_GE(hs.size(), 1u);
  double dpeak = 0.0, dcentroid = 0.0, dexcess = 0.0;
  bool same_members = hd.size() == hs.size();
  for (std::size_t k = 0; same_members && k < hs.size(); ++k) {
    same_members = hd[k].particles == hs[k].particles && hd[k].id == hs[k].id;
    dpeak = std::max(dpeak, std::fabs(hd[k].peak_temperature - hs[k].peak_temperature));
    for (int d = 0; d < 3; ++d)
      dcentroid = std::max(dcentroid, std::fabs(hd[k].centroid[static_cast<std::size_t>(d)] -
                                                hs[k].centroid[static_cast<std::size_t>(d)]));
    dexcess = std::max(dexcess, std::fabs(hd[k].excess_energy - hs[k].excess_energy) / std::fabs(hs[k].excess_energy));
  }
  EXPECT_TRUE(same_members);
  EXPECT_LE(dpeak / rise, 1e-9);
  EXPECT_LE(dcentroid / h, 1e-9);
  EXPECT_LE(dexcess, 1e-9);
  EXPECT_LE(std::fabs(split_spots.max_temperature() - serial_spots.max_temperature()) / rise, 1e-9);
  // The largest hot spot: the sliding interface, across the x cut.
  std::size_t largest = 0;
  for (std::size_t k = 1; k < hd.size(); ++k)
    if (hd[k].particle_count > hd[largest].particle_count) largest = k;
  const fm::DecomposedLocalParticles local = split.local_particle_data();
  const int holding = hd.empty() ? 0 : ranks_holding(hd[largest].particles, local.id);
  if (comm_size() > 1) {
    EXPECT_GE(holding, 2);
  }
  if (comm_rank() == 0) {
    std::printf("[hot spots 3D] threshold %.4f K rise: %zu hot spot(s) (serial %zu), sizes", hopt.threshold, hd.size(),
                hs.size());
    for (const fc::HotSpot& x : hd) std::printf(" %zu", x.particle_count);
    std::printf("; the largest on %d rank(s); |d peak|/rise %.2e, |d centroid|/h %.2e, |d excess| %.2e\n", holding,
                dpeak / rise, dcentroid / h, dexcess);
  }

  // ---- (c) one snapshot per rank joined by one XDMF, read back on rank 0 ----
  const std::string dir = frictherm::test::scratch_folder("/tmp/frictherm_heat3d_"), base_path = dir + "/heat3d";
  {
    fc::DecomposedOutput out(MPI_COMM_WORLD, base_path, 3, false);
    out.write(steps, time, heat.snapshot());
  }
  unsigned long long with_particles = split.local_particles() > 0 ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &with_particles, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() == 0) {
    std::ifstream in(base_path + ".xdmf");
    std::stringstream text;
    text << in.rdbuf();
    const std::string xml = text.str();
    EXPECT_NE(xml.find("GeometryType=\"XYZ\""), std::string::npos);
    EXPECT_NE(xml.find("CollectionType=\"Temporal\""), std::string::npos);
    std::vector<int> seen(sp.size(), 0);
    double dx = 0.0, dTo = 0.0;
    std::size_t files = 0, points = 0;
    for (int r = 0; r < comm_size(); ++r) {
      const std::string name = fc::DecomposedOutput::rank_file("heat3d", r);
      if (xml.find(name + ":/snapshots/000000/position") == std::string::npos) continue;
      ++files;
      const std::string path = dir + "/" + name, group = "/snapshots/000000/";
      const auto id = read<std::int64_t>(path, group + "id", H5T_NATIVE_INT64);
      const auto x = read<double>(path, group + "position", H5T_NATIVE_DOUBLE);
      const auto T = read<double>(path, group + "temperature", H5T_NATIVE_DOUBLE);
      points += id.size();
      EXPECT_EQ(x.size(), 3 * id.size());
      EXPECT_EQ(T.size(), id.size());
      for (std::size_t k = 0; k < id.size() && x.size() == 3 * id.size() && T.size() == id.size(); ++k) {
        if (id[k] < 0 || static_cast<std::size_t>(id[k]) >= a.size()) continue;
        const Mpm::Particle& p = a[static_cast<std::size_t>(id[k])];  // gathered after the last step, by id
        ++seen[static_cast<std::size_t>(id[k])];
        for (int d = 0; d < 3; ++d) dx = std::max(dx, std::fabs(x[3 * k + static_cast<std::size_t>(d)] - p.position[d]));
        dTo = std::max(dTo, std::fabs(T[k] - p.scalars[0]));
      }
    }
    EXPECT_EQ(files, static_cast<std::size_t>(with_particles));  // every rank with particles has its file named
    EXPECT_EQ(points, sp.size());
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<std::ptrdiff_t>(sp.size()));
    EXPECT_EQ(dx, 0.0);  // the values written are the run's
    EXPECT_EQ(dTo, 0.0);
    std::printf("[output 3D] %zu rank files named by %s.xdmf, %zu particles read back\n", files, base_path.c_str(), points);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() == 0 && !std::getenv("FRICTHERM_TEST_KEEP")) std::system(("rm -rf '" + dir + "'").c_str());
}

}  // namespace

int main(int argc, char** argv) {
  fm::DecomposedPetscSession session(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
