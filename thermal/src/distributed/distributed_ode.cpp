#include "distributed_ode.hpp"

#include "petsc_check.hpp"

#include <nvector/nvector_parallel.h>

#include <algorithm>
#include <cmath>

namespace frictherm::thermal::detail {
namespace {

// Each N_Vector_Parallel reduction is one MPI_Allreduce: count it, then do it.
void count() { DistributedProblem::count_reductions(1); }
sunrealtype c_dot(N_Vector x, N_Vector y) { count(); return N_VDotProd_Parallel(x, y); }
sunrealtype c_maxnorm(N_Vector x) { count(); return N_VMaxNorm_Parallel(x); }
sunrealtype c_wrms(N_Vector x, N_Vector w) { count(); return N_VWrmsNorm_Parallel(x, w); }
sunrealtype c_wrmsmask(N_Vector x, N_Vector w, N_Vector id) { count(); return N_VWrmsNormMask_Parallel(x, w, id); }
sunrealtype c_min(N_Vector x) { count(); return N_VMin_Parallel(x); }
sunrealtype c_wl2(N_Vector x, N_Vector w) { count(); return N_VWL2Norm_Parallel(x, w); }
sunrealtype c_l1(N_Vector x) { count(); return N_VL1Norm_Parallel(x); }
sunbooleantype c_invtest(N_Vector x, N_Vector z) { count(); return N_VInvTest_Parallel(x, z); }
sunbooleantype c_constrmask(N_Vector c, N_Vector x, N_Vector m) { count(); return N_VConstrMask_Parallel(c, x, m); }
sunrealtype c_minquot(N_Vector n, N_Vector d) { count(); return N_VMinQuotient_Parallel(n, d); }
int c_dotmulti(int nv, N_Vector x, N_Vector* y, sunrealtype* d) { count(); return N_VDotProdMulti_Parallel(nv, x, y, d); }
int c_wrmsarray(int nv, N_Vector* x, N_Vector* w, sunrealtype* d) {
  count();
  return N_VWrmsNormVectorArray_Parallel(nv, x, w, d);
}
int c_wrmsmaskarray(int nv, N_Vector* x, N_Vector* w, N_Vector id, sunrealtype* d) {
  count();
  return N_VWrmsNormMaskVectorArray_Parallel(nv, x, w, id, d);
}

}  // namespace

NVectorPtr make_parallel_vector(MPI_Comm comm, Index local, Index global, SUNContext ctx) {
  N_Vector v = N_VNew_Parallel(comm, static_cast<sunindextype>(local), static_cast<sunindextype>(global), ctx);
  check_ptr(v, "N_VNew_Parallel", "thermal (distributed)");
  N_Vector_Ops o = v->ops;
  o->nvdotprod = c_dot;
  o->nvmaxnorm = c_maxnorm;
  o->nvwrmsnorm = c_wrms;
  o->nvwrmsnormmask = c_wrmsmask;
  o->nvmin = c_min;
  o->nvwl2norm = c_wl2;
  o->nvl1norm = c_l1;
  o->nvinvtest = c_invtest;
  o->nvconstrmask = c_constrmask;
  o->nvminquotient = c_minquot;
  if (o->nvdotprodmulti != nullptr) o->nvdotprodmulti = c_dotmulti;
  if (o->nvwrmsnormvectorarray != nullptr) o->nvwrmsnormvectorarray = c_wrmsarray;
  if (o->nvwrmsnormmaskvectorarray != nullptr) o->nvwrmsnormmaskvectorarray = c_wrmsmaskarray;
  o->nvdotprodmultiallreduce = nullptr;  // would bypass the count; SUNDIALS falls back to nvdotprodmulti
  return NVectorPtr(v);
}

DistributedOde::~DistributedOde() { destroy_petsc(); }

void DistributedOde::destroy_petsc() {
  KSPDestroy(&ksp_);
  MatDestroy(&pmat_);
  VecDestroy(&r_vec_);
  VecDestroy(&z_vec_);
  gamma_ = -1.0;
}

void DistributedOde::build(const DistributedProblem& problem, bool symmetric, const std::string& preconditioner) {
  problem_ = &problem;
  const Index n = problem.local_size();
  scale(problem.mass(), symmetric);
  Eigen::VectorXd free(n);
  for (Index i = 0; i < n; ++i) free[i] = problem.is_dirichlet_local(i) ? 0.0 : 1.0;
  for (Index i = 0; i < n; ++i) fscale_[i] *= free[i];
  const auto ng = problem.ghost_ids().size();
  const double* gs = problem.exchange(s_.data());
  const std::vector<double> s_ghost(gs, gs + ng);
  const double* gf = problem.exchange(free.data());
  const std::vector<double> free_ghost(gf, gf + ng);

  // J_ij = −fscale_i K_ij / s_j over free i, j (ode_system.cpp), kept in the problem's local CSR.
  const auto& start = problem.row_start();
  const auto& col = problem.local_col();
  const double* kv = problem.conductance().valuePtr();
  const auto* kcol = problem.conductance().innerIndexPtr();
  jval_.assign(col.size(), 0.0);
  for (Index i = 0; i < n; ++i) {
    for (Index e = start[static_cast<std::size_t>(i)]; e < start[static_cast<std::size_t>(i) + 1]; ++e) {
      const auto ue = static_cast<std::size_t>(e);
      const Index c = col[ue];
      const double sj = c < n ? s_[c] : s_ghost[static_cast<std::size_t>(c - n)];
      const double fj = c < n ? free[c] : free_ghost[static_cast<std::size_t>(c - n)];
      jval_[ue] = fj > 0.0 ? -fscale_[i] * kv[e] / sj : 0.0;
    }
  }
  t_work_.resize(n);
  w_work_.resize(n);
  // An insulated problem conserves Σ M T (conservative_krylov.hpp): no Dirichlet node and zero row sums
  // to 1e-12 of the row's Σ_j |K_ij| (a particle-assembled 3D row sums ~100 products of both signs whose
  // magnitudes can exceed its diagonal many times: the round-off of the sum scales with them).
  int mine = 1, all = 0;
  for (Index i = 0; i < n && mine; ++i) {
    double sum = 0.0, size = 0.0;
    for (Index e = start[static_cast<std::size_t>(i)]; e < start[static_cast<std::size_t>(i) + 1]; ++e) {
      sum += kv[e];
      size += std::abs(kv[e]);
    }
    mine = free[i] > 0.0 && std::abs(sum) <= 1e-12 * size ? 1 : 0;
  }
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, problem.comm());
  DistributedProblem::count_reductions(1);
  conserves_ = all == 1 && !problem.has_reaction();  // the reaction adds heat: Σ M T is not invariant

  destroy_petsc();
  build_reaction(problem);
  if (preconditioner.empty() || reacts_) return;  // a reaction: the serial block Jacobi (psolve)
  // P = I − γJ with K's pattern plus an explicit diagonal: rows owned, columns global.
  const Index first = problem.first_row();
  p_start_.assign(1, 0);
  p_col_.clear();
  p_j_.clear();
  p_diag_.clear();
  std::vector<PetscInt> d_nnz(static_cast<std::size_t>(n), 0), o_nnz(static_cast<std::size_t>(n), 0);
  for (Index i = 0; i < n; ++i) {
    PetscInt diag = -1;
    for (Index e = start[static_cast<std::size_t>(i)]; e < start[static_cast<std::size_t>(i) + 1]; ++e) {
      const PetscInt gcol = kcol[e];
      if (gcol == first + i) diag = static_cast<PetscInt>(p_col_.size());
      p_col_.push_back(gcol);
      p_j_.push_back(jval_[static_cast<std::size_t>(e)]);
    }
    if (diag < 0) {
      diag = static_cast<PetscInt>(p_col_.size());
      p_col_.push_back(static_cast<PetscInt>(first + i));
      p_j_.push_back(0.0);
    }
    p_diag_.push_back(diag);
    p_start_.push_back(static_cast<PetscInt>(p_col_.size()));
    for (PetscInt e = p_start_[static_cast<std::size_t>(i)]; e < p_start_.back(); ++e) {
      const bool own = problem.owns(p_col_[static_cast<std::size_t>(e)]);
      ++(own ? d_nnz : o_nnz)[static_cast<std::size_t>(i)];
    }
  }
  p_val_.assign(p_col_.size(), 0.0);
  const MPI_Comm comm = problem.comm();
  const auto pn = static_cast<PetscInt>(n), pN = static_cast<PetscInt>(problem.global_size());
  petsc_check(MatCreateAIJ(comm, pn, pn, pN, pN, 0, d_nnz.data(), 0, o_nnz.data(), &pmat_), "MatCreateAIJ");
  petsc_check(MatSetOption(pmat_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
  petsc_check(VecCreateMPIWithArray(comm, 1, pn, pN, nullptr, &r_vec_), "VecCreateMPIWithArray");
  petsc_check(VecCreateMPIWithArray(comm, 1, pn, pN, nullptr, &z_vec_), "VecCreateMPIWithArray");
  petsc_check(KSPCreate(comm, &ksp_), "KSPCreate");
  petsc_check(KSPSetType(ksp_, KSPPREONLY), "KSPSetType");  // the PC alone: SUNDIALS runs the Krylov method
  PC pc = nullptr;
  petsc_check(KSPGetPC(ksp_, &pc), "KSPGetPC");
  if (preconditioner == "jacobi") {
    petsc_check(PCSetType(pc, PCJACOBI), "PCSetType(jacobi)");
  } else if (preconditioner == "bjacobi") {
    petsc_check(PCSetType(pc, PCBJACOBI), "PCSetType(bjacobi)");  // ILU(0) per rank by default
  } else if (preconditioner == "hypre") {
    petsc_check(PCSetType(pc, PCHYPRE), "PCSetType(hypre)");
    petsc_check(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType(boomeramg)");
  } else if (preconditioner == "mumps") {  // a sparse direct LU of P over the ranks: the first Krylov iterate solves
    petsc_check(PCSetType(pc, PCLU), "PCSetType(lu)");
    petsc_check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType(mumps)");
  } else {
    throw std::invalid_argument("thermal (distributed): unknown preconditioner \"" + preconditioner +
                                "\" (valid: jacobi, bjacobi, hypre, mumps)");
  }
}

void DistributedOde::assemble(double gamma) {
  // P_ij = δ_ij − γ J_ij (Dirichlet rows: the identity)
  for (std::size_t e = 0; e < p_j_.size(); ++e) p_val_[e] = -gamma * p_j_[e];
  const Index n = nodes();
  const auto first = static_cast<PetscInt>(problem_->first_row());
  for (Index i = 0; i < n; ++i) {
    p_val_[static_cast<std::size_t>(p_diag_[static_cast<std::size_t>(i)])] += 1.0;
    const PetscInt row = first + static_cast<PetscInt>(i);
    const PetscInt b = p_start_[static_cast<std::size_t>(i)], e = p_start_[static_cast<std::size_t>(i) + 1];
    petsc_check(MatSetValues(pmat_, 1, &row, e - b, p_col_.data() + b, p_val_.data() + b, INSERT_VALUES),
                "MatSetValues");
  }
  petsc_check(MatAssemblyBegin(pmat_, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  petsc_check(MatAssemblyEnd(pmat_, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  petsc_check(KSPSetOperators(ksp_, pmat_, pmat_), "KSPSetOperators");
  petsc_check(KSPSetUp(ksp_), "KSPSetUp");
  gamma_ = gamma;
  ++setups_;
}

int DistributedOde::rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* self = static_cast<DistributedOde*>(user_data);
  try {
    self->problem_->heat_rate(t, self->temperatures(N_VGetArrayPointer(y)).data(), self->w_work_.data());
    self->finish_rhs(self->problem_->reaction(), N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
    return 0;
  } catch (...) {
    return -1;  // unrecoverable
  }
}

int DistributedOde::jtimes(N_Vector v, N_Vector jv, sunrealtype, N_Vector y, N_Vector, void* user_data, N_Vector) {
  auto* self = static_cast<DistributedOde*>(user_data);
  try {
    const double* in = N_VGetArrayPointer(v);
    double* out = N_VGetArrayPointer(jv);
    const double* g = self->problem_->exchange(in);
    const auto& start = self->problem_->row_start();
    const auto& col = self->problem_->local_col();
    const Index n = self->nodes();
    for (Index i = 0; i < n; ++i) {
      double acc = 0.0;
      for (Index e = start[static_cast<std::size_t>(i)]; e < start[static_cast<std::size_t>(i) + 1]; ++e) {
        const Index c = col[static_cast<std::size_t>(e)];
        acc += self->jval_[static_cast<std::size_t>(e)] * (c < n ? in[c] : g[c - n]);
      }
      out[i] = acc;
    }
    if (!self->reacts_) return 0;
    self->reaction_blocks(N_VGetArrayPointer(y));  // exact J·v at the current iterate (OdeSystem::jtimes)
    add_reaction_jv(self->reaction_nodes(), self->reaction_blocks_view(), in, out, n);
    return 0;
  } catch (...) {
    return -1;
  }
}

int DistributedOde::psetup(sunrealtype, N_Vector y, N_Vector, sunbooleantype, sunbooleantype* jcur, sunrealtype gamma,
                           void* user_data) {
  auto* self = static_cast<DistributedOde*>(user_data);
  try {
    if (self->reacts_) {  // the blocks at y; psolve inverts them with its γ (OdeSystem::psetup)
      self->reaction_blocks(N_VGetArrayPointer(y));
      *jcur = SUNTRUE;
      return 0;
    }
    // J is constant: only a new γ changes P (the jok flag carries no information here).
    if (gamma != self->gamma_) self->assemble(gamma);
    *jcur = SUNTRUE;
    return 0;
  } catch (...) {
    return -1;
  }
}

int DistributedOde::psolve(sunrealtype, N_Vector, N_Vector, N_Vector r, N_Vector z, sunrealtype gamma, sunrealtype, int,
                           void* user_data) {
  auto* self = static_cast<DistributedOde*>(user_data);
  try {
    if (self->reacts_) {
      // A non-positive pivot on any rank (the step too long for the self-heating): a recoverable
      // failure on every rank alike, so that no rank goes on alone into the next collective call.
      int ok = self->block_jacobi(N_VGetArrayPointer(r), N_VGetArrayPointer(z), gamma) == 0 ? 1 : 0, all = 0;
      MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, self->problem_->comm());
      DistributedProblem::count_reductions(1);
      return all == 1 ? 0 : 1;
    }
    petsc_check(VecPlaceArray(self->r_vec_, N_VGetArrayPointer(r)), "VecPlaceArray");
    petsc_check(VecPlaceArray(self->z_vec_, N_VGetArrayPointer(z)), "VecPlaceArray");
    const PetscErrorCode code = KSPSolve(self->ksp_, self->r_vec_, self->z_vec_);
    VecResetArray(self->r_vec_);
    VecResetArray(self->z_vec_);
    petsc_check(code, "KSPSolve");
    return 0;
  } catch (...) {
    return -1;
  }
}

// The free nodes with Q_i > 0 (OdeSystem::build), their Q_i, and the diagonal of J for the block Jacobi.
void DistributedOde::build_reaction(const DistributedProblem& problem) {
  reacts_ = problem.has_reaction();
  consume_ = problem.reaction_consumes();
  rx_node_.clear();
  if (!reacts_) return;
  const Index n = nodes();
  for (Index i = 0; i < n; ++i)
    if (problem.reaction().heat[i] > 0.0 && !problem.is_dirichlet_local(i)) rx_node_.push_back(i);
  const Index nr = reacting();
  rx_q_.resize(nr);
  for (Index r = 0; r < nr; ++r) rx_q_[r] = problem.reaction().heat[rx_node_[static_cast<std::size_t>(r)]];
  frozen_.setZero(nr);
  d_tt_.setZero(nr), d_tl_.setZero(nr), d_lt_.setZero(nr), d_ll_.setZero(nr);
  jdiag_.setZero(n);
  const auto& start = problem.row_start();
  const auto& col = problem.local_col();
  for (Index i = 0; i < n; ++i)
    for (Index e = start[static_cast<std::size_t>(i)]; e < start[static_cast<std::size_t>(i) + 1]; ++e)
      if (col[static_cast<std::size_t>(e)] == i) jdiag_[i] += jval_[static_cast<std::size_t>(e)];
}

// OdeSystem::reaction_blocks: ∂f_T/∂y, ∂f_T/∂λ, ∂f_λ/∂y, ∂f_λ/∂λ at the reacting nodes (T = y/s).
void DistributedOde::reaction_blocks(const double* y) {
  evaluate_reaction_blocks(problem_->reaction(), reaction_nodes(), y, nodes(), s_, fscale_,
                           {d_tt_, d_tl_, d_lt_, d_ll_});
}

// OdeSystem::psolve: z = diag(I − γJ)⁻¹ r, the reacting nodes' 2×2 blocks (1×1 zero-order) inverted
// exactly; 1 for a non-positive pivot.
int DistributedOde::block_jacobi(const double* r, double* z, double gamma) const {
  const Index n = nodes();
  for (Index i = 0; i < n; ++i) z[i] = r[i] / (1.0 - gamma * jdiag_[i]);
  return invert_reaction_blocks(reaction_nodes(), reaction_blocks_view(), jdiag_.data(), gamma, r, z, n);
}

}  // namespace frictherm::thermal::detail
