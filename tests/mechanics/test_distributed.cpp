// Decomposed mechanics (frictherm/mechanics/distributed.hpp), run by ctest under mpirun with 2 and 4
// ranks: (a) an isolated elastic body moving and spinning across rank boundaries keeps every particle
// (count and each mass bit for bit) and conserves linear momentum to round-off; (b) two colliding
// blocks of one material give, decomposed, the positions, velocities and stresses of the same run on
// one rank (MPI_COMM_SELF, in the same process) to round-off; (c) and those of the serial module's
// Simulation<2> (USL, FLIP, no contact) to round-off; plus the DMDA's stencil width from the
// kernels' reach and the refusals; (a') the transfers coupled physics uses (particle scalars through
// migration, node sums at the owners, owner values on the ghosts). Prints the traffic of the exchange phases (docs/distributed.md).
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
#include <functional>

namespace {

namespace fm = frictherm::mechanics;
using V2 = fm::Vec<2>;

using frictherm::test::comm_rank;
using frictherm::test::comm_size;

fm::Material elastic(double E, double nu, double rho) { return frictherm::test::elastic("elastic", E, nu, rho); }

// A rectangle [lo, hi] (multiples of h) filled with ppc × ppc particles per cell, ids from first_id.
std::vector<fm::DecomposedParticle> block(const V2& lo, const V2& hi, double h, int ppc, double rho,
                                          std::int64_t first_id, const std::function<V2(const V2&)>& velocity) {
  std::vector<fm::DecomposedParticle> out;
  const double d = h / ppc;
  const int nx = static_cast<int>(std::lround((hi[0] - lo[0]) / d)), ny = static_cast<int>(std::lround((hi[1] - lo[1]) / d));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      fm::DecomposedParticle p;
      p.id = first_id + j * nx + i;
      p.position = lo + V2((i + 0.5) * d, (j + 0.5) * d);
      p.volume = d * d;
      p.mass = rho * p.volume;
      p.half_size = V2(0.5 * d, 0.5 * d);
      p.velocity = velocity(p.position);
      out.push_back(p);
    }
  return out;
}

// Rank 0 creates the particles; the first migration sends them to their owners.
std::vector<fm::DecomposedParticle> on_rank0(std::vector<fm::DecomposedParticle> all, MPI_Comm comm) {
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r == 0 ? all : std::vector<fm::DecomposedParticle>{};
}

void print_traffic(const char* label, const fm::DecomposedMpm2D& run) {
  const fm::DecomposedTraffic& t = run.traffic();
  long ghost = t.ghost_nodes, sent = t.particles_sent, ghost_max = t.ghost_nodes;
  MPI_Allreduce(MPI_IN_PLACE, &ghost, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &ghost_max, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &sent, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  const auto pr = run.processes();
  if (comm_rank() == 0) {
    std::printf("[traffic] %s: %d ranks (%d x %d), stencil width %d, %ld steps; per step: 3 exchanges; grid "
                "exchanges move %d doubles per ghost node, ghost nodes %ld in all (max %ld per rank) = %.1f kB "
                "per exchange in all; migration %.2f particles per step in all at %d B each\n",
                label, comm_size(), pr[0], pr[1], run.stencil_width(), t.steps, t.values_per_node, ghost, ghost_max,
                ghost * t.values_per_node * 8.0 / 1024.0, t.steps > 0 ? static_cast<double>(sent) / t.steps : 0.0,
                t.particle_bytes);
    std::printf("[phases] %s, rank 0, s:", label);
    for (std::size_t p = 0; p < fm::DecomposedMpm2D::phase_names().size(); ++p)
      std::printf(" %s %.4f", fm::DecomposedMpm2D::phase_names()[p], t.phase_seconds[p]);
    std::printf("\n");
  }
}

// ---- the DMDA's stencil width: the kernels' reach beyond the nearest node ----
TEST(DecomposedMechanics, StencilWidthIsTheKernelsReachBeyondTheNearestNode) {
  // Linear: nodes j, j+1 of cell j, nearest j or j+1. uGIMP (l_p ≤ h/2) and the quadratic B-spline:
  // three nodes centred on the nearest one.
  EXPECT_EQ(fm::stencil_reach(fm::ShapeKind::linear), 1);
  EXPECT_EQ(fm::stencil_reach(fm::ShapeKind::ugimp), 1);
  EXPECT_EQ(fm::stencil_reach(fm::ShapeKind::quadratic_bspline), 1);
  // The extended B-spline: a degenerate node of the block (nearest ± 1) is extended from the three
  // B-splines on its nearest interior cell, within search_radius (3) of it: 1 + 3 + 1 nodes.
  EXPECT_EQ(fm::stencil_reach(fm::ShapeKind::extended_bspline), fm::EbsOptions{}.search_radius + 2);
  EXPECT_EQ(fm::stencil_reach(fm::ShapeKind::extended_bspline), 5);
  const fm::Grid<2> grid(V2(0.0, 0.0), V2(1e-3, 1e-3), {8, 8});
  fm::Material rigid = elastic(1e6, 0.3, 1000.0);  // (materials: test_distributed_materials.cpp)
  rigid.kind = fm::MaterialKind::rigid;
  rigid.rigid_controls = {{true, false, false}};  // a free component needs a boundary rigid material
  const fm::DecomposedMpm2D::Options options;  // named: GCC 12 misreads a braced temporary's strings
  EXPECT_THROW(fm::DecomposedMpm2D(MPI_COMM_WORLD, grid, rigid, options), std::invalid_argument);
}

// ---- (a) an isolated body crossing rank boundaries: particles kept, momentum conserved ----
TEST(DecomposedMechanics, IsolatedBodyKeepsEveryParticleAndConservesMomentum) {
  const double h = 1e-3, rho = 1000.0;
  const fm::Grid<2> grid(V2(0.0, 0.0), V2(h, h), {30, 20});
  fm::DecomposedOptions opt;
  opt.shape = fm::ShapeKind::ugimp;
  fm::DecomposedMpm2D run(MPI_COMM_WORLD, grid, elastic(1e7, 0.3, rho), opt);
  const V2 c(10e-3, 7e-3);
  // Translation (30, 15) m/s, spin 2000 rad/s and a stretching rate 500 /s: it moves 9 cells,
  // turns and vibrates.
  auto velocity = [&](const V2& x) {
    const V2 r = x - c;
    return V2(30.0 - 2000.0 * r[1] + 500.0 * r[0], 15.0 + 2000.0 * r[0]);
  };
  const auto initial = block(V2(6e-3, 4e-3), V2(14e-3, 10e-3), h, 2, rho, 0, velocity);
  run.add_particles(on_rank0(initial, MPI_COMM_WORLD));
  const long long n0 = static_cast<long long>(initial.size());
  EXPECT_EQ(run.global_particles(), n0);
  {
    // The first migration moved every particle's data unchanged (bit for bit).
    const auto moved = run.gather();
    bool same = moved.size() == initial.size();
    for (std::size_t k = 0; same && k < moved.size(); ++k)
      same = moved[k].id == initial[k].id && moved[k].position == initial[k].position &&
             moved[k].velocity == initial[k].velocity && moved[k].volume == initial[k].volume;
    EXPECT_TRUE(same);
    if (!same && !moved.empty())
      std::printf("rank %d: id %lld x %g %g v %g %g (initial x %g %g)\n", comm_rank(), (long long)moved[0].id,
                  moved[0].position[0], moved[0].position[1], moved[0].velocity[0], moved[0].velocity[1],
                  initial[0].position[0], initial[0].position[1]);
  }
  const V2 p0 = run.total_momentum();
  const double scale = run.total_momentum_scale();
  const double cp = std::sqrt((elastic(1e7, 0.3, rho).p_wave_modulus(fm::Analysis::plane_strain)) / rho);
  const double dt = 0.3 * h / (cp + 40.0);
  double worst = 0.0;
  for (int s = 0; s < 150; ++s) {
    run.step(dt);
    worst = std::max(worst, (run.total_momentum() - p0).norm() / scale);
  }
  EXPECT_EQ(run.global_particles(), n0);
  const auto fin = run.gather();
  bool same_masses = fin.size() == initial.size();
  for (std::size_t k = 0; same_masses && k < fin.size(); ++k)
    same_masses = fin[k].id == initial[k].id && fin[k].mass == initial[k].mass;  // bit for bit
  EXPECT_TRUE(same_masses);
  // Momentum: Σ_p m_p Δv_p = dt Σ_i m_i a_i = dt Σ_i f_i = 0 (Σ_i G_ip = 0); round-off only.
  EXPECT_LE(worst, 1e-12) << "largest |P(t) − P(0)| / Σ m|v| over 150 steps";
  // The body did cross rank boundaries: the centre of mass moved 9 cells.
  V2 xc = V2::Zero();
  double m = 0.0;
  for (const auto& p : fin) xc += p.mass * p.position, m += p.mass;
  xc /= m;
  EXPECT_GT((xc - c).norm(), 8.0 * h);
  long sent = run.traffic().particles_sent;
  MPI_Allreduce(MPI_IN_PLACE, &sent, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  if (comm_size() > 1) {
    EXPECT_GT(sent, 0L);
  }
  if (comm_rank() == 0) std::printf("[momentum] largest relative drift %.3e over 150 steps\n", worst);
  print_traffic("isolated body, uGIMP", run);
}

// ---- (a') the transfers for coupled physics: particle scalars migrate, node sums complete at the
// owners and owner values reach the ghosts ----
TEST(DecomposedMechanics, TransfersCarryScalarsAndCompleteNodeSums) {
  const double h = 1e-3, rho = 1000.0;
  const fm::Grid<2> grid(V2(0.0, 0.0), V2(h, h), {30, 20});
  fm::DecomposedOptions opt;
  opt.shape = fm::ShapeKind::ugimp;
  opt.particle_scalars = {"temperature", "tag"};
  fm::DecomposedMpm2D run(MPI_COMM_WORLD, grid, elastic(1e7, 0.3, rho), opt);
  auto velocity = [](const V2&) { return V2(40.0, 25.0); };
  auto initial = block(V2(6e-3, 4e-3), V2(14e-3, 10e-3), h, 2, rho, 0, velocity);
  for (auto& p : initial) p.scalars = {300.0 + 0.01 * static_cast<double>(p.id), -static_cast<double>(p.id)};
  run.add_particles(on_rank0(initial, MPI_COMM_WORLD));
  const double cp = std::sqrt((elastic(1e7, 0.3, rho).p_wave_modulus(fm::Analysis::plane_strain)) / rho);
  const double dt = 0.3 * h / (cp + 50.0);
  for (int s = 0; s < 60; ++s) run.step(dt);  // the body moves ≈ 4 cells, into the next rank
  long sent = run.traffic().particles_sent;
  MPI_Allreduce(MPI_IN_PLACE, &sent, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  if (comm_size() > 1) {
    EXPECT_GT(sent, 0L);  // the scalars did travel with migrating particles
  }
  const auto fin = run.gather();
  bool same = fin.size() == initial.size();
  for (std::size_t k = 0; same && k < fin.size(); ++k)
    same = fin[k].id == initial[k].id && fin[k].scalars == initial[k].scalars;  // bit for bit
  EXPECT_TRUE(same);
  EXPECT_EQ(run.particle_scalar_index("tag"), 1);
  EXPECT_THROW(run.particle_scalar_index("pressure"), std::invalid_argument);

  // M_i = Σ_p m_p S_ip from every rank's particles summed at the owners: Σ_i M_i = Σ_p m_p (partition
  // of unity), and with M_i back on the ghosts, Σ_p m_p Σ_i S_ip M_i = Σ_i M_i² (both sides over ranks).
  const fm::DecomposedStencils& st = run.current_stencils();
  const fm::DecomposedLocalParticles lp = run.local_particle_data();
  const std::vector<double> tag = run.particle_scalar(1);
  std::vector<double> local(static_cast<std::size_t>(run.local_node_count()), 0.0), owned, ghosted;
  bool tags = tag.size() == lp.id.size();
  for (std::size_t k = 0; k < lp.id.size(); ++k) {
    tags = tags && tag[k] == -static_cast<double>(lp.id[k]);
    for (int a = st.first[k]; a < st.first[k + 1]; ++a)
      local[static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)])] += lp.mass[k] * st.S[static_cast<std::size_t>(a)];
  }
  EXPECT_TRUE(tags);  // the scalars in swarm order belong to the local particles
  run.sum_to_owned(local, 1, owned);
  run.owned_to_local(owned, 1, ghosted);
  double sums[4] = {0.0, 0.0, 0.0, 0.0};  // Σ M_i, Σ m_p, Σ_p m_p Σ_i S_ip M_i, Σ M_i²
  for (double M : owned) sums[0] += M, sums[3] += M * M;
  for (std::size_t k = 0; k < lp.id.size(); ++k) {
    sums[1] += lp.mass[k];
    for (int a = st.first[k]; a < st.first[k + 1]; ++a)
      sums[2] += lp.mass[k] * st.S[static_cast<std::size_t>(a)] * ghosted[static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)])];
  }
  bool owners_kept = true;  // the owned nodes keep their values through owned_to_local
  for (std::size_t q = 0; q < owned.size(); ++q)
    owners_kept = owners_kept && ghosted[static_cast<std::size_t>(run.owned_local_nodes()[q])] == owned[q];
  EXPECT_TRUE(owners_kept);
  MPI_Allreduce(MPI_IN_PLACE, sums, 4, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_LE(std::fabs(sums[0] - sums[1]) / sums[1], 1e-14);
  EXPECT_LE(std::fabs(sums[2] - sums[3]) / sums[3], 1e-14);
  EXPECT_THROW(run.sum_to_owned(local, fm::DecomposedMpm2D::max_transfer_components + 1, owned), std::invalid_argument);
  if (comm_rank() == 0)
    std::printf("[transfers] partition of unity %.2e, ghost identity %.2e\n", std::fabs(sums[0] - sums[1]) / sums[1],
                std::fabs(sums[2] - sums[3]) / sums[3]);
}

// ---- (b) the decomposed run equals the same run on one rank ----
class DecomposedEqualsOneRank : public ::testing::TestWithParam<fm::ShapeKind> {};

TEST_P(DecomposedEqualsOneRank, TwoCollidingBlocks) {
  const double h = 1e-3, rho = 1000.0, E = 1e6;
  const fm::Grid<2> grid(V2(0.0, 0.0), V2(h, h), {28, 16});
  fm::DecomposedOptions opt;
  opt.shape = GetParam();
  opt.gravity = V2(0.0, -200.0);  // a body force too
  const fm::Material mat = elastic(E, 0.3, rho);
  auto right = [](const V2&) { return V2(8.0, 0.5); };
  auto left = [](const V2&) { return V2(-8.0, 0.0); };
  std::vector<fm::DecomposedParticle> all;
  if (GetParam() == fm::ShapeKind::linear) {
    // Linear hats: a particle entering a new cell gives a node of tiny mass m_i a force −V σ G_ip
    // with |G_ip| = 1/h, so v_i = p_i/m_i is huge (the cell-crossing error); in the collision this
    // amplifies the reordered sums' round-off to 3e-9 in 80 steps, and with 0.8 m/s the bar below
    // blows up at step 68 on one rank as well. The chaos-free case: a bar vibrating in its first
    // mode, v = v0 sin(πX/ℓ), with v0 small enough (0.2 m/s, ≤ 0.11 mm in 80 steps) that no particle
    // leaves its cell (they sit a quarter cell, 0.25 mm, from the cell edges).
    all = block(V2(5e-3, 6e-3), V2(23e-3, 10e-3), h, 2, rho, 0,
                [](const V2& x) { return V2(0.2 * std::sin(M_PI * (x[0] - 5e-3) / 18e-3), 0.0); });
  } else {
    all = block(V2(7e-3, 4e-3), V2(13e-3, 10e-3), h, 2, rho, 0, right);
    const auto b2 = block(V2(15e-3, 5e-3), V2(21e-3, 11e-3), h, 2, rho, 1000, left);
    all.insert(all.end(), b2.begin(), b2.end());
  }

  fm::DecomposedMpm2D split(MPI_COMM_WORLD, grid, mat, opt);
  fm::DecomposedMpm2D one(MPI_COMM_SELF, grid, mat, opt);  // every rank runs the 1-rank reference
  split.add_particles(on_rank0(all, MPI_COMM_WORLD));
  one.add_particles(all);
  const double dt = 0.3 * h / (std::sqrt(mat.p_wave_modulus(fm::Analysis::plane_strain) / rho) + 8.0);
  for (int s = 0; s < 80; ++s) {
    split.step(dt);
    one.step(dt);
  }
  const auto a = split.gather(), b = one.gather();
  EXPECT_EQ(a.size(), all.size());
  EXPECT_EQ(b.size(), all.size());
  double dx = 0.0, dv = 0.0, ds = 0.0, vmax = 0.0, smax = 0.0;
  const double L = 28.0 * h;
  for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
    EXPECT_EQ(a[k].id, b[k].id);
    dx = std::max(dx, (a[k].position - b[k].position).norm());
    dv = std::max(dv, (a[k].velocity - b[k].velocity).norm());
    ds = std::max(ds, (a[k].stress - b[k].stress).norm());
    vmax = std::max(vmax, b[k].velocity.norm());
    smax = std::max(smax, b[k].stress.norm());
  }
  // The blocks met (stresses of the order of ρ c v ≈ 3e5 Pa); the bar vibrated (peak ρ c v0 ≈ 7e3
  // Pa; 80 steps = 0.54 ms ends near a zero of its 1 ms period, measured 8e2 Pa).
  EXPECT_GT(smax, GetParam() == fm::ShapeKind::linear ? 1e2 : 1e4);
  // Round-off: the sums at shared nodes are added in another order (per rank, then across ranks).
  EXPECT_LE(dx / L, 1e-12);
  EXPECT_LE(dv / vmax, 1e-12);
  EXPECT_LE(ds / smax, 1e-12);
  if (comm_rank() == 0)
    std::printf("[equality] %s: max |Δx|/L %.2e, |Δv|/v_max %.2e, |Δσ|/σ_max %.2e (σ_max %.3e Pa)\n",
                fm::to_string(GetParam()), dx / L, dv / vmax, ds / smax, smax);
  print_traffic(fm::to_string(GetParam()), split);
}

INSTANTIATE_TEST_SUITE_P(Kernels, DecomposedEqualsOneRank,
                         ::testing::Values(fm::ShapeKind::linear, fm::ShapeKind::ugimp,
                                           fm::ShapeKind::quadratic_bspline),
                         [](const auto& p) { return std::string(fm::to_string(p.param)); });

// ---- (c) the decomposed run equals the serial module's Simulation<2> (USL, FLIP, no contact) ----
TEST(DecomposedMechanics, EqualsTheSerialSimulation) {
  const double h = 1e-3, rho = 1000.0;
  const fm::Grid<2> grid(V2(0.0, 0.0), V2(h, h), {28, 16});
  fm::SimulationOptions so = frictherm::test::usl_options(fm::ShapeKind::ugimp);
  so.gravity = fm::Vec<3>(0.0, -200.0, 0.0);
  fm::Simulation<2> serial(grid, so);
  const fm::Material mat = elastic(1e6, 0.3, rho);
  const int m = serial.add_material(mat);
  serial.add_body("left", *fm::make_box<2>(V2(7e-3, 4e-3), V2(13e-3, 10e-3), m), 2, V2(8.0, 0.5));
  serial.add_body("right", *fm::make_box<2>(V2(15e-3, 5e-3), V2(21e-3, 11e-3), m), 2, V2(-8.0, 0.0));
  serial.finalize();
  const auto& sp = serial.particles();
  fm::DecomposedOptions opt;
  opt.shape = so.shape;
  opt.gravity = V2(0.0, -200.0);
  fm::DecomposedMpm2D split(MPI_COMM_WORLD, grid, mat, opt);
  split.add_particles(frictherm::test::decomposed(sp));
  const double dt = 0.3 * h / (std::sqrt(mat.p_wave_modulus(fm::Analysis::plane_strain) / rho) + 8.0);
  double taken = 0.0;
  for (int s = 0; s < 80; ++s) {
    taken = std::max(taken, std::fabs(serial.step(dt) - dt));
    split.step(dt);
  }
  EXPECT_EQ(taken, 0.0);  // the serial step took dt (below its CFL limit)
  const auto a = split.gather();
  EXPECT_EQ(a.size(), sp.size());
  double dx = 0.0, dv = 0.0, ds = 0.0, vmax = 0.0, smax = 0.0;
  for (std::size_t k = 0; k < std::min(a.size(), sp.size()); ++k) {
    dx = std::max(dx, (a[k].position - sp.position[k]).norm());
    dv = std::max(dv, (a[k].velocity - sp.velocity[k]).norm());
    ds = std::max(ds, (a[k].stress - sp.stress[k]).norm());
    vmax = std::max(vmax, sp.velocity[k].norm());
    smax = std::max(smax, sp.stress[k].norm());
  }
  EXPECT_GT(smax, 1e4);  // the blocks met
  // Round-off: the same operations per particle, the nodal sums in another order.
  EXPECT_LE(dx / (28.0 * h), 1e-12);
  EXPECT_LE(dv / vmax, 1e-12);
  EXPECT_LE(ds / smax, 1e-12);
  if (comm_rank() == 0)
    std::printf("[serial] uGIMP, USL: max |Δx|/L %.2e, |Δv|/v_max %.2e, |Δσ|/σ_max %.2e\n", dx / (28.0 * h),
                dv / vmax, ds / smax);
}

}  // namespace

int main(int argc, char** argv) {
  fm::DecomposedPetscSession session(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
