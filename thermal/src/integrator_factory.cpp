#include "frictherm/thermal/integrator.hpp"

#include "arkode_integrators.hpp"
#include "cvode_integrator.hpp"
#include "forward_euler.hpp"

#include <cvode/cvode.h>

#include <cmath>
#include <sstream>

namespace frictherm::thermal {

IntegratorStats& IntegratorStats::operator+=(const IntegratorStats& o) {
  steps += o.steps;
  rhs_evals += o.rhs_evals;
  jac_evals += o.jac_evals;
  nonlinear_iters += o.nonlinear_iters;
  linear_iters += o.linear_iters;
  error_test_failures += o.error_test_failures;
  convergence_failures += o.convergence_failures;
  reinits += o.reinits;
  wall_seconds += o.wall_seconds;
  return *this;
}

IntegratorStats& IntegratorStats::operator-=(const IntegratorStats& o) {
  steps -= o.steps;
  rhs_evals -= o.rhs_evals;
  jac_evals -= o.jac_evals;
  nonlinear_iters -= o.nonlinear_iters;
  linear_iters -= o.linear_iters;
  error_test_failures -= o.error_test_failures;
  convergence_failures -= o.convergence_failures;
  reinits -= o.reinits;
  wall_seconds -= o.wall_seconds;
  return *this;
}

void Integrator::advance(const Problem& problem, Eigen::VectorXd& T, double t0, double t1) {
  if (problem.reaction_consumes()) {
    throw std::invalid_argument(name() +
                                ": the problem's reaction consumes its reactant; pass the reaction "
                                "progress: advance(problem, T, progress, t0, t1)");
  }
  advance_impl(problem, T, nullptr, t0, t1);
}

void Integrator::advance(const Problem& problem, Eigen::VectorXd& T, Eigen::VectorXd& progress, double t0,
                         double t1) {
  problem.check_progress(progress);
  advance_impl(problem, T, &progress, t0, t1);
}

const std::vector<std::string>& integrator_names() {
  static const std::vector<std::string> names{"forward_euler", "cvode_bdf", "cvode_adams", "arkode_erk",
                                              "arkode_dirk"};
  return names;
}

namespace {

void check_options(const std::string& name, const IntegratorOptions& o) {
  auto bad = [&](const std::string& what) {
    throw std::invalid_argument("make_integrator(\"" + name + "\"): " + what);
  };
  if (!(std::isfinite(o.rtol) && o.rtol > 0.0)) bad("rtol must be finite and > 0");
  if (!(std::isfinite(o.atol) && o.atol > 0.0)) bad("atol must be finite and > 0 (K)");
  if (!(std::isfinite(o.progress_atol) && o.progress_atol > 0.0)) bad("progress_atol must be finite and > 0");
  if (o.max_steps <= 0) bad("max_steps must be > 0");
  if (o.krylov_maxl <= 0) bad("krylov_maxl must be > 0");
  if (!(o.fe_safety > 0.0 && o.fe_safety <= 1.0)) bad("fe_safety must be in (0, 1]");
  if (!(std::isfinite(o.fe_max_dt) && o.fe_max_dt >= 0.0)) bad("fe_max_dt must be finite and >= 0");
  const auto& p = o.fe_stability_policy;
  if (p != "substep" && p != "refuse" && p != "unguarded") {
    bad("unknown fe_stability_policy \"" + p + "\" (valid: substep, refuse, unguarded)");
  }
  const auto& e = o.fe_limit_estimate;
  if (e != "gershgorin" && e != "power") {
    bad("unknown fe_limit_estimate \"" + e + "\" (valid: gershgorin, power)");
  }
}

}  // namespace

std::unique_ptr<Integrator> make_integrator(const std::string& name, const IntegratorOptions& options) {
  bool known = false;
  for (const auto& n : integrator_names()) known = known || n == name;
  if (!known) {
    std::ostringstream os;
    os << "make_integrator: unknown integrator \"" << name << "\" (valid:";
    for (const auto& n : integrator_names()) os << ' ' << n;
    os << ")";
    throw std::invalid_argument(os.str());
  }
  check_options(name, options);
  if (name == "forward_euler") {
    detail::parse_linear_solver(name, options.linear_solver);  // rejects a linear_solver
    return std::make_unique<detail::ForwardEuler>(options);
  }
  if (name == "cvode_bdf") return std::make_unique<detail::CvodeIntegrator>(name, CV_BDF, options);
  if (name == "cvode_adams") return std::make_unique<detail::CvodeIntegrator>(name, CV_ADAMS, options);
  if (name == "arkode_erk") return std::make_unique<detail::ArkodeErk>(options);
  return std::make_unique<detail::ArkodeDirk>(options);
}

}  // namespace frictherm::thermal
