#pragma once
// Scalar functions of time used for load ramps and prescribed (rigid) velocity histories.
#include <string>
#include <vector>

namespace frictherm::mechanics {

class TimeFunction {
 public:
  enum class Kind { constant, ramp, sinusoid, table };

  /// f(t) = value.
  static TimeFunction constant(double value);
  /// 0 before t_start, linear rise to `value` at t_start + duration, `value` after.
  static TimeFunction ramp(double value, double duration, double t_start = 0.0);
  /// 0 before t_start, amplitude * sin(omega (t - t_start)) after (Nairn 2018 eq. 44 for v(t)),
  /// optionally stopping (0) after t_end.
  static TimeFunction sinusoid(double amplitude, double omega, double t_start = 0.0, double t_end = -1.0);
  /// Piecewise linear through (times[k], values[k]); held constant outside the table.
  static TimeFunction table(std::vector<double> times, std::vector<double> values);

  double operator()(double t) const;
  /// Integral of f from 0 to t (used for prescribed displacements and analytic checks).
  double integral(double t) const;
  Kind kind() const { return kind_; }

 private:
  Kind kind_ = Kind::constant;
  double a_ = 0.0, b_ = 0.0, t0_ = 0.0, t1_ = -1.0;
  std::vector<double> times_, values_;
};

}  // namespace frictherm::mechanics
