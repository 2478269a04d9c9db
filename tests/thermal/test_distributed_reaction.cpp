// The Arrhenius reaction in the distributed thermal solve (distributed.hpp: DistributedProblem::
// set_reaction, DistributedIntegrator::advance with the progress λ; issue 32, the first part of a
// decomposed `thermal.reaction`), run by ctest under mpirun with 2 and 4 ranks against the serial
// module (Problem::set_reaction, Integrator::advance with progress) on the 2D grid of
// test_distributed.cpp (conductivity 0.2): a hot blob (up to 388 K) in a slab whose left 60 % reacts
// (first order, Θ = 15 000 K, k(380 K) = 300 /s, Q_i = 50 K · M_i: the blob runs away, λ → 1, 393 K
// within the 10 ms), left edge held at 300 K.
//   * cvode_bdf with linear_solver "pcg": a consuming reaction makes the Newton matrix non-symmetric,
//     so both switch to GMRES with the serial 2×2 block-Jacobi preconditioner: the same algorithm,
//     the same steps; T and λ within 1 % of the local tolerance rtol |T| + atol (λ: rtol + progress_atol)
//     of the serial run (the runs differ by the summation order of the global reductions only);
//   * against a tight serial reference (KLU, rtol = atol = 1e-12): as accurate as the serial run;
//   * the books: Σ M T − Σ Q λ is invariant without sources and fixed nodes (released_heat);
//   * forward_euler (the serial implementation, issue 32) takes the same sub-steps as the serial run,
//     its conduction + self-heating limit agreed over the ranks; T and λ equal to round-off.
// No ASSERT before a collective call: a rank that returned early would leave the others waiting.
#include "frictherm/thermal/distributed.hpp"
#include "grids.hpp"

#include "frictherm/thermal/integrator.hpp"

#include "../mpi_ranks.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace {

namespace ft = frictherm::thermal;
using thermal_test::Grid2D;
using thermal_test::make_grid_2d;
using thermal_test::Material;

using frictherm::test::comm_rank;
using frictherm::test::comm_size;
using frictherm::test::global_max;

constexpr double kTheta = 15000.0;                   // Θ (K)
const double kZ = 300.0 * std::exp(kTheta / 380.0);  // k(380 K) = 300 /s

Grid2D grid() { return make_grid_2d(26, 21, 0.0, 0.0, 1.0 / 25.0, Material{1.0, 0.2}); }

Eigen::VectorXd initial_field(const Grid2D& g) {
  Eigen::VectorXd t(g.size());
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double dx = g.x(i) - 0.35, dy = g.y(j) - 0.55;
      t[g.id(i, j)] = 300.0 + 80.0 * std::exp(-(dx * dx + dy * dy) / 0.02) + 10.0 * g.x(i);
    }
  return t;
}

// Q_i = 50 K · M_i where x < 0.6, else 0.
ft::Reaction reaction(const Grid2D& g, ft::Index first, ft::Index count) {
  ft::Reaction r;
  r.prefactor = kZ;
  r.activation_temperature = kTheta;
  r.heat = Eigen::VectorXd::Zero(count);
  for (ft::Index k = 0; k < count; ++k) {
    const auto id = static_cast<int>(first + k);
    if (g.x(id % g.nx) < 0.6) r.heat[k] = 50.0 * g.mass[id];
  }
  return r;
}

struct Part {
  ft::RowRange rows;
  std::unique_ptr<ft::DistributedProblem> problem;
};

Part distribute(const Grid2D& g, bool fixed_edge) {
  Part p;
  p.rows = ft::partition_rows(g.size(), MPI_COMM_WORLD);
  const ft::Index n = p.rows.size();
  ft::SparseMatrix k = g.k.middleRows(p.rows.begin, n);
  p.problem = std::make_unique<ft::DistributedProblem>(MPI_COMM_WORLD, g.size(), p.rows.begin,
                                                       Eigen::VectorXd(g.mass.segment(p.rows.begin, n)), std::move(k));
  if (fixed_edge)
    for (int j = 0; j < g.ny; ++j)
      if (p.problem->owns(g.id(0, j))) p.problem->set_dirichlet(g.id(0, j), 300.0);
  p.problem->set_reaction(reaction(g, p.rows.begin, n));
  return p;
}

// The serial problem (left edge held at 300 K) and this rank's part of it.
ft::Problem serial_problem(const Grid2D& g) {
  ft::Problem serial = g.problem();
  for (int j = 0; j < g.ny; ++j) serial.set_dirichlet(g.id(0, j), 300.0);
  serial.set_reaction(reaction(g, 0, g.size()));
  return serial;
}

constexpr double kWindow = 2.5e-3;
constexpr int kWindows = 4;

// kWindows windows of the named integrator, serial (ts, ls) and distributed (td, ld: owned T and λ);
// dT, dl: the largest |distributed − serial| over all ranks.
struct Runs {
  Eigen::VectorXd ts, ls, td, ld;
  double dT = 0.0, dl = 0.0;
  ft::IntegratorStats serial, distributed;
};
Runs run_both(const Grid2D& g, const ft::Problem& serial, const Part& part, const std::string& name,
              const ft::IntegratorOptions& o) {
  auto s_int = ft::make_integrator(name, o);
  ft::DistributedOptions d;
  d.integrator = o;
  auto d_int = ft::make_distributed_integrator(name, d);
  const ft::Index first = part.rows.begin, n = part.rows.size();
  Runs r;
  r.ts = initial_field(g);
  r.ls = Eigen::VectorXd::Zero(g.size());
  r.td = r.ts.segment(first, n);
  r.ld = Eigen::VectorXd::Zero(n);
  for (int w = 0; w < kWindows; ++w) {
    s_int->advance(serial, r.ts, r.ls, w * kWindow, (w + 1) * kWindow);
    d_int->advance(*part.problem, r.td, r.ld, w * kWindow, (w + 1) * kWindow);
  }
  r.dT = global_max((r.td - r.ts.segment(first, n)).cwiseAbs().maxCoeff());
  r.dl = global_max((r.ld - r.ls.segment(first, n)).cwiseAbs().maxCoeff());
  r.serial = s_int->stats();
  r.distributed = d_int->stats();
  return r;
}

TEST(DistributedReaction, CvodeBdfReproducesTheSerialSolution) {
  const Grid2D g = grid();
  const ft::Problem serial = serial_problem(g);
  Part part = distribute(g, true);
  const ft::Index first = part.rows.begin, n = part.rows.size();
  const Eigen::VectorXd t_init = initial_field(g);
  Eigen::VectorXd t_ref = t_init, lam_ref = Eigen::VectorXd::Zero(g.size());
  {
    ft::IntegratorOptions o;
    o.rtol = o.atol = 1e-12;
    o.progress_atol = 1e-12;
    o.max_steps = 100000;
    auto ref = ft::make_integrator("cvode_bdf", o);  // KLU
    ref->advance(serial, t_ref, lam_ref, 0.0, kWindows * kWindow);
  }
  ft::IntegratorOptions o;
  o.rtol = o.atol = 1e-8;
  o.linear_solver = "pcg";
  const Runs r = run_both(g, serial, part, "cvode_bdf", o);
  const Eigen::VectorXd &ts = r.ts, &ls = r.ls, &td = r.td, &ld = r.ld;
  const double dT = r.dT, dl = r.dl;
  const double errT = global_max((td - t_ref.segment(first, n)).cwiseAbs().maxCoeff());
  const double errl = global_max((ld - lam_ref.segment(first, n)).cwiseAbs().maxCoeff());
  const double tmax = ts.cwiseAbs().maxCoeff(), lmax = ls.maxCoeff();
  const double tol_T = o.rtol * tmax + o.atol, tol_l = o.rtol + o.progress_atol;
  EXPECT_GT(lmax, 0.5) << "the blob reacts";
  EXPECT_GT(tmax, t_init.maxCoeff() + 5.0) << "and heats";
  EXPECT_EQ(r.distributed.steps, r.serial.steps);
  EXPECT_LE(dT, 0.01 * tol_T);
  EXPECT_LE(dl, 0.01 * tol_l);
  // As accurate as the serial run against the tight reference (a runaway amplifies the local errors:
  // both measured at 24 local tolerances in T, where conduction alone gives 0.2–10).
  const double s_errT = (ts - t_ref).cwiseAbs().maxCoeff(), s_errl = (ls - lam_ref).cwiseAbs().maxCoeff();
  EXPECT_LE(errT, s_errT + 0.01 * tol_T);
  EXPECT_LE(errl, s_errl + 0.01 * tol_l);
  if (comm_rank() == 0)
    std::printf("[distributed reaction, %d ranks] T_max %.4f K, λ_max %.4f; |dist − serial| T %.2e K (tol %.1e), "
                "λ %.2e (tol %.1e); |dist − ref| T %.2e K, λ %.2e (serial %.2e K, %.2e); steps %ld (serial %ld), "
                "%.2f Krylov iterations per step\n",
                comm_size(), tmax, lmax, dT, tol_T, dl, tol_l, errT, errl, s_errT, s_errl, r.distributed.steps,
                r.serial.steps, static_cast<double>(r.distributed.linear_iters) / static_cast<double>(r.distributed.steps));
}

// Insulated, no source: Σ M T − Σ Q λ is invariant (reaction.hpp), to the integrator's tolerance.
TEST(DistributedReaction, HeatReleasedEqualsTheThermalEnergyGained) {
  const Grid2D g = grid();
  Part part = distribute(g, false);
  const ft::Index n = part.rows.size();
  ft::DistributedOptions d;
  d.integrator.rtol = d.integrator.atol = 1e-10;
  d.integrator.progress_atol = 1e-10;
  auto integ = ft::make_distributed_integrator("cvode_bdf", d);
  Eigen::VectorXd t = initial_field(g).segment(part.rows.begin, n), lam = Eigen::VectorXd::Zero(n);
  const double e0 = part.problem->thermal_energy(t);
  integ->advance(*part.problem, t, lam, 0.0, 1e-2);
  const double gained = part.problem->thermal_energy(t) - e0, released = part.problem->released_heat(lam);
  EXPECT_GT(released, 0.0);
  EXPECT_NEAR(gained, released, 1e-6 * released);
  if (comm_rank() == 0)
    std::printf("[distributed reaction, %d ranks] released %.9g J/m, Σ M ΔT %.9g J/m (difference %.2e of it)\n",
                comm_size(), released, gained, std::fabs(gained - released) / released);
}

TEST(DistributedReaction, ForwardEulerReproducesTheSerialSolution) {
  const Grid2D g = grid();
  const ft::Problem serial = serial_problem(g);
  Part part = distribute(g, true);
  ft::IntegratorOptions o;
  o.max_steps = 1000000;
  const Runs r = run_both(g, serial, part, "forward_euler", o);
  // The same arithmetic per node (K·T in K's column order, the sub-step from a global maximum):
  // equal to round-off, 1e-12 K on ~400 K and 1e-12 in λ leave room for a different rounding.
  EXPECT_GT(r.ls.maxCoeff(), 0.5) << "the blob reacts";
  EXPECT_EQ(r.distributed.steps, r.serial.steps);
  EXPECT_LE(r.dT, 1e-12 * r.ts.cwiseAbs().maxCoeff());
  EXPECT_LE(r.dl, 1e-12);
  if (comm_rank() == 0)
    std::printf("[distributed reaction, %d ranks] forward_euler: %ld sub-steps (serial %ld), |dist − serial| T %.2e K, "
                "λ %.2e\n",
                comm_size(), r.distributed.steps, r.serial.steps, r.dT, r.dl);
}

}  // namespace

int main(int argc, char** argv) {
  ft::PetscSession session(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
