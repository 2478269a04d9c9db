// Explicit forward Euler with a stability guard (design §3, thermal-notes §2). Internal header.
#pragma once

#include "scheme.hpp"

#include <cstdint>

namespace frictherm::thermal::detail {

class ForwardEuler final : public Scheme {
 public:
  explicit ForwardEuler(const IntegratorOptions& options);
  void advance(ThermalOde& ode, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0, double t1) override;

 private:
  // With a reaction: adaptive sub-steps against the reaction's own stability limit.
  void advance_reacting(ThermalOde& ode, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0, double t1,
                        double dt_limit);

  IntegratorOptions opt_;
  std::uint64_t cached_revision_ = 0;
  double cached_dt_limit_ = 0.0;
};

}  // namespace frictherm::thermal::detail
