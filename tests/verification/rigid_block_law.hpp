#pragma once
// The rigid sliding block of Nairn, Bardenhagen & Smith (2018), appendix, under any sliding law: the
// block's momentum balance (eq. 48), ρ h dv/dt = R N (t − t2)/ts − S(v), with the law's own sliding
// traction S(v) (Pa, v ≥ 0) in place of the closed forms' (μd + k v) N + S_a. The closed forms
// (rigid_block.hpp, eqs. 50–54) cover a sharp static → dynamic step; a law whose coefficient moves
// with the speed over a range comparable to the block's (the smooth law of eq. 42 with v½ = 1 m/s, a
// composite law) has no closed form, and comparing it with the sharp one measures the law's
// difference, not the method's error. Sliding starts where the ramp reaches S(0) (eq. 47 with
// S(0) = μs N + S_a); from there v and the friction work Q = l b ∫ S(v) v dt are integrated with
// Boost.Odeint's Dormand–Prince 5(4) at 1e-12 tolerances and read off a table at 20 000 intervals
// (linear interpolation: at most 1e-9 of the final speed here).
#include "rigid_block.hpp"

#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <cstddef>
#include <functional>
#include <vector>

namespace frictherm::verification {

class RigidBlockUnderLaw {
 public:
  /// `setup` gives the block, its loads and the ramp (its friction coefficients are not used);
  /// `traction(v)` the law's sliding traction per unit area at the sliding speed v ≥ 0; the table
  /// covers [onset, t_end].
  RigidBlockUnderLaw(const RigidBlock& setup, std::function<double(double)> traction, double t_end,
                     int intervals = 20000)
      : r_(setup), S_(std::move(traction)) {
    onset_ = r_.t2 + S_(0.0) * r_.ts / (r_.R * r_.N);  // eq. 47: the ramp R N (t − t2)/ts reaches S(0)
    const double span = std::max(t_end - onset_, 0.0);
    dt_ = span / intervals;
    v_.assign(static_cast<std::size_t>(intervals) + 1, 0.0);
    q_.assign(v_.size(), 0.0);
    if (!(span > 0.0)) return;
    namespace ode = boost::numeric::odeint;
    using State = std::vector<double>;
    const double m = r_.rho * r_.h;  // mass per unit area
    auto rhs = [&](const State& x, State& dxdt, double t) {
      const double v = std::max(x[0], 0.0);  // the ramp only grows: the block never reverses
      const double S = S_(v);
      dxdt[0] = (r_.R * r_.N * (t - r_.t2) / r_.ts - S) / m;  // eq. 48
      dxdt[1] = S * v;                                        // friction power per unit area
    };
    std::vector<double> times(v_.size());
    for (std::size_t i = 0; i < times.size(); ++i) times[i] = onset_ + dt_ * static_cast<double>(i);
    State x{0.0, 0.0};
    std::size_t k = 0;
    ode::integrate_times(ode::make_dense_output(1e-12, 1e-12, ode::runge_kutta_dopri5<State>()), rhs, x,
                         times.begin(), times.end(), dt_, [&](const State& s, double) {
                           v_[k] = s[0];
                           q_[k] = s[1] * r_.l * r_.b;
                           ++k;
                         });
  }

  double onset() const { return onset_; }
  double velocity(double t) const { return lookup(v_, t); }
  /// Total friction work Q (J) up to t.
  double friction_work(double t) const { return lookup(q_, t); }

 private:
  double lookup(const std::vector<double>& y, double t) const {
    if (t <= onset_ || !(dt_ > 0.0)) return 0.0;
    const double s = (t - onset_) / dt_;
    const std::size_t i = std::min(static_cast<std::size_t>(s), y.size() - 2);
    const double w = std::min(s - static_cast<double>(i), 1.0);
    return (1.0 - w) * y[i] + w * y[i + 1];
  }

  RigidBlock r_;
  std::function<double(double)> S_;
  double onset_ = 0.0, dt_ = 0.0;
  std::vector<double> v_, q_;
};

/// The sliding traction of the smooth static → dynamic law (eq. 42) with a velocity term and
/// adhesion (the composite law of eq. 21): S(v) = N (μ(v) + k v) + S_a, μ(v) = (μs v½ + μd v)/(v½ + v).
/// Written here from the paper, independently of the library's FrictionLaw.
inline std::function<double(double)> smooth_law_traction(double N, double mu_s, double mu_d, double v_half,
                                                         double k = 0.0, double S_a = 0.0) {
  return [=](double v) { return N * ((mu_s * v_half + mu_d * v) / (v_half + v) + k * v) + S_a; };
}

}  // namespace frictherm::verification
