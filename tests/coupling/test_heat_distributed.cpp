// Frictional heating and matrix-free conduction in a decomposed run (frictherm/coupling/decomposed_heat.hpp),
// run by ctest under mpirun with 2 and 4 ranks, against the serial Simulation<2> + Coupler (a window
// every step, forward_euler taken matrix-free, the gather every window: reuse_distance 0):
//   (a) the sliding block with heating (elastic base fixed at y_min, elastic block sliding on it at
//       10 m/s across the rank split, gravity, Coulomb μ = 0.3, USL, uGIMP; both materials conduct):
//       the block's velocity history and the second-order frictional work within 1e-9 of v0 and of the
//       final work at every step, every particle's temperature within 1e-9 of the run's largest
//       temperature rise every 20 steps and at the end, the same sub-step counts; the books summed
//       over ranks close: work received = heat delivered = Σ_i M_i ΔT_i = Σ_p m_p C_p ΔT_p (and the
//       change of Σ_p m_p C_p T_p) to 1e-9 of the work;
//   (b) conduction alone across rank boundaries: a still body (no step, no heat) with a hot diagonal
//       stripe crossing both splits, 8 windows of several sub-steps: particle temperatures within
//       1e-12 of the stripe's 50 K amplitude of the serial Coupler's, the same sub-steps, heat
//       content kept to 1e-14; once with every node an unknown, once with sliver nodes that are not
//       (the lumped gradients G');
//   (c) work on a node with no thermal unknown next to it is refused on every rank;
//   (d) work on sliver nodes that are not unknowns goes to their neighbouring unknowns as the serial
//       Coupler's distribute_heat moves it: temperatures within 1e-12 of 50 K, the amounts relocated
//       equal, the books closed.
// No ASSERT before a collective call: a rank that returned early would leave the others waiting.
#include "frictherm/coupling/coupler.hpp"
#include "frictherm/coupling/decomposed_heat.hpp"
#include "frictherm/mechanics/distributed.hpp"
#include "frictherm/mechanics/geometry.hpp"
#include "frictherm/mechanics/simulation.hpp"

#include "../decomposed_test_support.hpp"
#include "../mpi_ranks.hpp"
#include "decomposed_heat_test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace {

namespace fm = frictherm::mechanics;
namespace fc = frictherm::coupling;
using V2 = fm::Vec<2>;
using frictherm::test::comm_rank;
using frictherm::test::comm_size;
using frictherm::test::decomposed;
using frictherm::test::decomposed_heat_options;
using frictherm::test::elastic;
using frictherm::test::serial_coupler_options;
using frictherm::test::temperature_difference;

constexpr double kT0 = 300.0;  // K


// ---- (a) the sliding block with heating ----
TEST(DecomposedHeat, SlidingBlockEqualsTheSerialRunAndClosesItsBooks) {
  // The scene of test_distributed_contact.cpp (a): base 24 × 4 mm fixed at y_min, block 8 × 4 mm at
  // 10 m/s crossing the 2-rank split, g = 2e4 m/s², Coulomb μ = 0.3, 1 mm cells, 2 × 2 particles per
  // cell. Thermal: base C = 100 J/(kg K), k = 50 W/(m K) (α = 5e-4 m²/s), block C = 150, k = 20, so
  // heat spreads ≈ 0.4 mm in the 200 steps (3.4e-4 s) and the interface warms by ≈ 0.1–1 K.
  frictherm::test::SlidingBlock scene(fm::ShapeKind::ugimp);
  const double h = scene.h, rho = scene.rho, v0 = scene.v0;
  const fm::Grid<2>& grid = scene.grid;
  fm::Simulation<2>& serial = *scene.serial;
  const std::vector<fm::Material>& mats = scene.materials;
  const int blk = scene.block;
  fm::Particles<2>& sp = serial.particles();
  std::fill(sp.temperature.begin(), sp.temperature.end(), kT0);
  const std::vector<fc::ThermalProperties> thermal{{true, 100.0, 50.0}, {true, 150.0, 20.0}};
  fc::Coupler<2> coupler(grid, fm::ShapeKind::ugimp, serial_coupler_options(thermal));
  coupler.start(sp, 0.0);

  fm::DecomposedOptions opt = scene.options;
  opt.particle_scalars = {"temperature"};
  fm::DecomposedMpm2D split(MPI_COMM_WORLD, grid, mats, opt);
  split.add_particles(decomposed(sp, true));
  fc::DecomposedHeat heat(split, decomposed_heat_options(thermal, fm::HeatingOrder::second));
  const double content0 = heat.heat_content();

  const double c = std::sqrt(mats[0].p_wave_modulus(fm::Analysis::plane_strain) / rho);
  const double dt = 0.3 * h / (c + v0);
  const int steps = 200;
  // Temperatures compared every 20 steps and at the end.
  const auto run = frictherm::test::run_heated_block(serial, coupler, split, heat, dt, steps, 20, blk, 1, kT0);
  const double dhist = run.dhist, dw = run.dw, dT = run.dT, rise = run.rise, ws = run.ws, v_end = run.v_end;
  const fc::DecomposedHeatBooks& b = heat.books();
  const double content = heat.heat_content() - content0;
  const fc::EnergyBooks& sb = coupler.books();

  frictherm::test::expect_heated_block_as_serial(run, b, sb, content, steps, v0);
  EXPECT_EQ(sb.heat_relocated, 0.0);  // no work off the unknowns, as the decomposed run requires
  EXPECT_GT(rise, 0.05);              // friction heated the interface
  if (comm_rank() == 0)
    std::printf("[heated sliding block] %d ranks, %d steps: block %.3f -> %.3f m/s, W2 %.6e J, max rise %.4f K, "
                "%ld sub-steps, %ld dropped nodes at the end; max over steps |dv|/v0 %.2e, |dW2|/W2 %.2e, |dT|/rise %.2e; books (/W2): delivered "
                "%.2e, nodal %.2e, particles %.2e, content %.2e; serial books: particles %.2e\n",
                comm_size(), steps, v0, v_end, ws, rise, b.substeps, b.dropped_nodes, dhist / v0, dw / ws, dT / rise,
                (b.heat_delivered - b.work_received) / ws, (b.nodal_energy_change - b.work_received) / ws,
                (b.particle_energy_change - b.work_received) / ws, (content - b.work_received) / ws,
                (coupler.particle_energy_change(sp) - sb.work_received) / ws);
}

// A still body on a 26 × 12 grid of 1 mm cells: a 22 × 8 mm box from (x0, y0), 2 × 2 particles per
// cell, uGIMP, with a hot diagonal stripe crossing the 2- and 4-rank splits. With x0 = y0 = 1.3 mm,
// 1.1 mm (edges off the grid lines) every node with mass is an unknown; with the box starting 20 nm
// before the grid lines x = 1 mm and y = 1 mm, the particles' domains reach 20 nm into the hats of
// the nodes on x = 0 and y = 0, whose M_i (≈ 4e-10 of a full node's) falls below
// active_mass_fraction · max M: nodes with mass that are not unknowns, and gradients lumped (G').
fm::Particles<2> striped_body(int material, bool slivers = false) {
  fm::Particles<2> p;
  const double s = 0.5e-3, rho = 1900.0, x0 = slivers ? 1e-3 - 2e-8 : 1.3e-3, y0 = slivers ? 1e-3 - 2e-8 : 1.1e-3;
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 44; ++i) {
      const V2 x(x0 + (i + 0.5) * s, y0 + (j + 0.5) * s);
      const double d = (x[0] + x[1] - 18e-3) / 2e-3;
      p.add(x, V2::Constant(0.5 * s), rho * s * s, s * s, material, 0, kT0 + 50.0 * std::exp(-d * d));
    }
  return p;
}

// The striped body of material 0 (α = k / (ρ C) = 2.15e-7 m²/s: λ bound ≈ a few 1/s) on its 26 × 12
// grid twice: the serial Coupler's particles and a decomposed run (uGIMP, the temperature carried by
// the particles) with its DecomposedHeat, both started.
struct StripedRun {
  const fm::Grid<2> grid{V2(0.0, 0.0), V2(1e-3, 1e-3), {26, 12}};
  const std::vector<fm::Material> mats{elastic("still", 1e7, 0.3, 1900.0)};
  const std::vector<fc::ThermalProperties> thermal{{true, 1100.0, 0.45}};
  fm::Particles<2> sp;
  fc::Coupler<2> coupler;
  fm::DecomposedMpm2D split;
  fc::DecomposedHeat heat;
  const double content0;  // J

  explicit StripedRun(bool slivers)
      : sp(striped_body(0, slivers)), coupler(grid, fm::ShapeKind::ugimp, serial_coupler_options(thermal)),
        split(MPI_COMM_WORLD, grid, mats, decomposed_options()), heat(started(), decomposed_heat_options(thermal)),
        content0(heat.heat_content()) {}

  static fm::DecomposedOptions decomposed_options() {
    fm::DecomposedOptions opt;
    opt.shape = fm::ShapeKind::ugimp;
    opt.particle_scalars = {"temperature"};
    return opt;
  }
  // The serial coupler started and the particles handed to the decomposed run, before its heat is set up.
  fm::DecomposedMpm2D& started() {
    coupler.start(sp, 0.0);
    split.add_particles(decomposed(sp, true));
    return split;
  }
};

// ---- (b) conduction alone across rank boundaries ----
class DecomposedConduction : public ::testing::TestWithParam<bool> {};

TEST_P(DecomposedConduction, EqualsTheSerialConduction) {
  const bool slivers = GetParam();
  StripedRun run(slivers);
  fm::Particles<2>& sp = run.sp;
  fc::Coupler<2>& coupler = run.coupler;
  fm::DecomposedMpm2D& split = run.split;
  fc::DecomposedHeat& heat = run.heat;
  const double content0 = run.content0;
  // Windows of 1 s take several sub-steps.
  const std::vector<double> none(split.owned_local_nodes().size(), 0.0);
  const double window = 1.0;  // s
  const int windows = 8;
  for (int k = 1; k <= windows; ++k) {
    coupler.after_step(sp, {}, window * k);
    heat.window(none, window);
  }
  bool same = true;
  const double dT = temperature_difference(split.gather(), sp, 1, same);
  const fm::Particles<2> start = striped_body(0, slivers);
  double change = 0.0;
  for (std::size_t k = 0; k < sp.size(); ++k) change = std::max(change, std::fabs(sp.temperature[k] - start.temperature[k]));
  const double drift = std::fabs(heat.heat_content() - content0);
  EXPECT_TRUE(same);
  EXPECT_EQ(coupler.books().matrix_free_windows, windows);
  EXPECT_EQ(heat.books().substeps, coupler.books().matrix_free_substeps);
  EXPECT_GE(heat.books().substeps, 2L * windows);  // more than one sub-step per window
  EXPECT_GT(change, 1.0);                          // the stripe did spread (K)
  if (slivers) {
    EXPECT_GT(heat.books().dropped_nodes, 0L);  // the lumping of G' was used
  }
  // Round-off of reordered sums (measured ≤ 1e-14 of the amplitude); heat conserved by Σ_i G'_ip = 0.
  EXPECT_LE(dT / 50.0, 1e-12);
  EXPECT_LE(drift / content0, 1e-14);
  EXPECT_LE(std::fabs(heat.books().nodal_energy_change) / content0, 1e-14);
  if (comm_rank() == 0)
    std::printf("[conduction%s] %d ranks, %d windows of %.1f s, %ld sub-steps, %ld dropped nodes: largest change "
                "%.3f K, |dT| vs serial %.2e K (%.2e of 50 K), heat content drift %.2e of %.4e J\n",
                slivers ? ", slivers" : "", comm_size(), windows, window, heat.books().substeps, heat.books().dropped_nodes, change, dT,
                dT / 50.0, drift / content0, content0);
}

INSTANTIATE_TEST_SUITE_P(Edges, DecomposedConduction, ::testing::Values(false, true),
                         [](const auto& p) { return std::string(p.param ? "slivers" : "off_grid_lines"); });

// ---- (c) work on a node with no unknown next to it: refused on every rank ----
TEST(DecomposedHeat, RefusesWorkOffTheUnknowns) {
  StripedRun run(false);  // the body of (b) with its edges off the grid lines
  fm::DecomposedMpm2D& split = run.split;
  fc::DecomposedHeat& heat = run.heat;
  // The owned node at DMDA index (0, 0) (the grid's ghost corner) and its neighbours hold no mass: work
  // there on rank 0 has nowhere to go.
  std::vector<double> joules(split.owned_local_nodes().size(), 0.0);
  const std::array<int, 4> box = split.owned_nodes();
  if (box[0] == 0 && box[2] == 0) joules[0] = 1.0;
  EXPECT_THROW(heat.window(joules, 1.0), std::runtime_error);
  fc::DecomposedHeatOptions missing;  // no thermal properties for material 0
  EXPECT_THROW(fc::DecomposedHeat(split, missing), std::invalid_argument);
}

// ---- (d) work on nodes that are not unknowns, relocated to their neighbouring unknowns ----
TEST(DecomposedHeat, RelocatesWorkOffTheUnknownsAsTheSerialCoupler) {
  // The sliver body of (b): 2 J on the sliver node at lattice (14, 0) (y = 0: not an unknown, its
  // neighbours on y = 1 mm are; they straddle the x cut at lattice 14 | 15 of 2 and 4 ranks), 1.5 J on
  // the sliver node (0, 7) (its neighbours straddle the y cut at 7 | 8 of 4 ranks) and 1 J on an
  // unknown, in each of 3 windows of 1 s, with the serial Coupler given the same grid-node work (its
  // distribute_heat moves the 3.5 J in proportion to M_i).
  StripedRun run(true);
  const fm::Grid<2>& grid = run.grid;
  fm::Particles<2>& sp = run.sp;
  fc::Coupler<2>& coupler = run.coupler;
  fm::DecomposedMpm2D& split = run.split;
  fc::DecomposedHeat& heat = run.heat;
  const double content0 = run.content0;
  // DMDA index = serial lattice index + 1 = the serial node's index along each axis.
  const int sliver[2] = {15, 1}, sliver2[2] = {1, 8}, inside[2] = {12, 7};
  const auto& npd = grid.nodes_per_dim();
  std::vector<double> serial_work(grid.node_count(), 0.0);
  serial_work[static_cast<std::size_t>(sliver[1] * npd[0] + sliver[0])] = 2.0;
  serial_work[static_cast<std::size_t>(sliver2[1] * npd[0] + sliver2[0])] = 1.5;
  serial_work[static_cast<std::size_t>(inside[1] * npd[0] + inside[0])] = 1.0;
  std::vector<double> joules(split.owned_local_nodes().size(), 0.0);
  const std::array<int, 4> box = split.owned_nodes();
  auto put = [&](const int* n, double w) {
    if (n[0] >= box[0] && n[0] < box[1] && n[1] >= box[2] && n[1] < box[3])
      joules[static_cast<std::size_t>((n[1] - box[2]) * (box[1] - box[0]) + n[0] - box[0])] = w;
  };
  put(sliver, 2.0);
  put(sliver2, 1.5);
  put(inside, 1.0);
  const int windows = 3;
  for (int k = 1; k <= windows; ++k) {
    coupler.after_step(sp, serial_work, 1.0 * k);
    heat.window(joules, 1.0);
  }
  bool same = true;
  const double dT = temperature_difference(split.gather(), sp, 1, same);
  const fc::DecomposedHeatBooks& b = heat.books();
  const double added = 4.5 * windows, content = heat.heat_content() - content0;
  EXPECT_TRUE(same);
  EXPECT_GT(b.dropped_nodes, 0L);
  EXPECT_EQ(b.substeps, coupler.books().matrix_free_substeps);
  EXPECT_EQ(coupler.books().heat_relocated, 3.5 * windows);
  EXPECT_EQ(b.heat_relocated, 3.5 * windows);
  // Round-off of reordered sums, as (b); the heat added is all there (1e-9 of the 13.5 J, against Σ m C T
  // ≈ 1.1e5 J).
  EXPECT_LE(dT / 50.0, 1e-12);
  EXPECT_LE(std::fabs(b.heat_delivered - added) / added, 1e-14);
  EXPECT_LE(std::fabs(b.nodal_energy_change - added) / added, 1e-12);
  EXPECT_LE(std::fabs(content - added) / added, 1e-9);
  if (comm_rank() == 0)
    std::printf("[relocation] %d ranks, %d windows: %.1f J relocated (serial %.1f J), |dT| vs serial %.2e of 50 K; "
                "books (/added): delivered %.2e, nodal %.2e, content %.2e\n",
                comm_size(), windows, b.heat_relocated, coupler.books().heat_relocated, dT / 50.0,
                (b.heat_delivered - added) / added, (b.nodal_energy_change - added) / added, (content - added) / added);
}

}  // namespace

int main(int argc, char** argv) {
  fm::DecomposedPetscSession session(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
