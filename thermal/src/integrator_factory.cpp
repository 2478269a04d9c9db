#include "frictherm/thermal/integrator.hpp"

#include "scheme.hpp"
#include "serial_ode.hpp"

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
  advance_impl(problem, T, &progress, t0, t1);
}

const std::vector<std::string>& integrator_names() {
  static const std::vector<std::string> names{"forward_euler", "cvode_bdf", "cvode_adams", "arkode_erk",
                                              "arkode_dirk"};
  return names;
}

namespace {

// Integrator over the serial Problem: a Scheme (scheme.hpp) on the problem's SerialOde.
class SerialIntegrator final : public Integrator {
 public:
  explicit SerialIntegrator(std::unique_ptr<detail::Scheme> scheme) : scheme_(std::move(scheme)) {}
  std::string name() const override { return scheme_->name(); }

 protected:
  void advance_impl(const Problem& problem, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0,
                    double t1) override {
    struct Sync {  // the counters also after a failed window
      IntegratorStats& to;
      const detail::Scheme& from;
      ~Sync() { to = from.stats(); }
    } sync{stats_, *scheme_};
    ode_.attach(problem);
    detail::open_window(ode_, name(), T, progress, t0, t1);
    if (t1 > t0) scheme_->advance(ode_, T, progress, t0, t1);
  }
  void on_reset_stats() override { scheme_->reset_stats(); }

 private:
  detail::SerialOde ode_;                   // the SUNDIALS callbacks' user data:
  std::unique_ptr<detail::Scheme> scheme_;  // freed first
};

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

void detail::check_integrator_options(const std::string& name, const IntegratorOptions& options) {
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
}

std::unique_ptr<Integrator> make_integrator(const std::string& name, const IntegratorOptions& options) {
  detail::check_integrator_options(name, options);
  const auto lin = detail::parse_linear_solver(name, options.linear_solver, true);
  return std::make_unique<SerialIntegrator>(detail::make_scheme(name, options, lin));
}

}  // namespace frictherm::thermal
