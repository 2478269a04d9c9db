// The Arrhenius reaction's terms of the conduction ODE (ode_system.hpp: f_T,i += c_i Q_i (1 − λ_r) k(T_i),
// f_λ,r = (1 − λ_r) k(T_i), and the 2×2 Jacobian block of each reacting node), written once for the
// serial OdeSystem (ode_system.cpp) and the distributed DistributedOde (distributed/distributed_ode.cpp).
// Each passes its own reacting nodes: node[r] the unknown of reacting node r, q[r] its Q, frozen[r]
// its λ when the reaction does not consume (zero-order window), d_tt … d_ll the block entries.
// Internal header.
#pragma once

#include "frictherm/thermal/reaction.hpp"
#include "frictherm/thermal/problem.hpp"

#include <Eigen/Dense>

#include <cstddef>
#include <vector>

namespace frictherm::thermal::detail {

struct ReactionNodes {
  const std::vector<Index>& node;
  const Eigen::VectorXd& q;
  const Eigen::VectorXd& frozen;
  bool consume;
  Index size() const { return static_cast<Index>(node.size()); }
  double progress(const double* lambda, Index r) const { return consume ? lambda[r] : frozen[r]; }
};

struct ReactionBlocks {  // written by evaluate_reaction_blocks
  Eigen::VectorXd& tt;
  Eigen::VectorXd& tl;
  Eigen::VectorXd& lt;
  Eigen::VectorXd& ll;
};
struct ReactionBlocksView {  // read by add_reaction_jv and invert_reaction_blocks
  const Eigen::VectorXd& tt;
  const Eigen::VectorXd& tl;
  const Eigen::VectorXd& lt;
  const Eigen::VectorXd& ll;
};

/// w_i += Q_r (1 − λ_r) k(T_i) at each reacting node (the nodal heat rate, before fscale) and, when
/// consuming, rate[r] = (1 − λ_r) k(T_i). temp: T at every node; lambda: the state's λ entries.
inline void add_reaction_rates(const Reaction& rx, const ReactionNodes& nodes, const double* temp,
                               const double* lambda, double* w, double* rate) {
  for (Index r = 0; r < nodes.size(); ++r) {
    const Index i = nodes.node[static_cast<std::size_t>(r)];
    const double remaining = 1.0 - nodes.progress(lambda, r);
    const double k = remaining * rx.rate_constant(temp[i]);  // (1 − λ) k(T)
    w[i] += nodes.q[r] * k;
    if (nodes.consume) rate[r] = k;
  }
}

/// ∂f_T/∂y, ∂f_T/∂λ, ∂f_λ/∂y, ∂f_λ/∂λ at the reacting nodes for the state y (T = y/s; λ = y[n + r]).
inline void evaluate_reaction_blocks(const Reaction& rx, const ReactionNodes& nodes, const double* y, Index n,
                                     const Eigen::VectorXd& s, const Eigen::VectorXd& fscale, ReactionBlocks d) {
  for (Index r = 0; r < nodes.size(); ++r) {
    const Index i = nodes.node[static_cast<std::size_t>(r)];
    const double temp = y[i] / s[i];
    const double lam = nodes.progress(y + n, r);
    const double k = rx.rate_constant(temp);
    const double dk = rx.rate_constant_derivative(temp);
    const double c = fscale[i] * nodes.q[r];
    d.tt[r] = c * (1.0 - lam) * dk / s[i];
    d.tl[r] = -c * k;
    d.lt[r] = (1.0 - lam) * dk / s[i];
    d.ll[r] = -k;
  }
}

/// out += the reaction's part of J·in (out already holds the conduction's part).
inline void add_reaction_jv(const ReactionNodes& nodes, const ReactionBlocksView& d, const double* in, double* out,
                            Index n) {
  for (Index r = 0; r < nodes.size(); ++r) {
    const Index i = nodes.node[static_cast<std::size_t>(r)];
    out[i] += d.tt[r] * in[i];
    if (!nodes.consume) continue;
    out[i] += d.tl[r] * in[n + r];
    out[n + r] = d.lt[r] * in[i] + d.ll[r] * in[n + r];
  }
}

/// z = the exact inverse of each reacting node's 2×2 block of I − γJ (1×1 when zero-order) applied
/// to r, on top of the Jacobi z = r / (1 − γ jdiag) the caller set elsewhere. Returns 1 for a
/// non-positive pivot (the step too long for the self-heating: a recoverable failure), else 0.
inline int invert_reaction_blocks(const ReactionNodes& nodes, const ReactionBlocksView& d, const double* jdiag,
                                  double gamma, const double* r, double* z, Index n) {
  for (Index q = 0; q < nodes.size(); ++q) {
    const Index i = nodes.node[static_cast<std::size_t>(q)];
    const double a11 = 1.0 - gamma * (jdiag[i] + d.tt[q]);
    if (!nodes.consume) {
      if (!(a11 > 0.0)) return 1;
      z[i] = r[i] / a11;
      continue;
    }
    const double a12 = -gamma * d.tl[q];
    const double a21 = -gamma * d.lt[q];
    const double a22 = 1.0 - gamma * d.ll[q];
    const double det = a11 * a22 - a12 * a21;
    if (!(det > 0.0) || !(a22 > 0.0)) return 1;
    z[i] = (a22 * r[i] - a12 * r[n + q]) / det;
    z[n + q] = (a11 * r[n + q] - a21 * r[i]) / det;
  }
  return 0;
}

}  // namespace frictherm::thermal::detail
