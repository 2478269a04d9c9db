// The thermal Problem written as an ODE y' = f(t, y) for SUNDIALS, in one of two forms
// (thermal-notes §1 "Mass matrix"):
//   plain      y = T,          f = M⁻¹(−K_eff T + b(t)),  J = −M⁻¹K_eff
//   symmetric  y = M^{1/2} T,  f = M^{-1/2}(−K_eff T + b), J = −M^{-1/2}K_eff M^{-1/2} (SPD form
//              needed by PCG; absolute tolerances scale as √M_i·atol).
// Dirichlet rows and columns of J are dropped: their f is 0 and their Newton correction is
// 0, so the dropped columns never act, and J stays symmetric in the symmetric form.
// Internal header; callbacks take this object as user_data.
#pragma once

#include "frictherm/thermal/problem.hpp"
#include "sundials_support.hpp"

#include <sundials/sundials_types.h>

namespace frictherm::thermal::detail {

class OdeSystem {
 public:
  void build(const Problem& problem, bool symmetric);
  // Rebinds to the caller's Problem object for this window (same revision as built).
  void bind(const Problem& problem) { problem_ = &problem; }
  Index size() const { return s_.size(); }
  bool symmetric() const { return symmetric_; }

  void to_y(const Eigen::VectorXd& T, N_Vector y) const;
  void to_T(N_Vector y, Eigen::VectorXd& T) const;
  void fill_abstol(double atol, N_Vector out) const;
  const SparseMatrix& jacobian() const { return jac_; }
  MatrixPtr make_jacobian_matrix(SUNContext ctx) const;  // CSR SUNSparseMatrix with J's pattern

  static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data);
  static int jac(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J, void* user_data, N_Vector tmp1,
                 N_Vector tmp2, N_Vector tmp3);
  static int jtimes(N_Vector v, N_Vector jv, sunrealtype t, N_Vector y, N_Vector fy, void* user_data,
                    N_Vector tmp);
  // Jacobi preconditioner z = diag(I − γJ)⁻¹ r.
  static int psolve(sunrealtype t, N_Vector y, N_Vector fy, N_Vector r, N_Vector z, sunrealtype gamma,
                    sunrealtype delta, int lr, void* user_data);

 private:
  const Problem* problem_ = nullptr;
  bool symmetric_ = false;
  Eigen::VectorXd s_;       // y = s ⊙ T
  Eigen::VectorXd fscale_;  // f = fscale ⊙ w (w the nodal heat rate), 0 on Dirichlet rows
  Eigen::VectorXd jdiag_;   // diag(J)
  SparseMatrix jac_;
  mutable Eigen::VectorXd t_work_, w_work_;
};

}  // namespace frictherm::thermal::detail
