#include "scheme.hpp"

#include "arkode_integrators.hpp"
#include "cvode_integrator.hpp"
#include "forward_euler.hpp"

#include <cvode/cvode.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace frictherm::thermal::detail {

void open_window(const ThermalOde& ode, const std::string& name, Eigen::VectorXd& T, const Eigen::VectorXd* progress,
                 double t0, double t1) {
  std::string bad = ode.state_error(T, progress);
  if (bad.empty() && !(std::isfinite(t0) && std::isfinite(t1) && t1 >= t0)) {
    std::ostringstream os;
    os << "need finite t1 >= t0, got [" << t0 << ", " << t1 << "]";
    bad = os.str();
  }
  if (!ode.all_ranks(bad.empty())) {
    throw std::invalid_argument(ode.who(name) + ": " + (bad.empty() ? "another process rejected its input" : bad));
  }
  ode.apply_dirichlet(T);
}

std::unique_ptr<Scheme> make_scheme(const std::string& name, const IntegratorOptions& options, LinearSolverKind lin) {
  if (name == "forward_euler") return std::make_unique<ForwardEuler>(options);
  if (name == "cvode_bdf") return std::make_unique<CvodeIntegrator>(name, CV_BDF, options, lin);
  if (name == "cvode_adams") return std::make_unique<CvodeIntegrator>(name, CV_ADAMS, options, lin);
  if (name == "arkode_erk") return std::make_unique<ArkodeErk>(options);
  if (name == "arkode_dirk") return std::make_unique<ArkodeDirk>(options, lin);
  throw std::invalid_argument("make_scheme: unknown integrator \"" + name + "\"");
}

}  // namespace frictherm::thermal::detail
