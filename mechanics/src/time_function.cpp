#include <frictherm/mechanics/time_function.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace frictherm::mechanics {

TimeFunction TimeFunction::constant(double value) {
  TimeFunction f;
  f.kind_ = Kind::constant;
  f.a_ = value;
  return f;
}

TimeFunction TimeFunction::ramp(double value, double duration, double t_start) {
  if (!(duration >= 0.0)) throw std::invalid_argument("ramp duration must be >= 0");
  TimeFunction f;
  f.kind_ = Kind::ramp;
  f.a_ = value;
  f.b_ = duration;
  f.t0_ = t_start;
  return f;
}

TimeFunction TimeFunction::sinusoid(double amplitude, double omega, double t_start, double t_end) {
  TimeFunction f;
  f.kind_ = Kind::sinusoid;
  f.a_ = amplitude;
  f.b_ = omega;
  f.t0_ = t_start;
  f.t1_ = t_end;
  return f;
}

TimeFunction TimeFunction::table(std::vector<double> times, std::vector<double> values) {
  if (times.empty() || times.size() != values.size())
    throw std::invalid_argument("time table needs equally many (>= 1) times and values");
  if (!std::is_sorted(times.begin(), times.end()))
    throw std::invalid_argument("time table times must be increasing");
  TimeFunction f;
  f.kind_ = Kind::table;
  f.times_ = std::move(times);
  f.values_ = std::move(values);
  return f;
}

double TimeFunction::operator()(double t) const {
  switch (kind_) {
    case Kind::constant: return a_;
    case Kind::ramp:
      if (t <= t0_) return 0.0;
      if (b_ <= 0.0 || t >= t0_ + b_) return a_;
      return a_ * (t - t0_) / b_;
    case Kind::sinusoid:
      if (t < t0_ || (t1_ >= 0.0 && t > t1_)) return 0.0;
      return a_ * std::sin(b_ * (t - t0_));
    case Kind::table: {
      if (t <= times_.front()) return values_.front();
      if (t >= times_.back()) return values_.back();
      const auto it = std::upper_bound(times_.begin(), times_.end(), t);
      const std::size_t k = static_cast<std::size_t>(it - times_.begin());
      const double s = (t - times_[k - 1]) / (times_[k] - times_[k - 1]);
      return values_[k - 1] + s * (values_[k] - values_[k - 1]);
    }
  }
  return 0.0;
}

double TimeFunction::integral(double t) const {
  switch (kind_) {
    case Kind::constant: return a_ * t;
    case Kind::ramp: {
      if (t <= t0_) return 0.0;
      if (b_ <= 0.0) return a_ * (t - t0_);
      if (t <= t0_ + b_) return 0.5 * a_ * (t - t0_) * (t - t0_) / b_;
      return 0.5 * a_ * b_ + a_ * (t - t0_ - b_);
    }
    case Kind::sinusoid: {
      if (t <= t0_) return 0.0;
      const double te = (t1_ >= 0.0) ? std::min(t, t1_) : t;
      if (b_ == 0.0) return 0.0;
      return a_ * (1.0 - std::cos(b_ * (te - t0_))) / b_;
    }
    case Kind::table: {
      // Trapezoids over the table, constant extension at both ends (integral from 0).
      auto value_at = [this](double s) { return (*this)(s); };
      std::vector<double> pts{0.0};
      for (double tk : times_)
        if (tk > 0.0 && tk < t) pts.push_back(tk);
      pts.push_back(t);
      double sum = 0.0;
      for (std::size_t k = 1; k < pts.size(); ++k)
        sum += 0.5 * (value_at(pts[k - 1]) + value_at(pts[k])) * (pts[k] - pts[k - 1]);
      return sum;
    }
  }
  return 0.0;
}

}  // namespace frictherm::mechanics
