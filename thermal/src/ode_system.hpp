// The thermal Problem written as an ODE y' = f(t, y) for SUNDIALS, in one of two forms
// (thermal-notes §1 "Mass matrix"):
//   plain      y = T,          f = M⁻¹(−K_eff T + b(t)),  J = −M⁻¹K_eff
//   symmetric  y = M^{1/2} T,  f = M^{-1/2}(−K_eff T + b), J = −M^{-1/2}K_eff M^{-1/2} (SPD form
//              needed by PCG; absolute tolerances scale as √M_i·atol).
// Dirichlet rows and columns of J are dropped: their f is 0 and their Newton correction is
// 0, so the dropped columns never act, and J stays symmetric in the symmetric form.
//
// Reaction (reaction.hpp), on the free nodes i with Q_i > 0 ("reacting nodes", r = 0..R−1):
//   f_T,i += c_i Q_i (1 − λ_r) k(T_i),   c_i = fscale_i (1/M_i or M_i^{-1/2});
//   consuming: the state grows to y = [s ⊙ T; λ_0 … λ_{R−1}] (N + R unknowns) with
//   f_λ,r = (1 − λ_r) k(T_i); zero-order: λ is a fixed parameter of the window.
// The reaction adds a 2×2 block per reacting node to J (T = y/s):
//   ∂f_T,i/∂y_i += c_i Q_i (1 − λ_r) k'(T_i)/s_i    ∂f_T,i/∂λ_r = −c_i Q_i k(T_i)
//   ∂f_λ,r/∂y_i  = (1 − λ_r) k'(T_i)/s_i            ∂f_λ,r/∂λ_r = −k(T_i)
// so J is no longer constant. With consumption it is not symmetric (∂f_T/∂λ < 0 < ∂f_λ/∂T,
// so no diagonal scaling symmetrises it): Krylov then uses GMRES.
// Internal header; callbacks take this object as user_data.
#pragma once

#include "frictherm/thermal/problem.hpp"
#include "ode_form.hpp"
#include "sundials_support.hpp"

#include <sundials/sundials_types.h>

#include <vector>

namespace frictherm::thermal::detail {

class OdeSystem : public OdeForm {
 public:
  void build(const Problem& problem, bool symmetric);
  // Rebinds to the caller's Problem object for this window (same revision as built).
  void bind(const Problem& problem) { problem_ = &problem; }
  bool symmetric() const { return symmetric_; }
  bool has_reaction() const { return !rx_node_.empty(); }
  // The Newton matrix is non-symmetric (consuming reaction): Krylov must be GMRES.
  bool nonsymmetric() const { return consume_ && has_reaction(); }

  // OdeForm::to_y, and the reaction blocks' cache cleared.
  void to_y(const Eigen::VectorXd& T, const Eigen::VectorXd* progress, N_Vector y) {
    OdeForm::to_y(T, progress, y);
    cache_valid_ = false;
  }
  const SparseMatrix& jacobian() const { return jac_; }  // constant part (reaction entries 0)
  MatrixPtr make_jacobian_matrix(SUNContext ctx) const;  // CSR SUNSparseMatrix with J's pattern

  static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data);
  static int jac(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J, void* user_data, N_Vector tmp1,
                 N_Vector tmp2, N_Vector tmp3);
  static int jtimes(N_Vector v, N_Vector jv, sunrealtype t, N_Vector y, N_Vector fy, void* user_data,
                    N_Vector tmp);
  // Reaction only: evaluates the reaction blocks at y for psolve.
  static int psetup(sunrealtype t, N_Vector y, N_Vector fy, sunbooleantype jok, sunbooleantype* jcur,
                    sunrealtype gamma, void* user_data);
  // Jacobi preconditioner z = diag(I − γJ)⁻¹ r (2×2 blocks on reacting nodes when consuming).
  static int psolve(sunrealtype t, N_Vector y, N_Vector fy, N_Vector r, N_Vector z, sunrealtype gamma,
                    sunrealtype delta, int lr, void* user_data);

 private:
  // Reaction Jacobian entries at y into d_tt_ … d_ll_ (cached on the reacting entries of y).
  void reaction_blocks(N_Vector y);
  ReactionBlocks reaction_blocks() { return {d_tt_, d_tl_, d_lt_, d_ll_}; }
  bool copy_conductance_pattern(const SparseMatrix& k, const Eigen::VectorXd& ha);  // build's fast path
  void finish_build(Index n, Index nr);  // after jac_: its diagonal and the reaction entries' positions

  const Problem* problem_ = nullptr;
  SparseMatrix jac_;        // constant part of J, with explicit zeros on the reaction entries
  std::vector<Index> pos_tt_, pos_tl_, pos_lt_, pos_ll_;  // CSR positions of the reaction entries
  Eigen::VectorXd cache_key_;  // reacting entries of y the blocks were computed at
  bool cache_valid_ = false;
};

}  // namespace frictherm::thermal::detail
