// DistributedIntegrator (distributed.hpp): the serial module's Scheme (scheme.hpp: forward_euler,
// CVODE, ARKODE and their window logic, written once) on the DistributedProblem's ThermalOde
// (distributed_thermal_ode.hpp), with the energy books and the traffic counts of the decomposed run.
#include "../scheme.hpp"
#include "distributed_thermal_ode.hpp"

#include <stdexcept>

namespace frictherm::thermal {

DistributedIntegrator::DistributedIntegrator(std::unique_ptr<detail::Scheme> scheme, const std::string& preconditioner)
    : ode_(std::make_unique<detail::DistributedThermalOde>(preconditioner)), scheme_(std::move(scheme)) {}

DistributedIntegrator::~DistributedIntegrator() { scheme_.reset(); }  // before the ODE its solvers call

std::string DistributedIntegrator::name() const { return scheme_->name(); }

void DistributedIntegrator::advance(const DistributedProblem& problem, Eigen::VectorXd& T, double t0, double t1) {
  window(problem, T, nullptr, t0, t1);
}

void DistributedIntegrator::advance(const DistributedProblem& problem, Eigen::VectorXd& T, Eigen::VectorXd& progress,
                                    double t0, double t1) {
  window(problem, T, problem.has_reaction() ? &progress : nullptr, t0, t1);  // has_reaction: the same on all ranks
}

void DistributedIntegrator::window(const DistributedProblem& problem, Eigen::VectorXd& T, Eigen::VectorXd* progress,
                                   double t0, double t1) {
  const CommunicationStats before = problem.communication();
  struct Sync {  // the counters also after a failed window
    const DistributedProblem& problem;
    const CommunicationStats& before;
    CommunicationStats& comm;
    IntegratorStats& stats;
    const detail::Scheme& scheme;
    ~Sync() {
      const CommunicationStats after = problem.communication();
      comm.ghost_exchanges += after.ghost_exchanges - before.ghost_exchanges;
      comm.reductions += after.reductions - before.reductions;
      comm.ghosts_received = after.ghosts_received;
      comm.ghosts_sent = after.ghosts_sent;
      comm.neighbours = after.neighbours;
      stats = scheme.stats();
    }
  } sync{problem, before, comm_, stats_, *scheme_};
  ode_->attach(problem);
  detail::open_window(*ode_, name(), T, progress, t0, t1);
  if (!books_started_) {
    books_.initial_stored = problem.thermal_energy(T);
    books_started_ = true;
  }
  if (t1 > t0) {
    scheme_->advance(*ode_, T, progress, t0, t1);
    books_.source_heat += problem.source_heat(t0, t1);
  }
  books_.stored = problem.thermal_energy(T);
}

std::unique_ptr<DistributedIntegrator> make_distributed_integrator(const std::string& name,
                                                                   const DistributedOptions& options) {
  const IntegratorOptions& o = options.integrator;
  detail::check_integrator_options(name, o);  // the name (with the valid list) and the shared options
  auto bad = [&](const std::string& what) {
    throw std::invalid_argument("make_distributed_integrator(\"" + name + "\"): " + what);
  };
  std::string pc = options.preconditioner;
  if (pc != "jacobi" && pc != "bjacobi" && pc != "hypre" && pc != "mumps") {
    bad("unknown preconditioner \"" + pc + "\" (valid: jacobi, bjacobi, hypre, mumps)");
  }
  // "klu", the serial sparse direct solve: its distributed counterpart is MUMPS' sparse direct LU of
  // P = I − γJ over the ranks, applied as the preconditioner of the Krylov method (PCG), whose first
  // iterate is then the direct solution.
  IntegratorOptions scheme_options = o;
  if (o.linear_solver == "klu") scheme_options.linear_solver = "pcg", pc = "mumps";
  detail::LinearSolverKind lin = detail::LinearSolverKind::None;
  try {
    lin = detail::parse_linear_solver(name, scheme_options.linear_solver, false);  // Krylov by default
  } catch (const std::invalid_argument& e) {
    bad(e.what());
  }
  return std::unique_ptr<DistributedIntegrator>(
      new DistributedIntegrator(detail::make_scheme(name, scheme_options, lin), pc));
}

}  // namespace frictherm::thermal
