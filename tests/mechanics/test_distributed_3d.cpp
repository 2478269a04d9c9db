// The decomposed MPM step in 3D (frictherm/mechanics/distributed.hpp, DecomposedMpm<3>), run by ctest
// under mpirun with 2 and 4 ranks. Small grids (≤ 490 cells: 8 × 6 × 6 … 7 × 7 × 10; ≤ 2304 particles)
// so that each run stays within seconds on a busy 2-core machine.
//   (a) an isolated elastic body spinning, compressing and translating (no velocity condition, no
//       gravity): total linear momentum conserved to round-off (1e-13 of Σ m|v|) at every step;
//   (b) a body translating diagonally across rank cuts along every split axis: the global count,
//       the set of ids and every mass kept exactly, the first migration moves every field unchanged;
//       with it, the transfers for coupled physics in 3D (particle scalars through migration, node
//       sums at the owners, owner values on the ghosts);
//   (c) the decomposed run = the serial Simulation<3> (USL, FLIP, same dt) particle by particle:
//       two colliding blocks with gravity (uGIMP), and a body touching all six fixed grid faces
//       (quadratic B-spline);
//   (d) a block sliding with Coulomb friction on a base fixed at z_min, pressed by gravity
//       (multimaterial contact, specified normal): particles, the block's velocity history and the
//       cumulative frictional work (first and second order) = the serial run's;
//   plus the 3D stencil width, the DMDA's 3D process grid and the refusals (analysis, face axis).
// Tolerance of the serial comparisons: 1e-9 of the case's own scales (cell size or body length,
// v_max, σ_max, final W), the figure; the measured differences are round-off (printed).
// No ASSERT before a collective call: a rank that returned early would leave the others waiting.
#include "frictherm/mechanics/distributed.hpp"
#include "frictherm/mechanics/geometry.hpp"
#include "frictherm/mechanics/simulation.hpp"

#include "../decomposed_test_support.hpp"
#include "../mpi_ranks.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

namespace {

namespace fm = frictherm::mechanics;
using V3 = fm::Vec<3>;
using Mpm = fm::DecomposedMpm3D;
using Particle = Mpm::Particle;

using frictherm::test::comm_rank;
using frictherm::test::comm_size;
using frictherm::test::elastic;

constexpr double h = 1e-3, rho = 1000.0;

// A box [lo, hi] (multiples of h/ppc) filled with ppc³ particles per cell, ids from 0.
std::vector<Particle> box(const V3& lo, const V3& hi, int ppc, const std::function<V3(const V3&)>& velocity) {
  std::vector<Particle> out;
  const double d = h / ppc;
  int n[3];
  for (int a = 0; a < 3; ++a) n[a] = static_cast<int>(std::lround((hi[a] - lo[a]) / d));
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        Particle p;
        p.id = static_cast<std::int64_t>(out.size());
        p.position = lo + d * V3(i + 0.5, j + 0.5, k + 0.5);
        p.volume = d * d * d;
        p.mass = rho * p.volume;
        p.half_size = V3::Constant(0.5 * d);
        p.velocity = velocity(p.position);
        out.push_back(p);
      }
  return out;
}

std::vector<Particle> on_rank0(const std::vector<Particle>& all) {
  return comm_rank() == 0 ? all : std::vector<Particle>{};
}

long sum_over_ranks(long x) {
  MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return x;
}

double p_wave_speed(const fm::Material& m) { return std::sqrt(m.p_wave_modulus(fm::Analysis::three_d) / m.density); }

void print_traffic(const char* label, const Mpm& run) {
  const fm::DecomposedTraffic& t = run.traffic();
  const long ghost = sum_over_ranks(t.ghost_nodes), sent = sum_over_ranks(t.particles_sent);
  const long entries = sum_over_ranks(t.field_entries_sent);
  const auto pr = run.processes();
  if (comm_rank() != 0) return;
  const double steps = t.steps > 0 ? static_cast<double>(t.steps) : 1.0;
  std::printf("[traffic] %s: %d ranks (%d x %d x %d), %ld steps; DMDA exchanges %d doubles per ghost node, %ld ghost "
              "nodes in all = %.1f kB per exchange; per-material entries %.1f per step (%d B); migration %.2f "
              "particles per step (%d B each)\n",
              label, comm_size(), pr[0], pr[1], pr[2], t.steps, t.values_per_node, ghost,
              ghost * t.values_per_node * 8.0 / 1024.0, entries / steps, t.field_entry_bytes, sent / steps,
              t.particle_bytes);
}

// Largest differences of the gathered decomposed particles (by id) from the serial ones.
struct Difference {
  double position = 0.0, velocity = 0.0, stress = 0.0, v_max = 0.0, s_max = 0.0;
  bool same_ids = true;
};
Difference compare(const std::vector<Particle>& a, const fm::Particles<3>& sp) {
  Difference d;
  d.same_ids = a.size() == sp.size();
  for (std::size_t k = 0; d.same_ids && k < a.size(); ++k) {
    d.same_ids = a[k].id == static_cast<std::int64_t>(k) && a[k].material == sp.material[k] && a[k].mass == sp.mass[k];
    d.position = std::max(d.position, (a[k].position - sp.position[k]).norm());
    d.velocity = std::max(d.velocity, (a[k].velocity - sp.velocity[k]).norm());
    d.stress = std::max(d.stress, (a[k].stress - sp.stress[k]).norm());
    d.v_max = std::max(d.v_max, sp.velocity[k].norm());
    d.s_max = std::max(d.s_max, sp.stress[k].norm());
  }
  return d;
}

// ---- the 3D stencil width, the process grid, the refusals ----
TEST(Decomposed3D, StencilWidthProcessGridAndRefusals) {
  const fm::Grid<3> grid(V3::Zero(), V3::Constant(h), {8, 6, 6});
  const fm::Material mat = elastic("elastic", 1e7, 0.3, rho);
  for (fm::ShapeKind shape : {fm::ShapeKind::linear, fm::ShapeKind::ugimp, fm::ShapeKind::quadratic_bspline}) {
    Mpm::Options opt;
    opt.shape = shape;
    Mpm run(MPI_COMM_WORLD, grid, mat, opt);
    EXPECT_EQ(run.stencil_width(), 1);
    const auto pr = run.processes();
    EXPECT_EQ(pr[0] * pr[1] * pr[2], comm_size());
    // The owned node blocks tile the 11 × 9 × 9 nodes (ghost layer included).
    const auto o = run.owned_nodes();
    long owned = static_cast<long>(o[1] - o[0]) * (o[3] - o[2]) * (o[5] - o[4]);
    EXPECT_EQ(sum_over_ranks(owned), 11L * 9L * 9L);
    EXPECT_EQ(static_cast<long>(run.owned_local_nodes().size()), owned);
  }
  Mpm::Options plane;
  plane.analysis = fm::Analysis::plane_strain;
  EXPECT_THROW(Mpm(MPI_COMM_WORLD, grid, mat, plane), std::invalid_argument);
  Mpm::Options face;
  face.fixed_faces = {fm::FixedFace{3, false, {{true, true, true}}}};
  EXPECT_THROW(Mpm(MPI_COMM_WORLD, grid, mat, face), std::invalid_argument);
  fm::DecomposedOptions three_d_in_2d;
  three_d_in_2d.analysis = fm::Analysis::three_d;
  EXPECT_THROW(fm::DecomposedMpm2D(MPI_COMM_WORLD, fm::Grid<2>(fm::Vec<2>::Zero(), fm::Vec<2>::Constant(h), {8, 8}),
                                   mat, three_d_in_2d),
               std::invalid_argument);
}

// ---- (a) an isolated body spinning and compressing: momentum conserved to round-off ----
TEST(Decomposed3D, IsolatedBodyConservesMomentum) {
  // 10 × 6 × 6 cells (the 2-rank cut runs across x); a 6 × 4 × 4 mm body of 2³ uGIMP particles per
  // cell translating at (12, 5, −4) m/s, spinning about (1, 1, 2) at 1500 rad/s and compressed at
  // 800 /s along x; 60 steps.
  const fm::Grid<3> grid(V3::Zero(), V3::Constant(h), {10, 6, 6});
  const fm::Material mat = elastic("elastic", 1e7, 0.3, rho);
  Mpm::Options opt;
  opt.shape = fm::ShapeKind::ugimp;
  Mpm run(MPI_COMM_WORLD, grid, mat, opt);
  const V3 c(5e-3, 3e-3, 3e-3), omega = 1500.0 * V3(1.0, 1.0, 2.0).normalized();
  auto velocity = [&](const V3& x) {
    const V3 r = x - c;
    return V3(V3(12.0, 5.0, -4.0) + omega.cross(r) - 800.0 * V3(r[0], 0.0, 0.0));
  };
  const auto all = box(V3(2e-3, 1e-3, 1e-3), V3(8e-3, 5e-3, 5e-3), 2, velocity);
  run.add_particles(on_rank0(all));
  const V3 p0 = run.total_momentum();
  const double scale = run.total_momentum_scale();
  const double dt = 0.3 * h / (p_wave_speed(mat) + 20.0);
  double drift = 0.0;
  for (int s = 0; s < 60; ++s) {
    run.step(dt);
    drift = std::max(drift, (run.total_momentum() - p0).norm() / scale);
  }
  // Σ_p m_p Δv_p = dt Σ_i m_i a_i = dt Σ_i f_i = 0 (Σ_i G_ip = 0, no body force, no velocity
  // condition): round-off of sums over ~800 particles × 27 nodes, ~1e-16 each.
  EXPECT_LE(drift, 1e-13) << "largest |P(t) − P(0)| / Σ m|v| over 60 steps";
  EXPECT_EQ(run.global_particles(), static_cast<long long>(all.size()));
  if (comm_size() > 1) {
    EXPECT_GT(sum_over_ranks(run.traffic().particles_sent), 0L);  // particles did change rank
  }
  if (comm_rank() == 0) std::printf("[momentum 3D] largest relative drift %.3e over 60 steps\n", drift);
  print_traffic("isolated body 3D, uGIMP", run);
}

// ---- (b) a body translating across rank cuts along every split axis keeps every particle ----
TEST(Decomposed3D, TranslatingBodyKeepsEveryParticle) {
  // 7 × 7 × 10 cells: PETSc cuts z first (2 ranks: 1 × 1 × 2; 4 ranks: a second cut along x or y).
  // The body moves diagonally at (20, 20, 30) m/s, ~1.5 mm along x and y and 2.2 mm along z over the
  // run, across every cut.
  const fm::Grid<3> grid(V3::Zero(), V3::Constant(h), {7, 7, 10});
  const fm::Material mat = elastic("elastic", 1e7, 0.3, rho);
  Mpm::Options opt;
  opt.shape = fm::ShapeKind::quadratic_bspline;
  opt.particle_scalars = {"temperature", "tag"};
  Mpm run(MPI_COMM_WORLD, grid, mat, opt);
  auto all = box(V3(1.5e-3, 1.5e-3, 2.5e-3), V3(4.5e-3, 4.5e-3, 5.5e-3), 2, [](const V3&) {
    return V3(20.0, 20.0, 30.0);
  });
  for (auto& p : all) p.scalars = {300.0 + 0.01 * static_cast<double>(p.id), -static_cast<double>(p.id)};
  run.add_particles(on_rank0(all));
  {
    const auto moved = run.gather();  // the first migration moved every field unchanged
    bool same = moved.size() == all.size();
    for (std::size_t k = 0; same && k < moved.size(); ++k)
      same = moved[k].id == all[k].id && moved[k].position == all[k].position &&
             moved[k].velocity == all[k].velocity && moved[k].volume == all[k].volume &&
             moved[k].half_size == all[k].half_size && moved[k].mass == all[k].mass &&
             moved[k].scalars == all[k].scalars;
    EXPECT_TRUE(same);
  }
  const double dt = 0.3 * h / (p_wave_speed(mat) + 40.0);
  long long min_count = run.global_particles(), max_count = min_count;
  for (int s = 0; s < 40; ++s) {
    run.step(dt);
    const long long n = run.global_particles();
    min_count = std::min(min_count, n), max_count = std::max(max_count, n);
  }
  EXPECT_EQ(min_count, static_cast<long long>(all.size()));
  EXPECT_EQ(max_count, static_cast<long long>(all.size()));
  const auto fin = run.gather();
  bool same_ids = fin.size() == all.size();
  V3 shift = V3::Zero();
  for (std::size_t k = 0; same_ids && k < fin.size(); ++k) {
    same_ids = fin[k].id == all[k].id && fin[k].mass == all[k].mass &&  // ids, masses and scalars bit for bit
               fin[k].scalars == all[k].scalars;
    shift += (fin[k].position - all[k].position) / static_cast<double>(fin.size());
  }
  EXPECT_TRUE(same_ids);
  EXPECT_GT(shift.minCoeff(), 1.4 * h);  // it did travel along every axis
  const long sent = sum_over_ranks(run.traffic().particles_sent);
  if (comm_size() > 1) {
    EXPECT_GT(sent, static_cast<long>(all.size()) / 4);  // a good part of the body changed rank
  }
  if (comm_rank() == 0)
    std::printf("[translation 3D] %zu particles kept over 40 steps, shift (%.2f, %.2f, %.2f) mm, %ld migrations\n",
                fin.size(), 1e3 * shift[0], 1e3 * shift[1], 1e3 * shift[2], sent);

  // Transfers: M_i = Σ_p m_p S_ip from every rank's particles summed at the owners gives Σ_i M_i =
  // Σ_p m_p (partition of unity); with M_i back on the ghosts, Σ_p m_p Σ_i S_ip M_i = Σ_i M_i². Two
  // components (m S, then 2 m S) exercise the component layout; 7 is the most (the DMDA's values).
  const Mpm::Stencils& st = run.current_stencils();
  const fm::DecomposedLocalParticles lp = run.local_particle_data();
  const std::vector<double> tag = run.particle_scalar(run.particle_scalar_index("tag"));
  std::vector<double> local(2 * static_cast<std::size_t>(run.local_node_count()), 0.0), owned, ghosted;
  bool tags = tag.size() == lp.id.size();
  for (std::size_t k = 0; k < lp.id.size(); ++k) {
    tags = tags && tag[k] == -static_cast<double>(lp.id[k]);
    for (int a = st.first[k]; a < st.first[k + 1]; ++a) {
      const auto i = static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)]);
      local[2 * i] += lp.mass[k] * st.S[static_cast<std::size_t>(a)];
      local[2 * i + 1] += 2.0 * lp.mass[k] * st.S[static_cast<std::size_t>(a)];
    }
  }
  EXPECT_TRUE(tags);  // the scalars in swarm order belong to the local particles
  run.sum_to_owned(local, 2, owned);
  run.owned_to_local(owned, 2, ghosted);
  double sums[5] = {0.0, 0.0, 0.0, 0.0, 0.0};  // Σ M_i, Σ m_p, Σ_p m_p Σ_i S_ip M_i, Σ M_i², Σ (2nd − 2 M_i)²
  for (std::size_t q = 0; q < owned.size() / 2; ++q) {
    sums[0] += owned[2 * q], sums[3] += owned[2 * q] * owned[2 * q];
    sums[4] += std::pow(owned[2 * q + 1] - 2.0 * owned[2 * q], 2);
  }
  for (std::size_t k = 0; k < lp.id.size(); ++k) {
    sums[1] += lp.mass[k];
    for (int a = st.first[k]; a < st.first[k + 1]; ++a)
      sums[2] += lp.mass[k] * st.S[static_cast<std::size_t>(a)] *
                 ghosted[2 * static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)])];
  }
  bool owners_kept = 2 * run.owned_local_nodes().size() == owned.size();
  for (std::size_t q = 0; owners_kept && q < owned.size() / 2; ++q)
    owners_kept = ghosted[2 * static_cast<std::size_t>(run.owned_local_nodes()[q])] == owned[2 * q];
  EXPECT_TRUE(owners_kept);
  MPI_Allreduce(MPI_IN_PLACE, sums, 5, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_LE(std::fabs(sums[0] - sums[1]) / sums[1], 1e-14);
  EXPECT_LE(std::fabs(sums[2] - sums[3]) / sums[3], 1e-14);
  EXPECT_EQ(sums[4], 0.0);  // doubling is exact: the second component is twice the first at every node
  EXPECT_EQ(Mpm::max_transfer_components, 7);
  EXPECT_THROW(run.sum_to_owned(local, Mpm::max_transfer_components + 1, owned), std::invalid_argument);
  if (comm_rank() == 0)
    std::printf("[transfers 3D] partition of unity %.2e, ghost identity %.2e\n", std::fabs(sums[0] - sums[1]) / sums[1],
                std::fabs(sums[2] - sums[3]) / sums[3]);
  print_traffic("translating body 3D, quadratic B-spline", run);
}

// ---- (c) the decomposed run = the serial Simulation<3>, no contact ----
struct SerialCase {
  std::unique_ptr<fm::Simulation<3>> serial;
  Mpm::Options options;
};

void run_against_serial(const char* label, const fm::Grid<3>& grid, SerialCase& sc, const fm::Material& mat,
                        int steps, double v_ref, double length) {
  fm::Simulation<3>& serial = *sc.serial;
  Mpm split(MPI_COMM_WORLD, grid, mat, sc.options);
  split.add_particles(frictherm::test::decomposed(serial.particles()));
  const double dt = 0.3 * h / (p_wave_speed(mat) + v_ref);
  double taken = 0.0;
  for (int s = 0; s < steps; ++s) {
    taken = std::max(taken, std::fabs(serial.step(dt) - dt));
    split.step(dt);
  }
  const Difference d = compare(split.gather(), serial.particles());
  EXPECT_EQ(taken, 0.0);  // the serial step took dt (below its CFL limit)
  EXPECT_TRUE(d.same_ids);
  EXPECT_GT(d.s_max, 1e4);  // the bodies were loaded
  EXPECT_LE(d.position / length, 1e-9);
  EXPECT_LE(d.velocity / d.v_max, 1e-9);
  EXPECT_LE(d.stress / d.s_max, 1e-9);
  if (comm_rank() == 0)
    std::printf("[serial 3D] %s, %d steps: σ_max %.3e Pa, v_max %.3f m/s; max |Δx|/L %.2e, |Δv|/v_max %.2e, "
                "|Δσ|/σ_max %.2e\n",
                label, steps, d.s_max, d.v_max, d.position / length, d.velocity / d.v_max, d.stress / d.s_max);
  print_traffic(label, split);
}

TEST(Decomposed3D, CollidingBlocksEqualTheSerialSimulation) {
  // Two 4 × 4 × 4 mm blocks meeting head-on at ±8 m/s (one also moving along y and z), g = 200 m/s²
  // along −z, uGIMP, 12 × 6 × 6 cells (the 2-rank cut near x = 6.5 mm, where they meet); 50 steps.
  const fm::Grid<3> grid(V3::Zero(), V3::Constant(h), {12, 6, 6});
  const fm::Material mat = elastic("elastic", 1e6, 0.3, rho);
  SerialCase sc;
  fm::SimulationOptions so = frictherm::test::usl_options(fm::ShapeKind::ugimp);
  so.gravity = V3(0.0, 0.0, -200.0);
  sc.serial = std::make_unique<fm::Simulation<3>>(grid, so);
  const int m = sc.serial->add_material(mat);
  sc.serial->add_body("left", *fm::make_box<3>(V3(1.5e-3, 1e-3, 1e-3), V3(5.5e-3, 5e-3, 5e-3), m), 2, V3(8.0, 0.5, 0.3));
  sc.serial->add_body("right", *fm::make_box<3>(V3(6.5e-3, 1e-3, 1.5e-3), V3(10.5e-3, 5e-3, 5.5e-3), m), 2,
                      V3(-8.0, 0.0, 0.0));
  sc.serial->finalize();
  sc.options.shape = so.shape;
  sc.options.gravity = V3(0.0, 0.0, -200.0);
  run_against_serial("colliding blocks 3D, uGIMP", grid, sc, mat, 50, 8.0, 12.0 * h);
}

TEST(Decomposed3D, SixFixedFacesEqualTheSerialSimulation) {
  // One body filling the physical region 8 × 6 × 6 mm (its particles reach the nodes of all six faces
  // and the ghost layer beyond), expanding and shearing with v = (2 sin(πx/Lx), −1.5 sin(πz/Lz),
  // 1 + cos(πy/Ly)) m/s under g = (0, 0, −3e4) m/s²; each face fixes other components:
  // the normal one everywhere (walls) and tangential ones on some: x_min all, x_max x, y_min y,
  // y_max y and z, z_min z, z_max x and z. Quadratic B-spline, 60 steps.
  const fm::Grid<3> grid(V3::Zero(), V3::Constant(h), {8, 6, 6});
  const fm::Material mat = elastic("elastic", 1e7, 0.25, rho);
  SerialCase sc;
  fm::SimulationOptions so = frictherm::test::usl_options(fm::ShapeKind::quadratic_bspline);
  so.gravity = V3(0.0, 0.0, -3e4);
  sc.serial = std::make_unique<fm::Simulation<3>>(grid, so);
  const int m = sc.serial->add_material(mat);
  sc.serial->add_body("body", *fm::make_box<3>(V3::Zero(), V3(8e-3, 6e-3, 6e-3), m), 2, V3::Zero());
  const std::vector<fm::FixedFace> faces{
      {0, false, {{true, true, true}}}, {0, true, {{true, false, false}}}, {1, false, {{false, true, false}}},
      {1, true, {{false, true, true}}}, {2, false, {{false, false, true}}}, {2, true, {{true, false, true}}}};
  for (const auto& f : faces) sc.serial->fix_face(f);
  sc.serial->finalize();
  auto& sp = sc.serial->particles();
  for (std::size_t k = 0; k < sp.size(); ++k) {
    const V3& x = sp.position[k];
    sp.velocity[k] = V3(2.0 * std::sin(M_PI * x[0] / 8e-3), -1.5 * std::sin(M_PI * x[2] / 6e-3),
                        1.0 + std::cos(M_PI * x[1] / 6e-3));
  }
  sc.options.shape = so.shape;
  sc.options.gravity = V3(0.0, 0.0, -3e4);
  sc.options.fixed_faces = faces;
  run_against_serial("six fixed faces 3D, quadratic B-spline", grid, sc, mat, 60, 3.0, 8.0 * h);
}

// ---- (d) frictional sliding with contact = the serial run, with the frictional work ----
class Decomposed3DSliding : public ::testing::TestWithParam<fm::ShapeKind> {};

TEST_P(Decomposed3DSliding, EqualsTheSerialRunWithHeating) {
  // The 3D sliding block of decomposed_test_support.hpp (base 10 × 4 × 2 mm fixed at z_min, block
  // 4 × 4 × 2 mm sliding along x at 10 m/s across the 2-rank cut, g = 2e4 m/s² along −z, Coulomb
  // μ = 0.3, 12 × 6 × 5 cells of 1 mm, USL); 150 steps (the block moves ~2.5 mm).
  frictherm::test::SlidingBlock3D scene(GetParam());
  const double v0 = scene.v0;
  const fm::Grid<3>& grid = scene.grid;
  const std::vector<fm::Material>& mats = scene.materials;
  fm::Simulation<3>& serial = *scene.serial;
  const int blk = scene.block;
  Mpm split(MPI_COMM_WORLD, grid, mats, scene.options);
  split.add_particles(frictherm::test::decomposed(serial.particles()));

  const double dt = 0.3 * h / (p_wave_speed(mats[0]) + v0);
  const int steps = 150;
  frictherm::test::SlidingDifferences diff;
  for (int s = 0; s < steps; ++s)
    diff.step(s, serial, split, dt, blk, [&](const auto& a) { return compare(a, serial.particles()); });
  const long sent = sum_over_ranks(split.traffic().particles_sent);
  const long entries = sum_over_ranks(split.traffic().field_entries_sent);
  if (comm_size() > 1) {
    EXPECT_GT(sent, 0L);     // block particles crossed rank boundaries
    EXPECT_GT(entries, 0L);  // per-material sums at shared contact nodes travelled over the star forest
  }
  // The block slid and was braked over the whole run (μ g t ≈ 1.6 m/s over 150 steps) and equals the
  // serial run to 1e-9 of the case's scales.
  frictherm::test::expect_sliding_block_equals_serial(diff, h, v0);
  frictherm::test::print_sliding_block("sliding 3D", fm::to_string(GetParam()), steps, h, v0, diff);
  print_traffic(fm::to_string(GetParam()), split);
}

INSTANTIATE_TEST_SUITE_P(Kernels, Decomposed3DSliding, ::testing::Values(fm::ShapeKind::linear, fm::ShapeKind::ugimp),
                         [](const auto& p) { return std::string(fm::to_string(p.param)); });

}  // namespace

int main(int argc, char** argv) {
  fm::DecomposedPetscSession session(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
