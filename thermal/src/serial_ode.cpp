#include "serial_ode.hpp"

#include "frictherm/thermal/stability.hpp"

#include <stdexcept>

namespace frictherm::thermal::detail {

std::string SerialOde::state_error(const Eigen::VectorXd& temperature, const Eigen::VectorXd* progress) const {
  try {
    problem_->check_state(temperature);
    if (progress != nullptr) problem_->check_progress(*progress);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return {};
}

double SerialOde::dt_limit(const std::string& estimate) const { return forward_euler_dt_limit(*problem_, estimate); }

NVectorPtr SerialOde::make_vector(SUNContext ctx) const {
  return detail::make_vector(static_cast<long>(form_.state_size()), ctx);
}

OdeCallbacks SerialOde::callbacks() {
  OdeCallbacks c;
  c.rhs = &OdeSystem::rhs;
  c.jac = &OdeSystem::jac;
  c.jtimes = &OdeSystem::jtimes;
  c.psetup = form_.has_reaction() ? &OdeSystem::psetup : nullptr;  // Jacobi needs no set-up
  c.psolve = &OdeSystem::psolve;
  c.user_data = &form_;
  return c;
}

}  // namespace frictherm::thermal::detail
