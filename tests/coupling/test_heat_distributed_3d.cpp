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
using frictherm::test::elastic;
using frictherm::test::mean_velocity_x;

constexpr double kT0 = 300.0, h = 1e-3, rho = 1000.0, v0 = 10.0, g = 2e4, mu = 0.3;  // K, m, kg/m³, m/s

// Largest |T_p − T_p(serial)| over the gathered particles (by id), and whether the ids match.
double temperature_difference(const std::vector<Mpm::Particle>& a, const fm::Particles<3>& sp, bool& same) {
  double d = 0.0;
  same = same && a.size() == sp.size();
  for (std::size_t k = 0; same && k < a.size(); ++k) {
    same = a[k].id == static_cast<std::int64_t>(k) && a[k].scalars.size() == 2;
    if (same) d = std::max(d, std::fabs(a[k].scalars[0] - sp.temperature[k]));
  }
  return d;
}

// A scratch folder made by rank 0 and known to all.
std::string scratch() {
  std::string dir;
  if (comm_rank() == 0) {
    char tmpl[] = "/tmp/frictherm_heat3d_XXXXXX";
    dir = mkdtemp(tmpl);
  }
  int length = static_cast<int>(dir.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD);
  dir.resize(static_cast<std::size_t>(length));
  MPI_Bcast(dir.data(), length, MPI_CHAR, 0, MPI_COMM_WORLD);
  return dir;
}

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
  // ---- the serial coupled run (the reference) ----
  const fm::Grid<3> grid(V3::Zero(), V3::Constant(h), {12, 6, 5});
  const std::vector<fm::Material> mats{elastic("base", 2e7, 0.3, rho), elastic("block", 1.5e7, 0.25, rho)};
  fm::SimulationOptions so;
  so.shape = fm::ShapeKind::ugimp;
  so.scheme = fm::UpdateScheme::usl;
  so.gravity = V3(0.0, 0.0, -g);
  fm::Simulation<3> serial(grid, so);
  const int base = serial.add_material(mats[0]), blk = serial.add_material(mats[1]);
  serial.add_body("base", *fm::make_box<3>(V3(1e-3, 1e-3, 0.0), V3(11e-3, 5e-3, 2e-3), base), 2, V3::Zero());
  serial.add_body("block", *fm::make_box<3>(V3(2e-3, 1e-3, 2e-3), V3(6e-3, 5e-3, 4e-3), blk), 2, V3(v0, 0.0, 0.0));
  const fm::FixedFace bottom{2, false, {{true, true, true}}};
  serial.fix_face(bottom);
  fm::ContactOptions co;
  co.default_pair.law = fm::FrictionLaw::coulomb(mu);
  co.default_pair.normal = fm::NormalMethod::specified;
  co.default_pair.normal_vector = V3(0.0, 0.0, 1.0);
  serial.enable_contact(co);
  serial.set_contact_pair(base, blk, co.default_pair);
  serial.finalize();
  fm::Particles<3>& sp = serial.particles();
  std::fill(sp.temperature.begin(), sp.temperature.end(), kT0);
  // Thermal: base C = 100 J/(kg K), k = 50 W/(m K) (α = 5e-4 m²/s), block C = 150, k = 20: heat spreads
  // ≈ 0.3 mm over the run's 2.3e-4 s and the interface warms by a fraction of a kelvin.
  const std::vector<fc::ThermalProperties> thermal{{true, 100.0, 50.0}, {true, 150.0, 20.0}};
  fc::CouplerOptions copt;
  copt.materials = thermal;
  copt.integrator = "forward_euler";  // matrix-free for windows of ≤ 64 stable sub-steps
  copt.window.kind = fc::WindowPolicy::Kind::every_step;
  copt.reuse_distance = 0.0;  // gather every window
  fc::Coupler<3> coupler(grid, fm::ShapeKind::ugimp, copt);
  coupler.start(sp, 0.0);

  // ---- the decomposed run: temperature and its reference T0_p travel with the particles ----
  Mpm::Options opt;
  opt.shape = so.shape;
  opt.gravity = V3(0.0, 0.0, -g);
  opt.fixed_faces = {bottom};
  opt.contact = true;
  opt.contact_options = co;
  opt.contact_pairs = {fm::DecomposedContactPair{base, blk, co.default_pair}};
  opt.particle_scalars = {"temperature", "reference_temperature"};
  Mpm split(MPI_COMM_WORLD, grid, mats, opt);
  std::vector<Mpm::Particle> given = frictherm::test::decomposed(sp, true);
  for (Mpm::Particle& p : given) p.scalars.push_back(kT0);
  split.add_particles(given);
  fc::DecomposedHeatOptions ho;
  ho.materials = thermal;
  ho.order = fm::HeatingOrder::second;
  fc::DecomposedHeat heat(split, ho);
  const double content0 = heat.heat_content();

  const double c = std::sqrt(mats[0].p_wave_modulus(fm::Analysis::three_d) / rho);
  const double dt = 0.3 * h / (c + v0);
  const int steps = 150;
  double dhist = 0.0, dw = 0.0, dT = 0.0, rise = 0.0, time = 0.0, ws = 0.0;
  bool same = true;
  std::vector<Mpm::Particle> a;
  for (int s = 1; s <= steps; ++s) {
    serial.step(dt);
    time += dt;
    coupler.after_step(sp, serial.frictional_work(fm::HeatingOrder::second), time);
    split.step(dt);
    heat.after_step(dt);
    ws = serial.cumulative_frictional_work(fm::HeatingOrder::second);
    dw = std::max(dw, std::fabs(split.cumulative_frictional_work(fm::HeatingOrder::second) - ws));
    a = split.gather();
    dhist = std::max(dhist, std::fabs(mean_velocity_x(a, blk) - mean_velocity_x(sp, blk)));
    if (s % 25 == 0) dT = std::max(dT, temperature_difference(a, sp, same));
  }
  for (double T : sp.temperature) rise = std::max(rise, T - kT0);
  const fc::DecomposedHeatBooks& b = heat.books();
  const double content = heat.heat_content() - content0;
  const fc::EnergyBooks& sb = coupler.books();
  const double v_end = mean_velocity_x(sp, blk);

  EXPECT_EQ(heat.dim(), 3);
  EXPECT_TRUE(same);  // every particle kept, with its temperature
  EXPECT_EQ(sb.matrix_free_windows, steps);  // the serial run took the matrix-free path every step
  // Work on nodes that are not unknowns moved to their neighbouring unknowns, as the serial run moved it.
  EXPECT_LE(std::fabs(b.heat_relocated - sb.heat_relocated) / ws, 1e-9);
  EXPECT_EQ(b.windows, steps);
  EXPECT_EQ(b.substeps, sb.matrix_free_substeps);
  EXPECT_LT(v_end, v0 - 0.5);  // friction braked the block
  EXPECT_GT(rise, 0.0);        // and heated the interface
  // The 1e-9 of the case's own scales: v0, the final work, the largest temperature rise.
  EXPECT_LE(dhist / v0, 1e-9);
  EXPECT_LE(dw / ws, 1e-9);
  EXPECT_LE(dT / rise, 1e-9);
  EXPECT_LE(std::fabs(b.work_received - ws) / ws, 1e-9);
  // Books over ranks: heat delivered = work received (no relocation), and conduction creates no heat.
  EXPECT_LE(std::fabs(b.heat_delivered - b.work_received) / ws, 1e-9);
  EXPECT_LE(std::fabs(b.nodal_energy_change - b.work_received) / ws, 1e-9);
  EXPECT_LE(std::fabs(b.particle_energy_change - b.work_received) / ws, 1e-9);
  EXPECT_LE(std::fabs(content - b.work_received) / ws, 1e-9);
  EXPECT_LE(b.max_capacity_residual, 1e-12);  // Σ_i M_i = Σ_p m_p C_p (partition of unity)
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
  const std::string dir = scratch(), base_path = dir + "/heat3d";
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
