#include "forward_euler.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace frictherm::thermal::detail {

ForwardEuler::ForwardEuler(const IntegratorOptions& options) : Scheme("forward_euler"), opt_(options) {}

void ForwardEuler::advance(ThermalOde& ode, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0, double t1) {
  const auto start = std::chrono::steady_clock::now();
  const double window = t1 - t0;
  const std::string who = ode.who(name_);
  if (ode.revision() != cached_revision_) {  // the global limit: equal sub-steps on every process
    cached_dt_limit_ = ode.dt_limit(opt_.fe_limit_estimate);
    cached_revision_ = ode.revision();
  }
  const double dt_limit = cached_dt_limit_;
  const double h_stable = opt_.fe_safety * dt_limit;
  if (ode.reaction() != nullptr) {
    advance_reacting(ode, T, progress, t0, t1, dt_limit);
    stats_.wall_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return;
  }

  // Steps requested by the caller: one per window unless fe_max_dt caps the step; counted as doubles
  // first, so that a window of 1e20 stable steps is refused by max_steps rather than cast.
  double steps = 1.0;
  if (opt_.fe_max_dt > 0.0) steps = std::max(1.0, std::ceil(window / opt_.fe_max_dt - 1e-12));
  if (opt_.fe_stability_policy == "substep" && window / steps > h_stable) steps = std::ceil(window / h_stable);
  if (!(steps <= static_cast<double>(opt_.max_steps))) {
    std::ostringstream os;
    os << who << ": the window [" << t0 << ", " << t1 << "] s needs " << steps
       << " sub-steps (stability limit " << h_stable << " s with fe_safety " << opt_.fe_safety
       << (opt_.fe_max_dt > 0.0 ? ", or fe_max_dt" : "") << "), more than max_steps = " << opt_.max_steps
       << ". Use an implicit integrator such as cvode_bdf (or \"auto\"), shorter windows, or a larger max_steps";
    throw StabilityError(os.str(), window / steps, dt_limit);
  }
  const long n = static_cast<long>(steps);
  if (opt_.fe_stability_policy == "refuse") {
    const double h = window / static_cast<double>(n);
    if (h > h_stable) {
      std::ostringstream os;
      os << who << ": step " << h << " s exceeds the stability limit fe_safety*dt_limit = "
         << opt_.fe_safety << "*" << dt_limit << " s = " << h_stable
         << " s (dt_limit = 2/lambda_max, " << opt_.fe_limit_estimate
         << " estimate); refusing (fe_stability_policy \"refuse\"). Use \"substep\", a smaller "
            "fe_max_dt or window, or an implicit integrator such as cvode_bdf";
      throw StabilityError(os.str(), h, dt_limit);
    }
  }
  const double h = window / static_cast<double>(n);

  // T_{k+1} = T_k + h M⁻¹(−K_eff T_k + q(t_k + h/2) + …): the source is sampled at the
  // sub-step midpoint, which integrates a linear-in-time q exactly, so Σ M_i T_i gains exactly
  // ∫ Σ q dt (thermal-notes §4 invariant) — the conduction term stays explicit.
  Eigen::VectorXd work = T;
  Eigen::VectorXd dTdt(T.size());
  for (long k = 0; k < n; ++k) {
    const double tm = t0 + (static_cast<double>(k) + 0.5) * h;
    ode.rhs(tm, work, dTdt);
    work.noalias() += h * dTdt;
  }
  stats_.steps += n;
  stats_.rhs_evals += n;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats_.wall_seconds += elapsed;
  if (!ode.all_ranks(work.allFinite())) {
    std::ostringstream os;
    os << who << ": temperatures became non-finite with step " << h
       << " s against the stability limit " << dt_limit << " s (policy \"" << opt_.fe_stability_policy
       << "\")";
    throw StabilityError(os.str(), h, dt_limit);
  }
  T = std::move(work);
}

void ForwardEuler::advance_reacting(ThermalOde& ode, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0,
                                    double t1, double dt_limit) {
  // Explicit Euler for conduction and sources; the reaction is advanced over each sub-step
  // at the sub-step's start temperature with its exact solution for frozen T,
  //   λ⁺ = 1 − (1 − λ) e^{−h k(T)},   released heat Q (λ⁺ − λ)
  // (zero-order: Q h k(T)), so λ stays in [0, 1] and Σ M T − Σ Q λ changes only by the
  // transport heat. The remaining explicit constraint is the self-heating rate
  // a_i = Q_i (1 − λ_i) k'(T_i)/M_i, which with conduction gives sub-steps
  // h ≤ fe_safety·2/(λ_cond + max_i a_i) (the growing mode resolved to a factor e² per step).
  const Reaction& rx = *ode.reaction();
  const bool consume = ode.reaction_consumes();
  const Index n = ode.size();
  const Eigen::VectorXd& m = ode.mass();
  const std::string who = ode.who(name_);
  std::vector<Index> nodes;
  for (Index i = 0; i < n; ++i) {
    if (rx.heat[i] > 0.0 && !ode.is_dirichlet(i)) nodes.push_back(i);
  }
  const double lam_cond = std::isfinite(dt_limit) ? 2.0 / dt_limit : 0.0;
  Eigen::VectorXd work = T;
  Eigen::VectorXd lam = progress != nullptr ? *progress : Eigen::VectorXd::Zero(n);
  Eigen::VectorXd w(n), rate(static_cast<Index>(nodes.size()));
  double t = t0;
  long steps = 0;
  double h = 0.0, h_lim = 0.0;
  bool last = false;
  while (!last) {
    double smax = 0.0;
    for (std::size_t r = 0; r < nodes.size(); ++r) {
      const Index i = nodes[r];
      rate[static_cast<Index>(r)] = rx.rate_constant(work[i]);
      const double a = rx.heat[i] * (1.0 - lam[i]) * rx.rate_constant_derivative(work[i]) / m[i];
      smax = std::max(smax, a);
    }
    const double bound = lam_cond + ode.max_all(smax);  // the same sub-step on every process
    h_lim = bound > 0.0 ? opt_.fe_safety * 2.0 / bound : std::numeric_limits<double>::infinity();
    h = t1 - t;
    if (opt_.fe_max_dt > 0.0) h = std::min(h, opt_.fe_max_dt);
    if (opt_.fe_stability_policy == "substep") {
      h = std::min(h, h_lim);
    } else if (opt_.fe_stability_policy == "refuse" && h > h_lim) {
      std::ostringstream os;
      os << who << ": step " << h << " s exceeds the conduction + reaction stability limit "
         << h_lim << " s at t = " << t << " s; refusing (fe_stability_policy \"refuse\"). Use "
         << "\"substep\" or an implicit integrator such as cvode_bdf";
      throw StabilityError(os.str(), h, h_lim / opt_.fe_safety);
    }
    last = h >= t1 - t;
    if (last) h = t1 - t;
    ode.transport_heat_rate(t + 0.5 * h, work, w);  // source at the sub-step midpoint
    w *= h;                                                // transport heat [J]
    for (std::size_t r = 0; r < nodes.size(); ++r) {
      const Index i = nodes[r];
      const double k = rate[static_cast<Index>(r)];
      const double burnt = consume ? (1.0 - lam[i]) * -std::expm1(-h * k) : h * k;  // Δλ
      w[i] += rx.heat[i] * burnt;
      if (consume) lam[i] += burnt;
    }
    work.array() += w.array() / m.array();
    t = last ? t1 : t + h;
    ++steps;
    if (!last && steps >= opt_.max_steps) {
      stats_.steps += steps;
      stats_.rhs_evals += steps;
      std::ostringstream os;
      os << who << ": max_steps = " << opt_.max_steps << " sub-steps reached at t = " << t
         << " s in the window [" << t0 << ", " << t1 << "] s: the reaction limits the step to " << h_lim
         << " s. Raise IntegratorOptions::max_steps or use an implicit integrator such as cvode_bdf";
      throw StabilityError(os.str(), h, h_lim / opt_.fe_safety);
    }
  }
  stats_.steps += steps;
  stats_.rhs_evals += steps;
  if (!ode.all_ranks(work.allFinite() && lam.allFinite())) {
    std::ostringstream os;
    os << who << ": temperatures became non-finite (last step " << h << " s, limit " << h_lim
       << " s, policy \"" << opt_.fe_stability_policy << "\")";
    throw StabilityError(os.str(), h, h_lim);
  }
  T = std::move(work);
  if (progress != nullptr && consume) {
    for (Index i : nodes) (*progress)[i] = std::min(lam[i], 1.0);  // ≤ 1 up to round-off
  }
}

}  // namespace frictherm::thermal::detail
