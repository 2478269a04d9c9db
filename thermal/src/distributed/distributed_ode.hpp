// The DistributedProblem as an ODE y' = f(t, y) on SUNDIALS N_Vector_Parallel vectors, in the
// serial module's two forms (ode_system.hpp):
//   plain      y = T,          f = M⁻¹(−K T + q),           J = −M⁻¹K
//   symmetric  y = M^{1/2} T,  f = M^{-1/2}(−K T + q),      J = −M^{-1/2} K M^{-1/2}  (PCG)
// over the owned rows, Dirichlet rows and columns of J dropped. J·v and the preconditioner
// P = I − γJ (a parallel PETSc AIJ matrix, owned rows, global columns) use the ghost values of
// v fetched by the problem's VecScatter. With the problem's reaction, the serial OdeSystem's state
// and blocks (ode_system.hpp): y = [s ⊙ T; λ_r of this rank's free reacting nodes] when it consumes,
// f_T,i += fscale_i Q_i (1 − λ) k(T_i), f_λ,r = (1 − λ_r) k(T_i), the 2×2 block per reacting node in
// J·v, and the serial preconditioner: P = I − γJ block-Jacobi (1/(1 − γJ_ii), the 2×2 blocks inverted
// exactly), no PETSc PC. Internal header; callbacks take this object as user_data.
#pragma once

#include "../ode_form.hpp"
#include "../sundials_support.hpp"
#include "frictherm/thermal/distributed.hpp"

#include <petscksp.h>

#include <string>
#include <vector>

namespace frictherm::thermal::detail {

// N_VNew_Parallel whose reductions (dot products, norms, min …) count themselves in
// DistributedProblem::count_reductions; clones inherit the counting operations.
NVectorPtr make_parallel_vector(MPI_Comm comm, Index local, Index global, SUNContext ctx);

class DistributedOde : public OdeForm {
 public:
  DistributedOde() = default;
  DistributedOde(const DistributedOde&) = delete;
  DistributedOde& operator=(const DistributedOde&) = delete;
  ~DistributedOde();

  // Collective (two ghost exchanges: s and the Dirichlet mask of the ghost columns).
  // preconditioner: "jacobi", "bjacobi", "hypre", "mumps" (sparse direct LU), or empty for none (no PETSc objects).
  void build(const DistributedProblem& problem, bool symmetric, const std::string& preconditioner);
  void bind(const DistributedProblem& problem) { problem_ = &problem; }
  // The problem has a reaction (the same on every rank); it consumes: J is not symmetric (GMRES).
  bool has_reaction() const { return reacts_; }
  bool nonsymmetric() const { return reacts_ && consume_; }


  static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data);
  static int jtimes(N_Vector v, N_Vector jv, sunrealtype t, N_Vector y, N_Vector fy, void* user_data, N_Vector tmp);
  // Assembles P = I − γJ when γ changed and sets the PETSc PC up on it.
  static int psetup(sunrealtype t, N_Vector y, N_Vector fy, sunbooleantype jok, sunbooleantype* jcur,
                    sunrealtype gamma, void* user_data);
  // z = PC⁻¹ r (one KSPSolve with KSPPREONLY).
  static int psolve(sunrealtype t, N_Vector y, N_Vector fy, N_Vector r, N_Vector z, sunrealtype gamma,
                    sunrealtype delta, int lr, void* user_data);

  long preconditioner_setups() const { return setups_; }
  // True on every rank when no rank has a Dirichlet node and every row of K sums to zero (to
  // 1e-12 of its diagonal): then Σ M T is invariant under conduction (conservative_krylov.hpp).
  bool conserves() const { return conserves_; }

 private:
  void destroy_petsc();
  void assemble(double gamma);
  void build_reaction(const DistributedProblem& problem);
  void reaction_blocks(const double* y);  // the 2×2 blocks at y (OdeSystem::reaction_blocks)
  int block_jacobi(const double* r, double* z, double gamma) const;

  bool reacts_ = false;  // rx_node_: this rank's free reacting nodes (local), r = 0..R−1

  const DistributedProblem* problem_ = nullptr;
  bool conserves_ = false;
  std::vector<double> jval_;  // J in the problem's local CSR (row_start, local_col); 0 on dropped entries
  // Preconditioner matrix rows: global columns (K's, plus the diagonal when K lacks it) and the
  // position of the diagonal among them.
  std::vector<PetscInt> p_start_, p_col_, p_diag_;
  std::vector<double> p_j_, p_val_;
  Mat pmat_ = nullptr;
  KSP ksp_ = nullptr;
  Vec r_vec_ = nullptr, z_vec_ = nullptr;
  double gamma_ = -1.0;
  long setups_ = 0;
};

}  // namespace frictherm::thermal::detail
