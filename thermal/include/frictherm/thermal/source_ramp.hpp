#pragma once
// The nodal heat source q(t) [W] of the conduction ODE M dT/dt = −K T + q(t) (+ boundaries): none,
// constant, or linear over a coupling window from q0 at t0 to q1 at t1 and held at its ends outside
// it. One state and one ramp fraction for the serial Problem and the decomposed DistributedProblem
// (each keeps the vectors of its own nodes: all of them, or the owned ones).
#include <Eigen/Core>

#include <algorithm>
#include <utility>

namespace frictherm::thermal {

struct SourceRamp {
  bool active = false;  // a source is set
  Eigen::VectorXd q0, q1;
  double t0 = 0.0, t1 = 0.0;  // t1 > t0: a ramp; otherwise q = q0

  void set_constant(Eigen::VectorXd q) {
    q0 = std::move(q);
    q1 = q0;
    t0 = t1 = 0.0;
    active = true;
  }
  void set_ramp(Eigen::VectorXd start, Eigen::VectorXd end, double start_time, double end_time) {
    q0 = std::move(start);
    q1 = std::move(end);
    t0 = start_time;
    t1 = end_time;
    active = true;
  }
  /// A source that ramps (false for none or a constant one).
  bool ramped() const { return active && t1 > t0; }
  /// The ramp's fraction s(t) ∈ [0, 1] (q = (1 − s) q0 + s q1), clamped outside [t0, t1]; ramped() only.
  double fraction(double t) const { return std::clamp((t - t0) / (t1 - t0), 0.0, 1.0); }
  /// q(t) into q (the size of q0); zero without a source.
  template <class Out>
  void evaluate(double t, Out&& q) const {
    if (!active) {
      q.setZero();
    } else if (!(t1 > t0)) {
      q = q0;
    } else {
      const double s = fraction(t);
      q = (1.0 - s) * q0 + s * q1;
    }
  }
};

}  // namespace frictherm::thermal
