#include "ode_system.hpp"

#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <vector>

namespace frictherm::thermal::detail {
namespace {

Eigen::Map<Eigen::VectorXd> view(N_Vector v) {
  return {N_VGetArrayPointer(v), static_cast<Index>(N_VGetLength(v))};
}

}  // namespace

void OdeSystem::build(const Problem& problem, bool symmetric) {
  problem_ = &problem;
  symmetric_ = symmetric;
  const Index n = problem.size();
  const Eigen::VectorXd& m = problem.mass();
  s_ = symmetric ? Eigen::VectorXd(m.cwiseSqrt()) : Eigen::VectorXd::Ones(n);
  fscale_ = s_.cwiseQuotient(m);  // 1/M (plain) or M^{-1/2} (symmetric)
  for (Index d : problem.dirichlet_nodes()) fscale_[d] = 0.0;

  // J_ij = −fscale_i (K_ij + δ_ij hA_i) / s_j over free i, j; explicit (maybe zero) diagonal
  // for every row so that I − γJ never needs a new sparsity pattern.
  const SparseMatrix& k = problem.conductance();
  const Eigen::VectorXd& ha = problem.convection_coefficients();
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(static_cast<std::size_t>(k.nonZeros() + n));
  for (Index i = 0; i < n; ++i) {
    const bool free_row = !problem.is_dirichlet(i);
    trip.emplace_back(i, i, free_row ? -fscale_[i] * ha[i] / s_[i] : 0.0);
    if (!free_row) continue;
    for (SparseMatrix::InnerIterator it(k, i); it; ++it) {
      if (problem.is_dirichlet(it.col())) continue;
      trip.emplace_back(i, it.col(), -fscale_[i] * it.value() / s_[it.col()]);
    }
  }
  jac_.resize(n, n);
  jac_.setFromTriplets(trip.begin(), trip.end());
  jac_.makeCompressed();
  jdiag_ = jac_.diagonal();
  t_work_.resize(n);
  w_work_.resize(n);
}

void OdeSystem::to_y(const Eigen::VectorXd& T, N_Vector y) const { view(y) = s_.cwiseProduct(T); }

void OdeSystem::to_T(N_Vector y, Eigen::VectorXd& T) const { T = view(y).cwiseQuotient(s_); }

void OdeSystem::fill_abstol(double atol, N_Vector out) const { view(out) = atol * s_; }

MatrixPtr OdeSystem::make_jacobian_matrix(SUNContext ctx) const {
  SUNMatrix a = SUNSparseMatrix(static_cast<sunindextype>(size()), static_cast<sunindextype>(size()),
                                static_cast<sunindextype>(jac_.nonZeros()), CSR_MAT, ctx);
  check_ptr(a, "SUNSparseMatrix", "thermal");
  return MatrixPtr(a);
}

int OdeSystem::rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* self = static_cast<OdeSystem*>(user_data);
  try {
    self->t_work_ = view(y).cwiseQuotient(self->s_);
    self->problem_->heat_rate(t, self->t_work_, self->w_work_);
    view(ydot) = self->fscale_.cwiseProduct(self->w_work_);
    return 0;
  } catch (...) {
    return -1;  // unrecoverable: SUNDIALS reports *_RHSFUNC_FAIL
  }
}

int OdeSystem::jac(sunrealtype, N_Vector, N_Vector, SUNMatrix J, void* user_data, N_Vector, N_Vector,
                   N_Vector) {
  const auto* self = static_cast<const OdeSystem*>(user_data);
  const SparseMatrix& a = self->jac_;  // constant: copy the precomputed CSR arrays
  const auto nnz = static_cast<sunindextype>(a.nonZeros());
  if (SUNSparseMatrix_NNZ(J) < nnz && SUNSparseMatrix_Reallocate(J, nnz) != 0) return -1;
  sunindextype* ptr = SUNSparseMatrix_IndexPointers(J);
  sunindextype* idx = SUNSparseMatrix_IndexValues(J);
  sunrealtype* val = SUNSparseMatrix_Data(J);
  for (Index r = 0; r <= a.rows(); ++r) ptr[r] = static_cast<sunindextype>(a.outerIndexPtr()[r]);
  for (Index e = 0; e < a.nonZeros(); ++e) {
    idx[e] = static_cast<sunindextype>(a.innerIndexPtr()[e]);
    val[e] = a.valuePtr()[e];
  }
  return 0;
}

int OdeSystem::jtimes(N_Vector v, N_Vector jv, sunrealtype, N_Vector, N_Vector, void* user_data,
                      N_Vector) {
  const auto* self = static_cast<const OdeSystem*>(user_data);
  view(jv).noalias() = self->jac_ * view(v);  // exact stencil apply
  return 0;
}

int OdeSystem::psolve(sunrealtype, N_Vector, N_Vector, N_Vector r, N_Vector z, sunrealtype gamma,
                      sunrealtype, int, void* user_data) {
  const auto* self = static_cast<const OdeSystem*>(user_data);
  // P = diag(I − γJ) = 1 + γ·diag(M^{-1/2}K_eff M^{-1/2}) > 0 (Jacobi, thermal-notes §1)
  view(z) = view(r).array() / (1.0 - gamma * self->jdiag_.array());
  return 0;
}

}  // namespace frictherm::thermal::detail
