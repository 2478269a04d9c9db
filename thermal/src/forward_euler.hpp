// Explicit forward Euler with a stability guard (design §3, thermal-notes §2). Internal header.
#pragma once

#include "frictherm/thermal/integrator.hpp"

#include <cstdint>

namespace frictherm::thermal::detail {

class ForwardEuler final : public Integrator {
 public:
  explicit ForwardEuler(const IntegratorOptions& options);
  std::string name() const override { return "forward_euler"; }

 protected:
  void advance_impl(const Problem& problem, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0,
                    double t1) override;

 private:
  // With a reaction: adaptive sub-steps against the reaction's own stability limit.
  void advance_reacting(const Problem& problem, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0,
                        double t1, double dt_limit);

  IntegratorOptions opt_;
  std::uint64_t cached_revision_ = 0;
  double cached_dt_limit_ = 0.0;
};

}  // namespace frictherm::thermal::detail
