#pragma once
// Shared by the decomposed-run tests (tests/mechanics/test_distributed*.cpp,
// tests/coupling/test_heat_distributed*.cpp): a linear-elastic material, the serial options and the
// matching decomposed ones, serial particles handed to the decomposed run, the serial sliding blocks
// (2D, 3D) they compare with and the checks of that comparison.
#include "frictherm/mechanics/distributed.hpp"
#include "frictherm/mechanics/geometry.hpp"
#include "frictherm/mechanics/simulation.hpp"

#include "mpi_ranks.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace frictherm::test {

inline mechanics::Material elastic(const char* name, double E, double nu, double rho) {
  mechanics::Material m;
  m.name = name;
  m.kind = mechanics::MaterialKind::linear_elastic;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  m.density = rho;
  return m;
}

/// The serial run's options of the decomposed comparisons: the kernel `shape`, the USL scheme and,
/// where given, the CFL number `cfl` (the default otherwise).
inline mechanics::SimulationOptions usl_options(mechanics::ShapeKind shape, double cfl = mechanics::SimulationOptions{}.cfl) {
  mechanics::SimulationOptions so;
  so.shape = shape;
  so.scheme = mechanics::UpdateScheme::usl;
  so.cfl = cfl;
  return so;
}

/// The decomposed run's options matching a serial run with contact: its shape and (with `contact`)
/// its contact options `co`.
template <int Dim>
typename mechanics::DecomposedMpm<Dim>::Options matching_options(const mechanics::SimulationOptions& so,
                                                                 const mechanics::ContactOptions& co,
                                                                 bool contact = true) {
  typename mechanics::DecomposedMpm<Dim>::Options opt;
  opt.shape = so.shape;
  opt.contact = contact;
  opt.contact_options = co;
  return opt;
}

/// Serial particles as decomposed particles (id = serial index; with `temperature` the temperature
/// as the one scalar), 2D or 3D. Only rank 0 passes them: the first migration distributes them.
template <int Dim>
std::vector<typename mechanics::DecomposedMpm<Dim>::Particle> decomposed(const mechanics::Particles<Dim>& sp,
                                                                         bool temperature = false) {
  std::vector<typename mechanics::DecomposedMpm<Dim>::Particle> all(sp.position.size());
  for (std::size_t k = 0; k < all.size(); ++k) {
    all[k].id = static_cast<std::int64_t>(k);
    all[k].mass = sp.mass[k];
    all[k].volume = sp.volume[k];
    all[k].position = sp.position[k];
    all[k].velocity = sp.velocity[k];
    all[k].half_size = sp.half_size[k];
    all[k].material = sp.material[k];
    if (temperature) all[k].scalars = {sp.temperature[k]};
  }
  return comm_rank() == 0 ? all : decltype(all){};
}

/// Largest differences of the gathered decomposed particles `a` (by id) from the serial run's (position,
/// velocity, stress with σ_zz, each particle's plastic work), and the serial scales they are measured
/// against; `same_ids`: the same particles, with their materials and masses.
struct SerialDifference {
  double position = 0.0, velocity = 0.0, stress = 0.0, plastic = 0.0;
  double v_max = 0.0, s_max = 0.0, plastic_max = 0.0;
  bool same_ids = true;
};
template <int Dim>
SerialDifference compare_with_serial(const std::vector<typename mechanics::DecomposedMpm<Dim>::Particle>& a,
                                     const mechanics::Simulation<Dim>& serial) {
  const auto& sp = serial.particles();
  SerialDifference d;
  d.same_ids = a.size() == sp.position.size();
  for (std::size_t k = 0; d.same_ids && k < a.size(); ++k) {
    d.same_ids = a[k].id == static_cast<std::int64_t>(k) && a[k].material == sp.material[k] && a[k].mass == sp.mass[k];
    d.position = std::max(d.position, (a[k].position - sp.position[k]).norm());
    d.velocity = std::max(d.velocity, (a[k].velocity - sp.velocity[k]).norm());
    d.stress = std::max({d.stress, (a[k].stress - sp.stress[k]).norm(), std::fabs(a[k].stress_zz - sp.stress_zz[k])});
    d.plastic = std::max(d.plastic, std::fabs(a[k].plastic_work - sp.plastic_work[k]));
    d.v_max = std::max(d.v_max, sp.velocity[k].norm());
    d.s_max = std::max(d.s_max, sp.stress[k].norm());
    d.plastic_max = std::max(d.plastic_max, sp.plastic_work[k]);
  }
  return d;
}

/// Mass-weighted mean x-velocity of one material's particles (gathered decomposed ones, serial ones).
template <class Particle>
double mean_velocity_x(const std::vector<Particle>& a, int material) {
  double mv = 0.0, m = 0.0;
  for (const auto& p : a)
    if (p.material == material) mv += p.mass * p.velocity[0], m += p.mass;
  return mv / m;
}
template <int Dim>
double mean_velocity_x(const mechanics::Particles<Dim>& p, int material) {
  double mv = 0.0, m = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k)
    if (p.material[k] == material) mv += p.mass[k] * p.velocity[k][0], m += p.mass[k];
  return mv / m;
}

/// A block sliding on a base, the serial run the decomposed tests compare with, in 2D and 3D: an
/// elastic base (E = 20 MPa, ν = 0.3) with its bottom face (axis `up` = Dim − 1, lower side) fixed in
/// every component, an elastic block (15 MPa, 0.25) on it at v0 = 10 m/s along x, g = 2e4 m/s² along
/// −up, Coulomb μ = 0.3 with the specified normal +up from base to block; ρ = 1000 kg/m³, cells of
/// h = 1 mm from the origin, 2^Dim particles per cell, USL; and the matching options of the
/// decomposed run.
template <int Dim>
struct SlidingBlockOf {
  static constexpr double h = 1e-3, rho = 1000.0, v0 = 10.0, g = 2e4, mu = 0.3;
  static constexpr int up = Dim - 1;
  mechanics::Grid<Dim> grid;
  std::vector<mechanics::Material> materials{elastic("base", 2e7, 0.3, rho), elastic("block", 1.5e7, 0.25, rho)};
  std::unique_ptr<mechanics::Simulation<Dim>> serial;
  typename mechanics::DecomposedMpm<Dim>::Options options;
  int base = 0, block = 1;

  SlidingBlockOf(mechanics::ShapeKind shape, const mechanics::IVec<Dim>& cells, const mechanics::Vec<Dim>& base_lo,
                 const mechanics::Vec<Dim>& base_hi, const mechanics::Vec<Dim>& block_lo,
                 const mechanics::Vec<Dim>& block_hi)
      : grid(mechanics::Vec<Dim>::Zero(), mechanics::Vec<Dim>::Constant(h), cells) {
    using VD = mechanics::Vec<Dim>;
    mechanics::Vec<3> gravity = mechanics::Vec<3>::Zero();
    gravity[up] = -g;
    mechanics::SimulationOptions so;
    so.shape = shape;
    so.scheme = mechanics::UpdateScheme::usl;
    so.gravity = gravity;
    serial = std::make_unique<mechanics::Simulation<Dim>>(grid, so);
    base = serial->add_material(materials[0]);
    block = serial->add_material(materials[1]);
    VD sliding = VD::Zero();
    sliding[0] = v0;
    serial->add_body("base", *mechanics::make_box<Dim>(base_lo, base_hi, base), 2, VD::Zero());
    serial->add_body("block", *mechanics::make_box<Dim>(block_lo, block_hi, block), 2, sliding);
    const mechanics::FixedFace bottom{up, false, {{true, true, true}}};
    serial->fix_face(bottom);
    mechanics::ContactOptions co;
    co.default_pair.law = mechanics::FrictionLaw::coulomb(mu);
    co.default_pair.normal = mechanics::NormalMethod::specified;
    co.default_pair.normal_vector = mechanics::Vec<3>::Unit(up);
    serial->enable_contact(co);
    serial->set_contact_pair(base, block, co.default_pair);
    serial->finalize();
    options.shape = shape;
    options.gravity = gravity.template head<Dim>();
    options.fixed_faces = {bottom};
    options.contact = true;
    options.contact_options = co;
    options.contact_pairs = {mechanics::DecomposedContactPair{base, block, co.default_pair}};
  }
};

/// The 2D sliding block (test_distributed_contact.cpp (a), test_heat_distributed.cpp (a)): base
/// 24 × 4 mm fixed at y_min, block 8 × 4 mm on it (crossing the 2-rank split), 26 × 12 cells.
struct SlidingBlock : SlidingBlockOf<2> {
  explicit SlidingBlock(mechanics::ShapeKind shape)
      : SlidingBlockOf<2>(shape, {26, 12}, mechanics::Vec<2>(1e-3, 0.0), mechanics::Vec<2>(25e-3, 4e-3),
                          mechanics::Vec<2>(6e-3, 4e-3), mechanics::Vec<2>(14e-3, 8e-3)) {}
};

/// The 3D sliding block (test_distributed_3d.cpp (d), test_heat_distributed_3d.cpp): base 10 × 4 × 2 mm
/// fixed at z_min, block 4 × 4 × 2 mm on it sliding along x (across the 2-rank cut near x = 6.5 mm),
/// 12 × 6 × 5 cells.
struct SlidingBlock3D : SlidingBlockOf<3> {
  explicit SlidingBlock3D(mechanics::ShapeKind shape)
      : SlidingBlockOf<3>(shape, {12, 6, 5}, mechanics::Vec<3>(1e-3, 1e-3, 0.0), mechanics::Vec<3>(11e-3, 5e-3, 2e-3),
                          mechanics::Vec<3>(2e-3, 1e-3, 2e-3), mechanics::Vec<3>(6e-3, 5e-3, 4e-3)) {}
};

/// Expects the decomposed run of `materials` with options `o` on `grid` to be refused with an
/// std::invalid_argument naming `expect` (the scene key or the expected value).
template <int Dim>
void expect_refused(const mechanics::Grid<Dim>& grid, const std::vector<mechanics::Material>& materials,
                    const typename mechanics::DecomposedMpm<Dim>::Options& o, const char* expect) {
  try {
    mechanics::DecomposedMpm<Dim> run(MPI_COMM_WORLD, grid, materials, o);
  } catch (const std::invalid_argument& e) {
    const bool named = std::string(e.what()).find(expect) != std::string::npos;
    EXPECT_TRUE(named) << e.what();
    return;
  }
  ADD_FAILURE() << "not refused: " << expect;
}

/// The worst differences of a decomposed sliding block from the serial run over its steps: positions,
/// velocities, the block's mean x-velocity (the history), the first- and second-order cumulative
/// frictional work, and the books (each step's nodal work over all ranks against the cumulative
/// work's increment); with what the serial run did: |step taken − dt|, the final works W1, W2, the
/// block's final mean x-velocity, and the fewest contact and sliding nodes after the first 5 steps.
/// (Collective: every rank steps.)
struct SlidingDifferences {
  double taken = 0.0, dx = 0.0, dv = 0.0, dhist = 0.0, dw1 = 0.0, dw2 = 0.0, books = 0.0;
  double ws1 = 0.0, ws2 = 0.0, v_end = 0.0;
  long min_contact = 1L << 40, min_sliding = 1L << 40;
  bool same_ids = true;

  double w1 = 0.0, w2 = 0.0;  // the decomposed run's cumulative work (first, second order)

  /// Step `s`: steps the serial run and the decomposed one `split` by `dt`, and records the step's
  /// work and books, the decomposed run's contact statistics, and its gathered particles against the
  /// serial ones: `compare(gathered)` gives their largest differences (`same_ids`, `position`,
  /// `velocity`); the history is the mean x-velocity of material `block`.
  template <int Dim, class Compare>
  void step(int s, mechanics::Simulation<Dim>& serial, mechanics::DecomposedMpm<Dim>& split, double dt, int block,
            Compare compare) {
    taken = std::max(taken, std::fabs(serial.step(dt) - dt));
    split.step(dt);
    const double before1 = w1, before2 = w2;
    w1 = split.cumulative_frictional_work(mechanics::HeatingOrder::first);
    w2 = split.cumulative_frictional_work(mechanics::HeatingOrder::second);
    ws1 = serial.cumulative_frictional_work(mechanics::HeatingOrder::first);
    ws2 = serial.cumulative_frictional_work(mechanics::HeatingOrder::second);
    dw1 = std::max(dw1, std::fabs(w1 - ws1));
    dw2 = std::max(dw2, std::fabs(w2 - ws2));
    // The step's work per owned node summed over ranks is the cumulative work's increment.
    double step_work[2] = {0.0, 0.0};
    for (double w : split.frictional_work(mechanics::HeatingOrder::first)) step_work[0] += w;
    for (double w : split.frictional_work(mechanics::HeatingOrder::second)) step_work[1] += w;
    MPI_Allreduce(MPI_IN_PLACE, step_work, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    books = std::max({books, std::fabs(step_work[0] - (w1 - before1)), std::fabs(step_work[1] - (w2 - before2))});
    const mechanics::DecomposedContactStats st = split.contact_stats();
    if (s >= 5) min_contact = std::min(min_contact, st.contact_nodes), min_sliding = std::min(min_sliding, st.sliding_nodes);
    const auto a = split.gather();
    const auto d = compare(a);
    same_ids = same_ids && d.same_ids;
    dx = std::max(dx, d.position);
    dv = std::max(dv, d.velocity);
    dhist = std::max(dhist, std::fabs(mean_velocity_x(a, block) - mean_velocity_x(serial.particles(), block)));
    v_end = mean_velocity_x(serial.particles(), block);
  }
};

/// The sliding block slid and was braked by friction over the whole run (contact and sliding at every
/// step after the first few, the block slowed by more than 0.5 m/s, the books the comparisons rest on
/// not empty), and the decomposed run equals the serial one: every particle kept, positions within
/// 1e-9 of the cell size h, velocities and the history within 1e-9 of v0, the work within 1e-9 of its
/// final value (the tolerance) and the books closed to round-off (1e-12 of W1).
inline void expect_sliding_block_equals_serial(const SlidingDifferences& s, double h, double v0) {
  EXPECT_EQ(s.taken, 0.0);  // the serial step took dt (below its CFL limit)
  EXPECT_TRUE(s.same_ids);  // every particle kept, with its material and mass
  EXPECT_GT(s.min_contact, 0L);
  EXPECT_GT(s.min_sliding, 0L);
  EXPECT_LT(s.v_end, v0 - 0.5);
  EXPECT_GT(s.ws1, 0.0);
  EXPECT_GT(s.ws2, 0.0);
  EXPECT_LE(s.dx / h, 1e-9);
  EXPECT_LE(s.dv / v0, 1e-9);
  EXPECT_LE(s.dhist / v0, 1e-9);
  EXPECT_LE(s.dw1 / s.ws1, 1e-9);
  EXPECT_LE(s.dw2 / s.ws2, 1e-9);
  EXPECT_LE(s.books / s.ws1, 1e-12);
}

/// Rank 0 prints the sliding block's run and its differences from the serial one, tagged `tag`, for
/// the kernel named `kernel`.
inline void print_sliding_block(const char* tag, const char* kernel, int steps, double h, double v0,
                                const SlidingDifferences& s) {
  if (comm_rank() != 0) return;
  std::printf("[%s] %s, %d steps: block %.3f -> %.3f m/s, W1 %.6e J, W2 %.6e J; max over steps |dx|/h %.2e, "
              "|dv|/v0 %.2e, history %.2e, |dW1|/W1 %.2e, |dW2|/W2 %.2e, books %.2e; contact nodes >= %ld, "
              "sliding >= %ld\n",
              tag, kernel, steps, v0, s.v_end, s.ws1, s.ws2, s.dx / h, s.dv / v0, s.dhist / v0, s.dw1 / s.ws1,
              s.dw2 / s.ws2, s.books / s.ws1, s.min_contact, s.min_sliding);
}

}  // namespace frictherm::test
