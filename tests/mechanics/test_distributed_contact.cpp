// Decomposed multimaterial contact with frictional heating (frictherm/mechanics/distributed.hpp),
// run by ctest under mpirun with 2 and 4 ranks, against the serial module's Simulation<2> built
// through its own API with the same options (USL, FLIP, the same contact settings):
//   (a) a small sliding block: an elastic block sliding with Coulomb friction on an elastic base
//       fixed at y_min, pressed by gravity: every particle's position and velocity, the block's
//       velocity history and the frictional work (first and second order, summed over owned nodes
//       and ranks) equal the serial run's to 1e-9 of the case's own scales at every step; the work
//       of each step per owned node, summed over ranks, is the step's increment of the cumulative
//       work (the books the thermal hand-off reads);
//   (b) an isolated oblique impact of two materials (no velocity condition, no gravity): linear
//       momentum conserved to round-off at every step, every particle kept, and again the serial
//       run to 1e-9;
//   (c) the refusals of what the decomposed contact does not support;
//   (d) three materials meeting at nodes (lumped virtual material, eqs. 39–40) = the serial run;
//   (e) fixed faces on the upper sides (the serial fix_face's nodes) = the serial run.
// The contact cases (a), (b), (d) also assert that per-material entries crossed the star forest on
// 2 and 4 ranks (their contact surfaces cross the split).
// No ASSERT before a collective call: a rank that returned early would leave the others waiting.
#include "frictherm/mechanics/distributed.hpp"
#include "frictherm/mechanics/geometry.hpp"
#include "frictherm/mechanics/simulation.hpp"

#include "../decomposed_test_support.hpp"
#include "../mpi_ranks.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace {

namespace fm = frictherm::mechanics;
using V2 = fm::Vec<2>;

using frictherm::test::comm_rank;
using frictherm::test::comm_size;
using frictherm::test::elastic;

using Difference = frictherm::test::SerialDifference;

// Per-material entries sent over the star forest, over all ranks and steps (the sparse exchange).
long field_entries(const fm::DecomposedMpm2D& run) {
  long e = run.traffic().field_entries_sent;
  MPI_Allreduce(MPI_IN_PLACE, &e, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return e;
}

void print_phases(const char* label, const fm::DecomposedMpm2D& run) {
  const fm::DecomposedTraffic& t = run.traffic();
  long ghost = t.ghost_nodes, sent = t.particles_sent, multi = t.multi_ghost_nodes, entries = t.field_entries_sent;
  MPI_Allreduce(MPI_IN_PLACE, &ghost, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &sent, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &multi, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &entries, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  const double steps = t.steps > 0 ? static_cast<double>(t.steps) : 1.0;
  std::printf("[traffic] %s: %d ranks, %d velocity fields; DMDA exchanges %d doubles per ghost node, %ld ghost nodes "
              "in all = %.2f kB per exchange in all; per step in all: %.1f multi-material ghost nodes, %.1f "
              "per-material entries of %d B each way = %.2f kB; migration %.2f particles at %d B\n",
              label, comm_size(), run.velocity_fields(), t.values_per_node, ghost,
              ghost * t.values_per_node * 8.0 / 1024.0, multi / steps, entries / steps, t.field_entry_bytes,
              entries / steps * t.field_entry_bytes / 1024.0, sent / steps, t.particle_bytes);
  std::printf("[phases] %s, rank 0, s:", label);
  for (std::size_t p = 0; p < fm::DecomposedMpm2D::phase_names().size(); ++p)
    std::printf(" %s %.4f", fm::DecomposedMpm2D::phase_names()[p], t.phase_seconds[p]);
  std::printf("\n");
}

// ---- (a) the sliding block: decomposed = serial in particles, velocity history and frictional work ----
class DecomposedSlidingBlock : public ::testing::TestWithParam<fm::ShapeKind> {};

TEST_P(DecomposedSlidingBlock, EqualsTheSerialRunWithHeating) {
  // Base 24 × 4 mm fixed at y_min, block 8 × 4 mm on it sliding at 10 m/s (straddling the x = 13.5 mm
  // boundary of the 2-rank split and crossing it), pressed by g = 2e4 m/s²
  // (Coulomb μ = 0.3: deceleration μg = 6e3 m/s², about 2 m/s over the run); 1 mm cells, 2 × 2
  // particles per cell, the interface on a grid line. Specified normal (0, 1) from base to block.
  const frictherm::test::SlidingBlock sb(GetParam());
  const double h = sb.h, rho = sb.rho, v0 = sb.v0;
  fm::Simulation<2>& serial = *sb.serial;
  const std::vector<fm::Material>& mats = sb.materials;
  const int blk = sb.block;
  fm::DecomposedMpm2D split(MPI_COMM_WORLD, sb.grid, mats, sb.options);
  split.add_particles(frictherm::test::decomposed(serial.particles()));

  const double c = std::sqrt(mats[0].p_wave_modulus(fm::Analysis::plane_strain) / rho);
  const double dt = 0.3 * h / (c + v0);
  const int steps = 200;
  frictherm::test::SlidingDifferences diff;
  for (int s = 0; s < steps; ++s)
    diff.step(s, serial, split, dt, blk, [&](const auto& a) { return frictherm::test::compare_with_serial<2>(a, serial); });
  EXPECT_EQ(split.global_particles(), static_cast<long long>(serial.particles().size()));
  long sent = split.traffic().particles_sent;
  MPI_Allreduce(MPI_IN_PLACE, &sent, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  const long entries = field_entries(split);
  if (comm_size() > 1) {
    EXPECT_GT(sent, 0L);     // block particles crossed rank boundaries
    EXPECT_GT(entries, 0L);  // and the contact surface: per-material sums travelled over the star forest
  }
  // Round-off grows in the contact decisions and the stress: 1e-9 of the case's scales.
  frictherm::test::expect_sliding_block_equals_serial(diff, h, v0);
  frictherm::test::print_sliding_block("sliding block", fm::to_string(GetParam()), steps, h, v0, diff);
  print_phases(fm::to_string(GetParam()), split);
}

INSTANTIATE_TEST_SUITE_P(Kernels, DecomposedSlidingBlock,
                         ::testing::Values(fm::ShapeKind::linear, fm::ShapeKind::ugimp),
                         [](const auto& p) { return std::string(fm::to_string(p.param)); });

// ---- (b) an isolated impact of two materials: momentum conserved, particles kept, = serial ----
TEST(DecomposedContact, IsolatedImpactConservesMomentumAndEqualsSerial) {
  // Two blocks meeting obliquely (relative velocity (−12, 4) m/s) with Coulomb μ = 0.4 and the
  // default normal (maximum volume gradient), at x ≈ 14.75 mm, where the 2-rank split (x = 14.5 mm)
  // puts the contact nodes on both ranks; no velocity condition, no gravity.
  const double h = 1e-3, rho = 1000.0;
  const fm::Grid<2> grid(V2(0.0, 0.0), V2(h, h), {28, 18});
  const fm::SimulationOptions so = frictherm::test::usl_options(fm::ShapeKind::ugimp);
  fm::Simulation<2> serial(grid, so);
  const std::vector<fm::Material> mats{elastic("left", 1e7, 0.3, rho), elastic("right", 2e7, 0.3, 1500.0)};
  const int a = serial.add_material(mats[0]), b = serial.add_material(mats[1]);
  serial.add_body("left", *fm::make_box<2>(V2(7.5e-3, 4e-3), V2(14.5e-3, 10e-3), a), 2, V2(6.0, -1.0));
  serial.add_body("right", *fm::make_box<2>(V2(15e-3, 7e-3), V2(21.5e-3, 13e-3), b), 2, V2(-6.0, 3.0));
  fm::ContactOptions co;
  co.default_pair.law = fm::FrictionLaw::coulomb(0.4);
  serial.enable_contact(co);
  serial.finalize();

  fm::DecomposedMpm2D split(MPI_COMM_WORLD, grid, mats, frictherm::test::matching_options<2>(so, co));
  split.add_particles(frictherm::test::decomposed(serial.particles()));
  const V2 p0 = split.total_momentum();
  const double scale = split.total_momentum_scale();
  const double c = std::max(std::sqrt(mats[0].p_wave_modulus(fm::Analysis::plane_strain) / rho),
                            std::sqrt(mats[1].p_wave_modulus(fm::Analysis::plane_strain) / 1500.0));
  const double dt = 0.3 * h / (c + 8.0);
  double drift = 0.0, dx = 0.0, dv = 0.0;
  long max_contact = 0, max_sliding = 0;
  bool same_ids = true;
  for (int s = 0; s < 150; ++s) {
    serial.step(dt);
    split.step(dt);
    drift = std::max(drift, (split.total_momentum() - p0).norm() / scale);
    const fm::DecomposedContactStats st = split.contact_stats();
    max_contact = std::max(max_contact, st.contact_nodes);
    max_sliding = std::max(max_sliding, st.sliding_nodes);
    if (s % 10 == 9) {
      const Difference d = frictherm::test::compare_with_serial<2>(split.gather(), serial);
      same_ids = same_ids && d.same_ids;
      dx = std::max(dx, d.position), dv = std::max(dv, d.velocity);
    }
  }
  const double w = split.cumulative_frictional_work(fm::HeatingOrder::first);
  const double ws = serial.cumulative_frictional_work(fm::HeatingOrder::first);
  // The bodies met and rubbed; the right body's x momentum was exchanged with the left's.
  EXPECT_GT(max_contact, 0L);
  EXPECT_GT(max_sliding, 0L);
  EXPECT_GT(ws, 0.0);
  EXPECT_TRUE(same_ids);
  EXPECT_EQ(split.global_particles(), static_cast<long long>(serial.particles().size()));
  // Contact changes are ±Δp at a node (eq. 12) and Σ_i f_i = 0: momentum to round-off.
  EXPECT_LE(drift, 1e-12);
  EXPECT_LE(dx / h, 1e-9);
  EXPECT_LE(dv / 12.0, 1e-9);
  EXPECT_LE(std::fabs(w - ws) / ws, 1e-9);
  long sent = split.traffic().particles_sent;
  MPI_Allreduce(MPI_IN_PLACE, &sent, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  const long entries = field_entries(split);
  if (comm_size() > 1) {
    EXPECT_GT(sent, 0L);     // particles crossed rank boundaries
    EXPECT_GT(entries, 0L);  // per-material sums travelled over the star forest
  }
  if (comm_rank() == 0)
    std::printf("[impact] 150 steps: momentum drift %.2e of Σm|v|; vs serial |dx|/h %.2e, |dv|/12 m/s %.2e, work %.6e "
                "J (|dW|/W %.2e); contact nodes up to %ld, sliding up to %ld; %ld migrations\n",
                drift, dx / h, dv / 12.0, ws, std::fabs(w - ws) / ws, max_contact, max_sliding, sent);
  print_phases("impact, uGIMP", split);
}

// ---- (d) three materials meeting at nodes (virtual material, eqs. 39–40) across rank boundaries ----
TEST(DecomposedContact, ThreeMaterialsMeetingAtNodesEqualTheSerialRun) {
  // Blocks A and B side by side on block C (a T junction: nodes near it carry three materials), all
  // converging, Coulomb μ = 0.3 between every pair, interfaces off the grid lines; the junction near
  // x = 15 mm, where the 2-rank split runs. The serial ContactConservation case at 1 mm cells.
  const double h = 1e-3, rho = 1000.0;
  const fm::Grid<2> grid(V2(0.0, 0.0), V2(h, h), {30, 24});
  const fm::SimulationOptions so = frictherm::test::usl_options(fm::ShapeKind::ugimp);
  fm::Simulation<2> serial(grid, so);
  const std::vector<fm::Material> mats{elastic("A", 1e7, 0.3, rho), elastic("B", 1.5e7, 0.3, rho),
                                       elastic("C", 2e7, 0.2, rho)};
  for (const auto& m : mats) serial.add_material(m);
  const double x0 = 4.26e-3, xm = 14.76e-3, x1 = 25.26e-3, y0 = 4.22e-3, ym = 10.24e-3, y1 = 15.74e-3;
  serial.add_body("A", *fm::make_box<2>(V2(x0, ym), V2(xm, y1), 0), 2, V2(2.0, -3.0));
  serial.add_body("B", *fm::make_box<2>(V2(xm, ym), V2(x1, y1), 1), 2, V2(-1.0, -2.5));
  serial.add_body("C", *fm::make_box<2>(V2(x0, y0), V2(x1, ym), 2), 2, V2(0.5, 2.0));
  fm::ContactOptions co;
  co.default_pair.law = fm::FrictionLaw::coulomb(0.3);
  serial.enable_contact(co);
  serial.finalize();

  fm::DecomposedMpm2D split(MPI_COMM_WORLD, grid, mats, frictherm::test::matching_options<2>(so, co));
  split.add_particles(frictherm::test::decomposed(serial.particles()));
  double c = 0.0;
  for (const auto& m : mats) c = std::max(c, std::sqrt(m.p_wave_modulus(fm::Analysis::plane_strain) / rho));
  const double dt = 0.3 * h / (c + 4.0), vmax = std::hypot(3.0, 4.5);  // largest relative speed
  long max_multi = 0, serial_multi = 0;
  double dx = 0.0, dv = 0.0, dw = 0.0;
  bool same_ids = true;
  for (int s = 0; s < 150; ++s) {
    serial.step(dt);
    split.step(dt);
    const fm::DecomposedContactStats st = split.contact_stats();
    max_multi = std::max(max_multi, st.multi_nodes);
    serial_multi = std::max(serial_multi, serial.contact_stats().multi_nodes);
    dw = std::max(dw, std::fabs(split.cumulative_frictional_work(fm::HeatingOrder::second) -
                                serial.cumulative_frictional_work(fm::HeatingOrder::second)));
    if (s % 10 == 9) {
      const Difference d = frictherm::test::compare_with_serial<2>(split.gather(), serial);
      same_ids = same_ids && d.same_ids;
      dx = std::max(dx, d.position), dv = std::max(dv, d.velocity);
    }
  }
  const double ws = serial.cumulative_frictional_work(fm::HeatingOrder::second);
  EXPECT_GT(max_multi, 0L);  // three-material nodes were resolved
  EXPECT_EQ(max_multi, serial_multi);
  EXPECT_GT(ws, 0.0);
  EXPECT_TRUE(same_ids);
  EXPECT_LE(dx / h, 1e-9);
  EXPECT_LE(dv / vmax, 1e-9);
  EXPECT_LE(dw / ws, 1e-9);
  const long entries = field_entries(split);
  if (comm_size() > 1) {
    EXPECT_GT(entries, 0L);
  }
  if (comm_rank() == 0)
    std::printf("[three materials] 150 steps: three-material nodes up to %ld (serial %ld), work W2 %.6e J; vs serial "
                "|dx|/h %.2e, |dv|/v %.2e, |dW2|/W2 %.2e\n",
                max_multi, serial_multi, ws, dx / h, dv / vmax, dw / ws);
  print_phases("three materials, uGIMP", split);
}

// ---- (e) fixed faces on the upper sides (no contact): the serial fix_face's nodes ----
TEST(DecomposedContact, UpperFixedFacesEqualTheSerialRun) {
  // One elastic block pressed by a body force (3e4, 3e4) m/s² into the corner of the x_max face
  // (x component fixed) and the y_max face (both fixed); it starts half a cell from both, so its
  // particles reach the faces' nodes from the first step. Quadratic B-spline, 150 steps.
  const double h = 1e-3, rho = 1000.0;
  const fm::Grid<2> grid(V2(0.0, 0.0), V2(h, h), {20, 14});
  fm::SimulationOptions so = frictherm::test::usl_options(fm::ShapeKind::quadratic_bspline);
  so.gravity = fm::Vec<3>(3e4, 3e4, 0.0);
  fm::Simulation<2> serial(grid, so);
  const fm::Material mat = elastic("block", 1e7, 0.3, rho);
  const int m = serial.add_material(mat);
  serial.add_body("block", *fm::make_box<2>(V2(9.5e-3, 5.5e-3), V2(19.5e-3, 13.5e-3), m), 2, V2(1.0, 0.0));
  const fm::FixedFace right{0, true, {{true, false, false}}}, top{1, true, {{true, true, true}}};
  serial.fix_face(right);
  serial.fix_face(top);
  serial.finalize();
  fm::DecomposedOptions opt;
  opt.shape = so.shape;
  opt.gravity = V2(3e4, 3e4);
  opt.fixed_faces = {right, top};
  fm::DecomposedMpm2D split(MPI_COMM_WORLD, grid, {mat}, opt);
  split.add_particles(frictherm::test::decomposed(serial.particles()));
  const double dt = 0.3 * h / (std::sqrt(mat.p_wave_modulus(fm::Analysis::plane_strain) / rho) + 2.0);
  for (int s = 0; s < 150; ++s) {
    serial.step(dt);
    split.step(dt);
  }
  const Difference d = frictherm::test::compare_with_serial<2>(split.gather(), serial);
  double smax = 0.0, vmax = 0.0;
  for (std::size_t k = 0; k < serial.particles().size(); ++k) {
    smax = std::max(smax, serial.particles().stress[k].norm());
    vmax = std::max(vmax, serial.particles().velocity[k].norm());
  }
  EXPECT_TRUE(d.same_ids);
  EXPECT_GT(smax, 1e4);  // the faces held the block: ρ g H ≈ 2.4e5 Pa along y
  EXPECT_LE(d.position / h, 1e-9);
  EXPECT_LE(d.velocity / vmax, 1e-9);
  if (comm_rank() == 0)
    std::printf("[upper faces] 150 steps: σ_max %.3e Pa; vs serial |dx|/h %.2e, |dv|/v_max %.2e\n", smax,
                d.position / h, d.velocity / vmax);
}

// ---- (c) what the decomposed contact refuses, with the key and the expected value ----
TEST(DecomposedContact, RefusesWhatItDoesNotSupport) {
  const fm::Grid<2> grid(V2(0.0, 0.0), V2(1e-3, 1e-3), {8, 8});
  const std::vector<fm::Material> mats{elastic("a", 1e6, 0.3, 1000.0), elastic("b", 1e6, 0.3, 1000.0)};
  auto refused = [&](const fm::DecomposedOptions& o, const char* expect) {
    frictherm::test::expect_refused<2>(grid, mats, o, expect);
  };
  fm::DecomposedOptions o;
  o.contact = true;
  fm::DecomposedOptions penalty = o;
  penalty.contact_options.default_pair.method = fm::ContactMethod::penalty;
  refused(penalty, "penalty");
  // (The normal-stress regularisation runs: CliMpirun.ContactRegularization.)
  fm::DecomposedOptions same = o;
  same.contact_pairs = {fm::DecomposedContactPair{1, 1, {}}};
  refused(same, "two different materials");
  fm::DecomposedOptions off;
  off.contact_pairs = {fm::DecomposedContactPair{0, 1, {}}};
  refused(off, "contact = true");
  fm::DecomposedOptions face;
  face.fixed_faces = {fm::FixedFace{2, false, {{true, true, true}}}};
  refused(face, "axis");
  // A particle of a material that does not exist (every rank passes it: all throw before a collective).
  fm::DecomposedMpm2D run(MPI_COMM_WORLD, grid, mats, o);
  fm::DecomposedParticle p;
  p.position = V2(4e-3, 4e-3);
  p.mass = p.volume = 1e-6;
  p.material = 2;
  EXPECT_THROW(run.add_particles({p}), std::invalid_argument);
}

}  // namespace

int main(int argc, char** argv) {
  fm::DecomposedPetscSession session(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
