// Distributed thermal solve (frictherm/thermal/distributed.hpp), run by ctest under mpirun with
// 2 and 4 ranks: (a) a 2D grid partitioned over the ranks reproduces the serial module's
// solution, (b) a decaying Fourier mode matches its analytic amplitude with the error falling as
// h², (c) the energy books close with a heat source and insulated boundaries, plus the layout's
// ghost counts and the refusal of a bad layout on every rank.
// No ASSERT before a collective call: a rank that returned early would leave the others waiting.
#include "frictherm/thermal/distributed.hpp"
#include "grids.hpp"

#include "frictherm/thermal/integrator.hpp"
#include "frictherm/thermal/stability.hpp"

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

// This rank's share of a serial grid: the balanced row partition of its nodes.
struct Part {
  ft::RowRange rows;
  std::unique_ptr<ft::DistributedProblem> problem;
};

Part distribute(const Grid2D& g) {
  Part p;
  p.rows = ft::partition_rows(g.size(), MPI_COMM_WORLD);
  const ft::Index n = p.rows.size();
  ft::SparseMatrix k = g.k.middleRows(p.rows.begin, n);
  p.problem = std::make_unique<ft::DistributedProblem>(MPI_COMM_WORLD, g.size(), p.rows.begin,
                                                       Eigen::VectorXd(g.mass.segment(p.rows.begin, n)), std::move(k));
  return p;
}

// A smooth hot blob off-centre, above 300 K.
Eigen::VectorXd initial_field(const Grid2D& g) {
  Eigen::VectorXd t(g.size());
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double dx = g.x(i) - 0.35, dy = g.y(j) - 0.55;
      t[g.id(i, j)] = 300.0 + 80.0 * std::exp(-(dx * dx + dy * dy) / 0.02) + 10.0 * g.x(i);
    }
  return t;
}

// ---- (a) the serial module's solution, reproduced ----
struct Case {
  std::string name, linear_solver, preconditioner;
  double rtol;
};

TEST(DistributedThermal, ReproducesTheSerialSolution) {
  const Grid2D g = make_grid_2d(26, 21, 0.0, 0.0, 1.0 / 25.0, Material{1.0, 1.0});
  const Eigen::VectorXd t_init = initial_field(g);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(g.size());
  q[g.id(12, 10)] = 40.0;  // W per unit depth: a source in the middle rows (a rank boundary at 2 and 4 ranks)
  q[g.id(3, 16)] = -15.0;
  const double t_fixed = 300.0;
  // Serial problem and the same problem partitioned: fixed left edge, heat source, insulated elsewhere.
  ft::Problem serial = g.problem();
  serial.set_source(q);
  for (int j = 0; j < g.ny; ++j) serial.set_dirichlet(g.id(0, j), t_fixed);
  Part part = distribute(g);
  ft::DistributedProblem& dist = *part.problem;
  dist.set_source(q.segment(part.rows.begin, part.rows.size()));
  for (int j = 0; j < g.ny; ++j) {
    if (dist.owns(g.id(0, j))) dist.set_dirichlet(g.id(0, j), t_fixed);
  }
  const double window = 2.5e-3;  // ≈ 6 forward Euler stability limits (h²/4α = 4e-4 s)
  const int windows = 4;
  // A tight serial reference (sparse direct Newton, rtol = atol = 1e-12) for the global errors.
  Eigen::VectorXd t_ref = t_init;
  {
    ft::IntegratorOptions o;
    o.rtol = o.atol = 1e-12;
    o.max_steps = 100000;
    auto ref = ft::make_integrator("cvode_bdf", o);
    ref->advance(serial, t_ref, 0.0, windows * window);
  }
  const std::vector<Case> cases{{"forward_euler", "", "jacobi", 0.0},        {"cvode_bdf", "pcg", "jacobi", 1e-8},
                                {"cvode_bdf", "gmres", "jacobi", 1e-8},      {"cvode_bdf", "pcg", "hypre", 1e-8},
                                {"cvode_bdf", "pcg", "bjacobi", 1e-8},       {"cvode_adams", "", "jacobi", 1e-8},
                                {"arkode_erk", "", "jacobi", 1e-8},          {"arkode_dirk", "pcg", "jacobi", 1e-8},
                                // KLU serially; distributed, PCG preconditioned by MUMPS' LU of P = I − γJ
                                {"cvode_bdf", "klu", "mumps", 1e-8}};
  for (const Case& c : cases) {
    ft::IntegratorOptions o;
    if (c.rtol > 0.0) o.rtol = o.atol = c.rtol;
    o.linear_solver = c.linear_solver == "gmres" ? "pcg" : c.linear_solver;  // serial: pcg only
    auto s_int = ft::make_integrator(c.name, o);
    ft::DistributedOptions d;
    d.integrator = o;
    d.integrator.linear_solver = c.linear_solver;
    d.preconditioner = c.preconditioner;
    auto d_int = ft::make_distributed_integrator(c.name, d);
    Eigen::VectorXd ts = t_init;
    Eigen::VectorXd td = t_init.segment(part.rows.begin, part.rows.size());
    for (int w = 0; w < windows; ++w) {
      s_int->advance(serial, ts, w * window, (w + 1) * window);
      d_int->advance(dist, td, w * window, (w + 1) * window);
    }
    const Eigen::VectorXd ts_mine = ts.segment(part.rows.begin, part.rows.size());
    const double diff = global_max((td - ts_mine).cwiseAbs().maxCoeff());
    const double err = global_max((td - t_ref.segment(part.rows.begin, part.rows.size())).cwiseAbs().maxCoeff());
    const double err_serial = (ts - t_ref).cwiseAbs().maxCoeff();
    const double tmax = ts.cwiseAbs().maxCoeff();
    const double local_tol = c.rtol * tmax + c.rtol;  // rtol·max|T| + atol
    const bool same_algorithm = c.preconditioner == "jacobi" && c.linear_solver != "gmres";
    if (c.name == "forward_euler") {
      // The same operations in the same order (K's column order, midpoint source, the same
      // global stability limit): identical up to the last bit, allowed 1e-12 relative.
      EXPECT_LE(diff, 1e-12 * tmax);
      EXPECT_EQ(d_int->stats().steps, s_int->stats().steps);
      EXPECT_EQ(d_int->communication().ghost_exchanges, d_int->stats().steps);  // one K·T per sub-step
    } else if (c.linear_solver == "klu") {
      // The preconditioner is the inverse of P (to MUMPS' round-off): one Krylov iteration per
      // Newton iteration, as the direct solve.
      EXPECT_LE(d_int->stats().linear_iters, d_int->stats().nonlinear_iters) << c.name;
    } else if (same_algorithm) {
      // The serial algorithm (Jacobi on the symmetric form): the same steps, the runs differing
      // only by the summation order of the global reductions, far below the error control's
      // resolution (1% of the local tolerance; a different preconditioner moves the result at
      // the tolerance level: hypre 4e-5 K here).
      EXPECT_EQ(d_int->stats().steps, s_int->stats().steps) << c.name;
      EXPECT_LE(diff, 0.01 * local_tol) << c.name;
    }
    if (c.rtol > 0.0) {
      // Every adaptive run against the tight reference. CVODE/ARKODE keep the local error per
      // step below rtol·|T| + atol; the global error is a multiple of it that depends on the step
      // sequence, which the preconditioner moves (the Newton corrections enter the error
      // estimate): measured 0.2–10 local tolerances here (serial module: 3.2), allowed 20.
      EXPECT_LE(err, 20.0 * local_tol) << c.name << "/" << c.linear_solver << "/" << c.preconditioner;
    }
    const auto& cm = d_int->communication();
    const double steps = static_cast<double>(d_int->stats().steps);
    if (comm_rank() == 0) {
      std::printf("[distributed %d ranks] %-13s %-5s %-8s |dist - serial| %.2e K, |dist - ref| %.2e K "
                  "(serial %.2e, local tol %.1e); steps %ld (serial %ld); per step: %.2f ghost exchanges, "
                  "%.2f reductions, %.2f Krylov iterations\n",
                  comm_size(), c.name.c_str(), c.linear_solver.c_str(), c.preconditioner.c_str(), diff, err,
                  err_serial, local_tol, d_int->stats().steps, s_int->stats().steps, cm.ghost_exchanges / steps,
                  cm.reductions / steps, d_int->stats().linear_iters / steps);
    }
  }
}

// ---- ghost layout of the 5-point stencil: one grid row on each side of a rank's block ----
TEST(DistributedThermal, GhostLayoutOfTheRowPartition) {
  const Grid2D g = make_grid_2d(26, 21, 0.0, 0.0, 1.0 / 25.0, Material{1.0, 1.0});
  Part part = distribute(g);
  const auto c = part.problem->communication();
  const int sides = (part.rows.begin > 0 ? 1 : 0) + (part.rows.end < g.size() ? 1 : 0);
  EXPECT_EQ(c.ghosts_received, sides * g.nx);  // blocks hold ≥ nx nodes at ≤ 4 ranks
  EXPECT_EQ(c.ghosts_sent, sides * g.nx);      // K symmetric: what a rank needs it also gives
  EXPECT_EQ(c.neighbours, sides);
  if (comm_rank() == 0) {
    std::printf("[distributed %d ranks] 26x21 grid: rank 0 owns %ld nodes, receives %ld and sends %ld ghost "
                "values (%ld bytes) per exchange from %d neighbour(s)\n",
                comm_size(), static_cast<long>(part.rows.size()), static_cast<long>(c.ghosts_received),
                static_cast<long>(c.ghosts_sent), static_cast<long>(8 * c.ghosts_received), c.neighbours);
  }
}

// ---- (b) analytic: T = A(t) sin(πx/L) sin(πy/L), T = 0 on the boundary ----
// A(t) = exp(−2π²αt/L²). The semi-discrete 5-point mode decays at α(8/h²) sin²(πh/2L), a rate
// error −π²h²/12 relative: the amplitude error falls as h² (factor 4 per halving of h). forward
// Euler's time error also falls as h² (its step is 0.9 h²/4α); CVODE's is set far below by rtol.
double fourier_error(int n, const std::string& integrator, const std::string& pc) {
  const double length = 1.0, alpha = 1.0;
  const Grid2D g = make_grid_2d(n, n, 0.0, 0.0, length / (n - 1), Material{1.0, alpha});
  Part part = distribute(g);
  const double pi = std::acos(-1.0);
  Eigen::VectorXd t(part.rows.size());
  for (ft::Index l = 0; l < part.rows.size(); ++l) {
    const int id = static_cast<int>(part.rows.begin + l), i = id % n, j = id / n;
    t[l] = std::sin(pi * g.x(i) / length) * std::sin(pi * g.y(j) / length);
    if (i == 0 || j == 0 || i == n - 1 || j == n - 1) part.problem->set_dirichlet(id, 0.0);
  }
  ft::DistributedOptions d;
  d.integrator.rtol = d.integrator.atol = 1e-10;
  d.preconditioner = pc;
  auto integ = ft::make_distributed_integrator(integrator, d);
  const double t_end = length * length / (2.0 * pi * pi * alpha);  // amplitude e^{-1}
  integ->advance(*part.problem, t, 0.0, t_end);
  double err = 0.0;
  for (ft::Index l = 0; l < part.rows.size(); ++l) {
    const int id = static_cast<int>(part.rows.begin + l), i = id % n, j = id / n;
    const double exact = std::exp(-1.0) * std::sin(pi * g.x(i) / length) * std::sin(pi * g.y(j) / length);
    err = std::max(err, std::abs(t[l] - exact));
  }
  return global_max(err) / std::exp(-1.0);  // relative to the amplitude
}

TEST(DistributedThermal, FourierModeDecaysAsTheAnalyticSolution) {
  for (const auto& [integrator, pc] : std::vector<std::pair<std::string, std::string>>{
           {"forward_euler", "jacobi"}, {"cvode_bdf", "hypre"}}) {
    const double e1 = fourier_error(9, integrator, pc), e2 = fourier_error(17, integrator, pc),
                 e3 = fourier_error(33, integrator, pc);
    if (comm_rank() == 0) {
      std::printf("[distributed %d ranks] %s: Fourier-mode amplitude error at h = 1/8, 1/16, 1/32: %.3e %.3e %.3e "
                  "(ratios %.2f %.2f)\n",
                  comm_size(), integrator.c_str(), e1, e2, e3, e1 / e2, e2 / e3);
    }
    // Second order: ratios → 4; 3.5 leaves room for the pre-asymptotic h⁴ term at h = 1/8.
    EXPECT_GT(e1 / e2, 3.5) << integrator;
    EXPECT_GT(e2 / e3, 3.5) << integrator;
    // Leading terms at h = 1/32 over one e-folding (αλt = 1): the rate error π²h²/12 and FE's
    // time error λ·dt/2 = 2π²·0.9h²/8 (opposite signs: their magnitudes sum to a bound).
    const double h = 1.0 / 32.0, pi = std::acos(-1.0);
    EXPECT_LT(e3, (pi * pi / 12.0 + 2.0 * pi * pi * 0.9 / 8.0) * h * h) << integrator;
  }
}

// ---- (c) energy books: insulated grid, constant and ramped sources ----
// Conduction only moves heat (K has zero row and column sums), so Σ M T changes by ∫ Σ q dt.
// Explicit methods: exactly, up to round-off (forward Euler samples q at sub-step midpoints, ERK's
// quadrature is exact for q linear within a step: the ramp's kinks sit at window ends). Newton
// methods: a Krylov solve stopped at its tolerance drifts the sum unless the preconditioner keeps
// M^{1/2}·1 (Jacobi on this uniform grid does; hypre and bjacobi drifted 3e-8 and 2e-6 of the
// heat before the exact invariant component was restored after each solve,
// conservative_krylov.hpp). Fixed-point Adams: every iterate carries the exact source.
// Allowed: 1e-9 of the heat delivered (the stored energy is 3400 times larger).
struct BooksCase {
  std::string name, linear_solver;
  bool ramp;
  std::string preconditioner = "jacobi";
};

TEST(DistributedThermal, EnergyBooksCloseWithSources) {
  const Grid2D g = make_grid_2d(30, 24, 0.0, 0.0, 1.0 / 29.0, Material{2.0, 0.5});
  Part part = distribute(g);
  const ft::Index n = part.rows.size();
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(g.size()), q1 = q0;
  q0[g.id(7, 11)] = 3.0;   // W per unit depth; node 337, near the 2-rank boundary (360)
  q1[g.id(7, 11)] = 9.0;
  q0[g.id(20, 12)] = 5.0;  // on the 2-rank boundary row
  q1[g.id(25, 3)] = -2.0;  // a sink ramping in
  const Eigen::VectorXd t_init = initial_field(g).segment(part.rows.begin, n);
  const std::vector<double> ends{0.003, 0.007, 0.012, 0.018};  // window ends [s]
  const std::vector<BooksCase> cases{{"forward_euler", "", true}, {"arkode_erk", "", true},
                                     {"forward_euler", "", false}, {"cvode_bdf", "pcg", false},
                                     {"cvode_bdf", "gmres", false}, {"cvode_adams", "", false},
                                     {"arkode_erk", "", false},     {"cvode_bdf", "pcg", false, "hypre"},
                                     {"cvode_bdf", "gmres", false, "bjacobi"}, {"arkode_dirk", "gmres", false, "hypre"}};
  for (const auto& c : cases) {
    // Σq0 = 8 W; the ramp goes to Σq1 = 7 W over [0.003, 0.012] s (mean 7.5 W), then holds.
    double heat = 8.0 * ends.back();
    if (c.ramp) {
      part.problem->set_source_ramp(q0.segment(part.rows.begin, n), q1.segment(part.rows.begin, n), 0.003, 0.012);
      heat = 8.0 * 0.003 + 7.5 * (0.012 - 0.003) + 7.0 * (0.018 - 0.012);
    } else {
      part.problem->set_source(q0.segment(part.rows.begin, n));
    }
    ft::DistributedOptions d;
    d.integrator.rtol = d.integrator.atol = 1e-8;
    d.integrator.linear_solver = c.linear_solver;
    d.preconditioner = c.preconditioner;
    auto integ = ft::make_distributed_integrator(c.name, d);
    Eigen::VectorXd t = t_init;
    double t0 = 0.0;
    for (double t1 : ends) {
      integ->advance(*part.problem, t, t0, t1);
      t0 = t1;
    }
    const ft::EnergyBooks& b = integ->books();
    EXPECT_NEAR(b.source_heat, heat, 1e-14 * heat) << c.name;
    EXPECT_NEAR(b.stored, part.problem->thermal_energy(t), 1e-15 * std::abs(b.stored)) << c.name;
    EXPECT_LE(std::abs(b.imbalance()), 1e-9 * heat)
        << c.name << "/" << c.linear_solver << "/" << c.preconditioner << (c.ramp ? " ramp" : "");
    if (comm_rank() == 0) {
      std::printf("[distributed %d ranks] books %-13s %-5s %-7s %-8s: stored %.9e J, heat in %.9e J, imbalance "
                  "%.2e of the heat (stored energy %.3e J)\n",
                  comm_size(), c.name.c_str(), c.linear_solver.c_str(), c.preconditioner.c_str(),
                  c.ramp ? "ramp" : "constant",
                  b.stored - b.initial_stored, b.source_heat, b.imbalance() / heat, b.stored);
    }
  }
}

// ---- a bad layout is refused on every rank (none is left waiting in a collective) ----
TEST(DistributedThermal, BadLayoutRefusedOnEveryRank) {
  const Grid2D g = make_grid_2d(8, 8, 0.0, 0.0, 1.0 / 7.0, Material{1.0, 1.0});
  ft::RowRange rows = ft::partition_rows(g.size(), MPI_COMM_WORLD);
  const ft::Index shift = comm_rank() == comm_size() - 1 ? 1 : 0;  // the last rank claims a node too few
  const ft::Index n = rows.size() - shift;
  ft::SparseMatrix k = g.k.middleRows(rows.begin, n);
  EXPECT_THROW(ft::DistributedProblem(MPI_COMM_WORLD, g.size(), rows.begin,
                                      Eigen::VectorXd(g.mass.segment(rows.begin, n)), std::move(k)),
               std::invalid_argument);
  EXPECT_THROW(ft::make_distributed_integrator("cvode_bdf", [] {
                 ft::DistributedOptions o;
                 o.preconditioner = "ilu";
                 return o;
               }()),
               std::invalid_argument);
}

// ---- a diagonal below zero by round-off only is accepted, beyond 1e-12 of max |K| refused (every rank) ----
// (a node only zero-conductivity particles reach sums to ±1e-35 or so: serial Problem's rule)
TEST(DistributedThermal, RoundOffNegativeDiagonalAcceptedRealOneRefused) {
  const Grid2D g = make_grid_2d(8, 8, 0.0, 0.0, 1.0 / 7.0, Material{1.0, 1.0});
  const ft::RowRange rows = ft::partition_rows(g.size(), MPI_COMM_WORLD);
  const double kmax = Eigen::MatrixXd(g.k).cwiseAbs().maxCoeff();
  for (const double diagonal : {-1e-14 * kmax, -1e-9 * kmax}) {
    ft::SparseMatrix k = g.k.middleRows(rows.begin, rows.size());
    if (comm_rank() == comm_size() - 1) {  // the last rank's last node: its row and its diagonal
      const ft::Index r = rows.size() - 1, c = rows.begin + r;
      for (ft::SparseMatrix::InnerIterator it(k, r); it; ++it) it.valueRef() = it.col() == c ? diagonal : 0.0;
    }
    auto build = [&] {
      ft::DistributedProblem p(MPI_COMM_WORLD, g.size(), rows.begin, Eigen::VectorXd(g.mass.segment(rows.begin, rows.size())),
                               std::move(k));
    };
    if (diagonal > -1e-12 * kmax) EXPECT_NO_THROW(build());
    else EXPECT_THROW(build(), std::invalid_argument);
  }
}

// ---- forward Euler's guard: the global stability limit, refused on every rank ----
TEST(DistributedThermal, ForwardEulerRefusesBeyondItsLimitOnEveryRank) {
  const double h = 1.0 / 15.0;
  const Grid2D g = make_grid_2d(16, 16, 0.0, 0.0, h, Material{1.0, 1.0});
  Part part = distribute(g);
  // Gershgorin (exact for the 5-point stencil): λ_max = 8α/h², dt_limit = h²/4α on every rank
  // although only some ranks hold the stiffest rows.
  EXPECT_NEAR(part.problem->lambda_max_gershgorin(), 8.0 / (h * h), 1e-12 * 8.0 / (h * h));
  ft::DistributedOptions o;
  o.integrator.fe_stability_policy = "refuse";
  auto fe = ft::make_distributed_integrator("forward_euler", o);
  Eigen::VectorXd t = initial_field(g).segment(part.rows.begin, part.rows.size());
  const Eigen::VectorXd before = t;
  EXPECT_THROW(fe->advance(*part.problem, t, 0.0, 2.0 * h * h / 4.0), ft::StabilityError);
  EXPECT_EQ(t, before);  // the last good state kept
  EXPECT_NO_THROW(fe->advance(*part.problem, t, 0.0, 0.8 * h * h / 4.0));  // within fe_safety = 0.9
}

// ---- the "power" estimate: the serial power iteration over the ranks, to round-off ----
TEST(DistributedThermal, PowerEstimateEqualsTheSerialOne) {
  const double h = 1.0 / 15.0;
  const Grid2D g = make_grid_2d(16, 16, 0.0, 0.0, h, Material{1.0, 1.0});
  Part part = distribute(g);
  ft::Problem serial = g.problem();
  const double lam = ft::lambda_max_power(serial), mine = part.problem->lambda_max_power();
  EXPECT_GT(lam, 0.5 * 8.0 / (h * h));
  EXPECT_NEAR(mine, lam, 1e-12 * lam);  // the same start vector and iterations; sums in another order
  // And through forward Euler's limit (min(1.05 λ_power, λ_Gershgorin)), refused beyond fe_safety = 0.9 of it.
  const double limit = ft::forward_euler_dt_limit(serial, "power");
  ft::DistributedOptions o;
  o.integrator.fe_stability_policy = "refuse";
  o.integrator.fe_limit_estimate = "power";
  auto fe = ft::make_distributed_integrator("forward_euler", o);
  Eigen::VectorXd t = initial_field(g).segment(part.rows.begin, part.rows.size());
  EXPECT_NO_THROW(fe->advance(*part.problem, t, 0.0, 0.89 * limit));
  EXPECT_THROW(fe->advance(*part.problem, t, 0.0, 0.91 * limit), ft::StabilityError);
}

}  // namespace

int main(int argc, char** argv) {
  ft::PetscSession session(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
