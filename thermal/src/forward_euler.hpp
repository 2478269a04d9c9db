// Explicit forward Euler with a stability guard (design §3, thermal-notes §2). Internal header.
#pragma once

#include "frictherm/thermal/integrator.hpp"

#include <cstdint>

namespace frictherm::thermal::detail {

class ForwardEuler final : public Integrator {
 public:
  explicit ForwardEuler(const IntegratorOptions& options);
  void advance(const Problem& problem, Eigen::VectorXd& T, double t0, double t1) override;
  std::string name() const override { return "forward_euler"; }

 private:
  IntegratorOptions opt_;
  std::uint64_t cached_revision_ = 0;
  double cached_dt_limit_ = 0.0;
};

}  // namespace frictherm::thermal::detail
