// What the two ODE forms (ode_system.hpp: serial OdeSystem; distributed/distributed_ode.hpp:
// DistributedOde) share: the state y = [s ⊙ T; λ_r of the reacting nodes when consuming], its
// tolerances, and the RHS f = [fscale ⊙ (w + reaction heat); (1 − λ_r) k(T_i)] around a heat rate w
// that each computes its own way (thermal-notes §1). Internal header.
#pragma once

#include "reaction_blocks.hpp"

#include <sundials/sundials_nvector.h>

#include <algorithm>
#include <vector>

namespace frictherm::thermal::detail {

class OdeForm {
 public:
  Index nodes() const { return s_.size(); }
  Index reacting() const { return static_cast<Index>(rx_node_.size()); }
  Index state_size() const { return nodes() + (consume_ ? reacting() : 0); }

  // Window state. progress may be null (λ = 0). For a zero-order reaction λ is copied as the
  // window's fixed parameter; for a consuming one it enters y.
  void to_y(const Eigen::VectorXd& T, const Eigen::VectorXd* progress, N_Vector y) {
    double* yv = N_VGetArrayPointer(y);
    const Index n = nodes();
    Eigen::Map<Eigen::VectorXd>(yv, n) = s_.cwiseProduct(T);
    for (Index r = 0; r < reacting(); ++r) {
      const double lam = progress != nullptr ? (*progress)[rx_node_[static_cast<std::size_t>(r)]] : 0.0;
      if (consume_) yv[n + r] = lam;
      else frozen_[r] = lam;
    }
  }
  // T from y; progress (if given and consuming) updated on reacting nodes, clamped to [0, 1].
  void to_T(N_Vector y, Eigen::VectorXd& T, Eigen::VectorXd* progress) const {
    const double* yv = N_VGetArrayPointer(y);
    const Index n = nodes();
    T = Eigen::Map<const Eigen::VectorXd>(yv, n).cwiseQuotient(s_);
    if (progress == nullptr || !consume_) return;
    for (Index r = 0; r < reacting(); ++r) (*progress)[rx_node_[static_cast<std::size_t>(r)]] = std::clamp(yv[n + r], 0.0, 1.0);
  }
  // s_i·atol on T (√M_i·atol on the symmetric form), progress_atol on λ.
  void fill_abstol(double atol, double progress_atol, N_Vector out) const {
    Eigen::Map<Eigen::VectorXd> v(N_VGetArrayPointer(out), state_size());
    v.head(nodes()) = atol * s_;
    v.tail(state_size() - nodes()).setConstant(progress_atol);
  }

 protected:
  // The form: y = s ⊙ T with s = 1 (plain) or M^{1/2} (symmetric), f = fscale ⊙ w with fscale = s/M,
  // i.e. 1/M or M^{-1/2} (Dirichlet rows are then zeroed by the caller).
  void scale(const Eigen::VectorXd& mass, bool symmetric) {
    symmetric_ = symmetric;
    s_ = symmetric ? Eigen::VectorXd(mass.cwiseSqrt()) : Eigen::VectorXd::Ones(mass.size());
    fscale_ = s_.cwiseQuotient(mass);
  }
  // The temperatures of y into t_work_ (the heat rate then goes into w_work_).
  const Eigen::VectorXd& temperatures(const double* y) const {
    t_work_ = Eigen::Map<const Eigen::VectorXd>(y, nodes()).cwiseQuotient(s_);
    return t_work_;
  }
  // f from w_work_: the reaction heat and rates, then the scaling.
  void finish_rhs(const Reaction& rx, const double* y, double* ydot) const {
    const Index n = nodes();
    add_reaction_rates(rx, reaction_nodes(), t_work_.data(), y + n, w_work_.data(), ydot + n);
    Eigen::Map<Eigen::VectorXd>(ydot, n) = fscale_.cwiseProduct(w_work_);
  }
  ReactionNodes reaction_nodes() const { return {rx_node_, rx_q_, frozen_, consume_}; }
  ReactionBlocksView reaction_blocks_view() const { return {d_tt_, d_tl_, d_lt_, d_ll_}; }

  bool symmetric_ = false, consume_ = false;
  Eigen::VectorXd s_;            // y = s ⊙ T
  Eigen::VectorXd fscale_;       // f = fscale ⊙ w (w the nodal heat rate), 0 on Dirichlet rows
  Eigen::VectorXd jdiag_;        // diag of the constant part of J
  std::vector<Index> rx_node_;   // node of reacting unknown r
  Eigen::VectorXd rx_q_;         // Q of reacting node r
  Eigen::VectorXd frozen_;       // zero-order: λ_r for this window
  Eigen::VectorXd d_tt_, d_tl_, d_lt_, d_ll_;  // the reaction's 2×2 blocks of J
  mutable Eigen::VectorXd t_work_, w_work_;
};

}  // namespace frictherm::thermal::detail
