// Friction laws in impulse form and frictional work (Nairn, Bardenhagen & Smith 2018, §2.6–2.10).
// Notation: N* = −d_n = N A_c dt (normal load impulse), s = S_slide A_c dt (sliding impulse),
// final sliding speed v = (d_t − s)/m_red (eq. 21). A law slides iff d_t > s(v = 0) and then s solves
// s = A_c dt S(N, A_c, (d_t − s)/m_red) (eq. 21 substituted in eq. 16).
#include <frictherm/mechanics/friction.hpp>

#include <boost/math/tools/toms748_solve.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace frictherm::mechanics {

struct FrictionLaw::Custom {
  std::string name;
  SlidingTraction S;           // user law
  std::vector<double> speeds;  // tabulated law (S empty): mu(v) through these points
  std::vector<double> mu;

  double mu_at(double v) const {  // piecewise linear, constant outside the table
    if (v <= speeds.front()) return mu.front();
    if (v >= speeds.back()) return mu.back();
    const auto hi = static_cast<std::size_t>(std::upper_bound(speeds.begin(), speeds.end(), v) - speeds.begin());
    const double w = (v - speeds[hi - 1]) / (speeds[hi] - speeds[hi - 1]);
    return mu[hi - 1] + w * (mu[hi] - mu[hi - 1]);
  }
};

namespace {

std::string num(double x) {
  std::ostringstream o;
  o << x;
  return o.str();
}

[[noreturn]] void bad(const std::string& law, const std::string& param, const std::string& expected, double got) {
  throw std::invalid_argument(law + ": " + param + " must be " + expected + ", got " + num(got));
}

void require_coefficient(const char* law, const char* param, double v) {
  if (!(std::isfinite(v) && v >= 0.0)) bad(law, param, "finite and >= 0", v);
}

// Root of g(s) = s − h(s) on [0, d_t], h(s) the sliding impulse at final speed (d_t − s)/m_red.
// Precondition g(d_t) > 0 (the pair slides). g(0) = −h(0) ≤ 0, so the root is bracketed.
template <class H>
double solve_sliding_impulse(const H& h, double d_t) {
  const double g0 = -h(0.0);
  if (g0 >= 0.0) return 0.0;  // the law gives S = 0 at the largest possible speed
  const double gdt = d_t - h(d_t);
  auto g = [&h](double s) { return s - h(s); };
  // Stop at a bracket of 1e-14 relative width (about 50 ulp), or 1e-16 d_t absolute for a root at ~0.
  auto tol = [d_t](double a, double b) {
    return std::abs(b - a) <= std::max(1e-14 * std::min(std::abs(a), std::abs(b)), 1e-16 * d_t);
  };
  std::uintmax_t iterations = 100;
  const auto r = boost::math::tools::toms748_solve(g, 0.0, d_t, g0, gdt, tol, iterations);
  // The midpoint of the final bracket (still valid after 100 iterations) is < d_t, so v' > 0.
  return 0.5 * (r.first + r.second);
}

}  // namespace

FrictionLaw FrictionLaw::stick() { return FrictionLaw(); }

FrictionLaw FrictionLaw::frictionless() {
  FrictionLaw f;
  f.kind_ = FrictionKind::frictionless;
  return f;
}

FrictionLaw FrictionLaw::coulomb(double mu) {
  require_coefficient("coulomb", "mu", mu);
  FrictionLaw f;
  f.kind_ = FrictionKind::coulomb;
  f.mu_ = mu;
  return f;
}

FrictionLaw FrictionLaw::linear_velocity(double mu0, double k) {
  require_coefficient("linear_velocity", "mu0", mu0);
  require_coefficient("linear_velocity", "k", k);  // k < 0 would let mu turn negative: use a user law
  FrictionLaw f;
  f.kind_ = FrictionKind::linear_velocity;
  f.mu_ = mu0;
  f.k_ = k;
  return f;
}

FrictionLaw FrictionLaw::adhesion(double mu, double shear_strength, double tensile_strength) {
  require_coefficient("adhesion", "mu", mu);
  if (!(std::isfinite(shear_strength) && shear_strength >= 0.0))
    bad("adhesion", "shear_strength", "finite and >= 0 (Pa)", shear_strength);
  if (!(tensile_strength > 0.0))
    bad("adhesion", "tensile_strength", "> 0 (Pa), or +inf for no tensile adhesion", tensile_strength);
  FrictionLaw f;
  f.kind_ = FrictionKind::adhesion;
  f.mu_ = mu;
  f.shear_strength_ = shear_strength;
  f.tensile_strength_ = tensile_strength;
  return f;
}

FrictionLaw FrictionLaw::static_dynamic(double mu_static, double mu_dynamic) {
  require_coefficient("static_dynamic", "mu_static", mu_static);
  require_coefficient("static_dynamic", "mu_dynamic", mu_dynamic);
  // With mu_d > mu_s the sliding impulse mu_d N* could exceed d_t and reverse the sliding.
  if (mu_dynamic > mu_static) bad("static_dynamic", "mu_dynamic", "<= mu_static = " + num(mu_static), mu_dynamic);
  FrictionLaw f;
  f.kind_ = FrictionKind::static_dynamic;
  f.mu_ = mu_static;
  f.mu_d_ = mu_dynamic;
  return f;
}

FrictionLaw FrictionLaw::smooth_static_dynamic(double mu_static, double mu_dynamic, double v_half) {
  require_coefficient("smooth_static_dynamic", "mu_static", mu_static);
  require_coefficient("smooth_static_dynamic", "mu_dynamic", mu_dynamic);
  if (!(std::isfinite(v_half) && v_half > 0.0)) bad("smooth_static_dynamic", "v_half", "finite and > 0 (m/s)", v_half);
  FrictionLaw f;
  f.kind_ = FrictionKind::smooth_static_dynamic;
  f.mu_ = mu_static;
  f.mu_d_ = mu_dynamic;
  f.v_half_ = v_half;
  return f;
}

FrictionLaw FrictionLaw::composite(double mu_static, double mu_dynamic, double v_half, double k, double shear_strength,
                                   double tensile_strength) {
  require_coefficient("composite", "mu_static", mu_static);
  require_coefficient("composite", "mu_dynamic", mu_dynamic);
  require_coefficient("composite", "k", k);
  require_coefficient("composite", "shear_strength", shear_strength);
  if (!(v_half > 0.0)) bad("composite", "v_half", "> 0 (+inf: no static to dynamic transition)", v_half);
  if (!(tensile_strength > 0.0)) bad("composite", "tensile_strength", "> 0 (+inf for none)", tensile_strength);
  FrictionLaw f;
  f.kind_ = FrictionKind::composite;
  f.mu_ = mu_static, f.mu_d_ = mu_dynamic, f.v_half_ = v_half, f.k_ = k;
  f.shear_strength_ = shear_strength, f.tensile_strength_ = tensile_strength;
  return f;
}

FrictionLaw FrictionLaw::user(SlidingTraction S, std::string name) {
  if (!S) throw std::invalid_argument("user friction law '" + name + "': S must be a callable, got an empty function");
  FrictionLaw f;
  f.kind_ = FrictionKind::user;
  f.custom_ = std::make_shared<const Custom>(Custom{std::move(name), std::move(S), {}, {}});
  return f;
}

FrictionLaw FrictionLaw::tabulated(std::vector<double> speeds, std::vector<double> mu) {
  if (speeds.empty()) throw std::invalid_argument("tabulated: speeds must have at least one point, got none");
  if (mu.size() != speeds.size())
    throw std::invalid_argument("tabulated: mu must have as many values as speeds (" + std::to_string(speeds.size()) +
                                "), got " + std::to_string(mu.size()));
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    const std::string at = "[" + std::to_string(i) + "]";
    if (!(std::isfinite(speeds[i]) && speeds[i] >= 0.0)) bad("tabulated", "speeds" + at, "finite and >= 0 (m/s)", speeds[i]);
    if (i > 0 && !(speeds[i] > speeds[i - 1]))
      bad("tabulated", "speeds" + at, "strictly increasing (> " + num(speeds[i - 1]) + ")", speeds[i]);
    if (!(std::isfinite(mu[i]) && mu[i] >= 0.0)) bad("tabulated", "mu" + at, "finite and >= 0", mu[i]);
  }
  FrictionLaw f;
  f.kind_ = FrictionKind::user;
  f.custom_ = std::make_shared<const Custom>(Custom{"tabulated", {}, std::move(speeds), std::move(mu)});
  return f;
}

FrictionOutcome FrictionLaw::in_contact(const ContactImpulse& c) const {
  const double d_t = c.tangential;
  const double m = c.reduced_mass;
  // Non-finite input: stick, which carries the NaN into the state where the step's blow-up check reports it.
  if (!(std::isfinite(c.normal) && std::isfinite(d_t))) return {};
  const double n_star = std::max(0.0, -c.normal);  // N* = −d_n = N A_c dt (eq. 15)
  auto slide_if_above = [d_t](double s) { return d_t <= s ? FrictionOutcome{} : FrictionOutcome{false, s}; };

  switch (kind_) {
    case FrictionKind::stick:
      return {};
    case FrictionKind::frictionless:
      return slide_if_above(0.0);
    case FrictionKind::coulomb:
      return slide_if_above(mu_ * n_star);  // S A_c dt = −mu d_n (eq. 20)
    case FrictionKind::static_dynamic:
      // Naive static/dynamic (§2.8): stick test with mu_s, then slide with mu_d.
      return d_t <= mu_ * n_star ? FrictionOutcome{} : FrictionOutcome{false, mu_d_ * n_star};
    case FrictionKind::adhesion: {
      const double a_dt = std::isfinite(c.area * c.dt) ? std::max(0.0, c.area * c.dt) : 0.0;
      return slide_if_above(shear_strength_ * a_dt + mu_ * n_star);  // S A_c dt = S_a A_c dt − mu d_n (eq. 24)
    }
    case FrictionKind::linear_velocity: {
      if (d_t <= mu_ * n_star) return {};  // the law at v' = 0
      if (!(m > 0.0 && std::isfinite(m))) return {};
      // Eq. 22 in impulse form: s = N* (mu0 + k (d_t − s)/m)  ⇒  s = N* (m mu0 + k d_t)/(m + k N*)
      //   = −d_n (m mu0 + k d_t)/(m − k d_n).
      // The paper's printed eq. 23 has m_red + k d_n in the denominator: a sign slip, since d_n = −N A_c dt.
      // Then d_t − s = m (d_t − mu0 N*)/(m + k N*) > 0 while sliding.
      return {false, n_star * ((m * mu_ + k_ * d_t) / (m + k_ * n_star))};  // ratio first: no underflow at tiny m
    }
    case FrictionKind::smooth_static_dynamic: {
      if (d_t <= mu_ * n_star) return {};  // static friction holds (stick test with mu_s, §3)
      if (!(m > 0.0 && std::isfinite(m))) return {};
      // Eq. 42 with v = (d_t − s)/m: s (k* + d_t − s) = N* (mu_s k* + mu_d (d_t − s)), k* = v½ m, i.e.
      //   s² − (D* + mu_d N*) s + N* (mu_s k* + mu_d d_t) = 0,  D* = d_t + k*,
      // whose roots divided by N* are eq. 43. At s = d_t the quadratic equals k*(mu_s N* − d_t) < 0 while
      // sliding, so d_t lies between the roots: the + root gives v < 0, and the − root (eq. 43) is in (0, d_t).
      // − root as C/(B/2 + √disc) to avoid cancellation (large v½), √disc = |h|√(1 − r) to avoid overflow,
      // disc clamped at 0 against roundoff near a double root (k* = (mu_s − mu_d) N* at the stick boundary):
      const double k_star = v_half_ * m;
      const double h = 0.5 * (d_t + k_star - mu_d_ * n_star);  // (D* − mu_d N*)/2
      const double r = (h == 0.0) ? 0.0 : ((mu_ - mu_d_) * n_star / h) * (k_star / h);
      const double root_disc = (h == 0.0) ? std::sqrt(std::max(0.0, (mu_d_ - mu_) * k_star * n_star))
                                             : std::abs(h) * std::sqrt(std::max(0.0, 1.0 - r));
      const double half_b = h + mu_d_ * n_star;  // (D* + mu_d N*)/2 > 0
      return {false, n_star * ((mu_ * k_star + mu_d_ * d_t) / (half_b + root_disc))};
    }
    case FrictionKind::composite: {
      // Eq 21 with S = N (μ(v) + k v) + S_a, μ(v) = (μ_s v½ + μ_d v)/(v½ + v) (eq 42), in impulse form:
      // h(v) = N* (μ(v) + k v) + S_a A_c dt; stick while d_t ≤ h(0) = μ_s N* + S_a A_c dt.
      const double a_dt = std::isfinite(c.area * c.dt) ? std::max(0.0, c.area * c.dt) : 0.0;
      const double adhesion = shear_strength_ * a_dt;
      if (d_t <= mu_ * n_star + adhesion) return {};
      if (!(m > 0.0 && std::isfinite(m))) return {};
      auto h = [&](double v) {
        const double mu = std::isinf(v_half_) ? mu_ : (mu_ * v_half_ + mu_d_ * v) / (v_half_ + v);
        return n_star * (mu + k_ * v) + adhesion;
      };
      return {false, solve_sliding_impulse([&](double s) { return h((d_t - s) / m); }, d_t)};
    }
    case FrictionKind::user: {
      const Custom& u = *custom_;
      if (!u.S) {  // tabulated: s = mu(v) N*, independent of A_c
        if (d_t <= u.mu_at(0.0) * n_star) return {};
        if (!(m > 0.0 && std::isfinite(m))) return {};
        return {false, solve_sliding_impulse([&](double s) { return n_star * u.mu_at((d_t - s) / m); }, d_t)};
      }
      const double a_dt = c.area * c.dt;
      if (!(c.area > 0.0 && c.dt > 0.0 && std::isfinite(a_dt) && a_dt > 0.0))
        throw std::domain_error("friction law '" + u.name + "' needs contact area > 0 and dt > 0, got A_c = " +
                                num(c.area) + " m^2, dt = " + num(c.dt) + " s");
      const double N = n_star / a_dt;
      auto h = [&](double speed) {  // A_c dt S(N, A_c, speed), checked
        const double S = u.S(N, c.area, speed);
        if (!(std::isfinite(S) && S >= 0.0))
          throw std::domain_error("friction law '" + u.name + "' returned S = " + num(S) + " for N = " + num(N) +
                                  " Pa, A_c = " + num(c.area) + " m^2, sliding speed = " + num(speed) +
                                  " m/s (expected finite and >= 0)");
        return a_dt * S;
      };
      if (d_t <= h(0.0)) return {};
      if (!(m > 0.0 && std::isfinite(m))) return {};
      return {false, solve_sliding_impulse([&](double s) { return h((d_t - s) / m); }, d_t)};
    }
  }
  return {};
}

bool FrictionLaw::holds_when_separated(double sliding_traction, double normal_traction) const {
  if ((kind_ != FrictionKind::adhesion && kind_ != FrictionKind::composite) || !std::isfinite(tensile_strength_))
    return false;
  if (!(std::isfinite(sliding_traction) && std::isfinite(normal_traction))) return false;
  // Eq. 25: the bond breaks when (S_stick/S_a)² + (N/N_a)² > 1; with S_a = 0 any shear breaks it.
  double shear_term = 0.0;
  if (sliding_traction != 0.0) {
    if (shear_strength_ == 0.0) return false;
    shear_term = (sliding_traction / shear_strength_) * (sliding_traction / shear_strength_);
  }
  const double normal_term = (normal_traction / tensile_strength_) * (normal_traction / tensile_strength_);
  return shear_term + normal_term <= 1.0;
}

bool FrictionLaw::needs_area() const {
  return kind_ == FrictionKind::adhesion || (kind_ == FrictionKind::composite && shear_strength_ > 0.0) ||
         (kind_ == FrictionKind::user && custom_->S);
}

std::string FrictionLaw::describe() const {
  switch (kind_) {
    case FrictionKind::stick: return "stick";
    case FrictionKind::frictionless: return "frictionless";
    case FrictionKind::coulomb: return "coulomb(mu=" + num(mu_) + ")";
    case FrictionKind::linear_velocity: return "linear_velocity(mu0=" + num(mu_) + ", k=" + num(k_) + " s/m)";
    case FrictionKind::adhesion:
      return "adhesion(mu=" + num(mu_) + ", shear_strength=" + num(shear_strength_) + " Pa" +
             (std::isfinite(tensile_strength_) ? ", tensile_strength=" + num(tensile_strength_) + " Pa)" : ")");
    case FrictionKind::static_dynamic: return "static_dynamic(mu_static=" + num(mu_) + ", mu_dynamic=" + num(mu_d_) + ")";
    case FrictionKind::smooth_static_dynamic:
      return "smooth_static_dynamic(mu_static=" + num(mu_) + ", mu_dynamic=" + num(mu_d_) + ", v_half=" + num(v_half_) + " m/s)";
    case FrictionKind::composite:
      return "composite(mu_static=" + num(mu_) + ", mu_dynamic=" + num(mu_d_) + ", v_half=" + num(v_half_) +
             " m/s, k=" + num(k_) + " s/m, shear_strength=" + num(shear_strength_) +
             " Pa, tensile_strength=" + num(tensile_strength_) + " Pa)";
    case FrictionKind::user: {
      if (custom_->S) return "user(" + custom_->name + ")";
      std::string s = "tabulated(speeds=[", m = "], mu=[";
      for (std::size_t i = 0; i < custom_->speeds.size(); ++i) {
        s += (i ? ", " : "") + num(custom_->speeds[i]);
        m += (i ? ", " : "") + num(custom_->mu[i]);
      }
      return s + "] m/s" + m.substr(1) + "])";  // "tabulated(speeds=[...] m/s, mu=[...])"
    }
  }
  return "?";
}

FrictionKind friction_kind_from_string(const std::string& name) {
  static const std::pair<const char*, FrictionKind> names[] = {
      {"stick", FrictionKind::stick},
      {"frictionless", FrictionKind::frictionless},
      {"coulomb", FrictionKind::coulomb},
      {"linear_velocity", FrictionKind::linear_velocity},
      {"adhesion", FrictionKind::adhesion},
      {"static_dynamic", FrictionKind::static_dynamic},
      {"smooth_static_dynamic", FrictionKind::smooth_static_dynamic},
      {"composite", FrictionKind::composite}, {"tabulated", FrictionKind::user}};
  std::string valid;
  for (const auto& [n, k] : names) {
    if (name == n) return k;
    valid += std::string(valid.empty() ? "" : ", ") + n;
  }
  throw std::invalid_argument("unknown friction law '" + name + "' (expected one of " + valid + ")");
}

const char* to_string(FrictionKind kind) {
  switch (kind) {
    case FrictionKind::stick: return "stick";
    case FrictionKind::frictionless: return "frictionless";
    case FrictionKind::coulomb: return "coulomb";
    case FrictionKind::linear_velocity: return "linear_velocity";
    case FrictionKind::adhesion: return "adhesion";
    case FrictionKind::static_dynamic: return "static_dynamic";
    case FrictionKind::smooth_static_dynamic: return "smooth_static_dynamic";
    case FrictionKind::composite: return "composite";
    case FrictionKind::user: return "user";
  }
  return "?";
}

namespace {
bool work_inputs_ok(double s, double d_t, double m) {
  return std::isfinite(s) && std::isfinite(d_t) && std::isfinite(m) && s > 0.0 && m > 0.0;
}
double finite_or_zero(double w) { return std::isfinite(w) && w > 0.0 ? w : 0.0; }
}  // namespace

double frictional_work_first_order(double slide_impulse, double tangential, double reduced_mass) {
  if (!work_inputs_ok(slide_impulse, tangential, reduced_mass)) return 0.0;
  // Nairn 2018 eq. 27: force s/dt times final sliding speed (d_t − s)/m_red times dt.
  return finite_or_zero(slide_impulse * ((tangential - slide_impulse) / reduced_mass));
}

double frictional_work_second_order(double slide_impulse, double tangential, double tangential_force,
                                    double reduced_mass, double dt) {
  if (!work_inputs_ok(slide_impulse, tangential, reduced_mass) || !std::isfinite(tangential_force) ||
      !(std::isfinite(dt) && dt > 0.0))
    return 0.0;
  const double s = slide_impulse;
  const double w1 = s * ((tangential - s) / reduced_mass);                  // Nairn 2018 eq. 27
  const double w2 = s * ((tangential_force * dt - s) / reduced_mass);       // Nairn 2018 eq. 33
  // W1 − W2 = s (d_t − f_t dt)/m_red = s |Δv'(0)| (eq. 32): positive means sliding all step.
  if (w2 < w1) return finite_or_zero(w1 - 0.5 * w2);                        // Nairn 2018 eq. 34
  return finite_or_zero(w1 * (w1 / (2.0 * w2)));                            // Nairn 2018 eqs. 35-36 (W2 > W1 ≥ 0)
}

}  // namespace frictherm::mechanics
