#include "ode_system.hpp"

#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>

namespace frictherm::thermal::detail {
namespace {

Eigen::Map<Eigen::VectorXd> view(N_Vector v) {
  return {N_VGetArrayPointer(v), static_cast<Index>(N_VGetLength(v))};
}

// Position of entry (row, col) in a compressed row-major matrix (it must exist).
Index find_entry(const SparseMatrix& a, Index row, Index col) {
  const auto* begin = a.innerIndexPtr() + a.outerIndexPtr()[row];
  const auto* end = a.innerIndexPtr() + a.outerIndexPtr()[row + 1];
  const auto* it = std::lower_bound(begin, end, static_cast<SparseMatrix::StorageIndex>(col));
  return static_cast<Index>(it - a.innerIndexPtr());
}

}  // namespace

void OdeSystem::build(const Problem& problem, bool symmetric) {
  problem_ = &problem;
  const Index n = problem.size();
  scale(problem.mass(), symmetric);
  for (Index d : problem.dirichlet_nodes()) fscale_[d] = 0.0;

  rx_node_.clear();
  consume_ = problem.reaction_consumes();
  if (problem.has_reaction()) {
    for (Index i = 0; i < n; ++i) {
      if (problem.reaction().heat[i] > 0.0 && !problem.is_dirichlet(i)) rx_node_.push_back(i);
    }
  }
  const Index nr = reacting();
  rx_q_.resize(nr);
  for (Index r = 0; r < nr; ++r) rx_q_[r] = problem.reaction().heat[rx_node_[static_cast<std::size_t>(r)]];
  frozen_ = Eigen::VectorXd::Zero(nr);
  const Index ns = state_size();

  // J_ij = −fscale_i (K_ij + δ_ij hA_i) / s_j over free i, j; explicit (maybe zero) diagonal
  // for every row so that I − γJ never needs a new sparsity pattern; explicit zeros on the
  // reaction's T–λ entries.
  const SparseMatrix& k = problem.conductance();
  const Eigen::VectorXd& ha = problem.convection_coefficients();
  if (problem.dirichlet_nodes().empty() && !consume_ && copy_conductance_pattern(k, ha)) {
    finish_build(n, nr);
    return;
  }
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(static_cast<std::size_t>(k.nonZeros() + n + 3 * nr));
  for (Index i = 0; i < n; ++i) {
    const bool free_row = !problem.is_dirichlet(i);
    trip.emplace_back(i, i, free_row ? -fscale_[i] * ha[i] / s_[i] : 0.0);
    if (!free_row) continue;
    for (SparseMatrix::InnerIterator it(k, i); it; ++it) {
      if (problem.is_dirichlet(it.col())) continue;
      trip.emplace_back(i, it.col(), -fscale_[i] * it.value() / s_[it.col()]);
    }
  }
  if (consume_) {
    for (Index r = 0; r < nr; ++r) {
      const Index i = rx_node_[static_cast<std::size_t>(r)];
      trip.emplace_back(i, n + r, 0.0);
      trip.emplace_back(n + r, i, 0.0);
      trip.emplace_back(n + r, n + r, 0.0);
    }
  }
  jac_.resize(ns, ns);
  jac_.setFromTriplets(trip.begin(), trip.end());
  jac_.makeCompressed();
  finish_build(n, nr);
}

// Without fixed nodes or a consumed reaction J has K's pattern: J = −diag(fscale) (K + diag(hA))
// diag(1/s) written over a copy of K (no triplet list, no sort: a window's build in a coupled run).
// The diagonal gets the convection term first and K's second, as setFromTriplets sums them, so J is
// bit-identical to the general build. False (nothing done) if K is not compressed with sorted
// columns and a stored diagonal in every row.
bool OdeSystem::copy_conductance_pattern(const SparseMatrix& k, const Eigen::VectorXd& ha) {
  if (!k.isCompressed()) return false;
  const Index n = k.rows();
  const auto* outer = k.outerIndexPtr();
  const auto* inner = k.innerIndexPtr();
  for (Index i = 0; i < n; ++i) {
    bool diagonal = false;
    for (auto e = outer[i]; e < outer[i + 1]; ++e) {
      if (e > outer[i] && inner[e] <= inner[e - 1]) return false;
      diagonal = diagonal || inner[e] == i;
    }
    if (!diagonal) return false;
  }
  jac_ = k;
  double* value = jac_.valuePtr();
  for (Index i = 0; i < n; ++i)
    for (auto e = outer[i]; e < outer[i + 1]; ++e) {
      const Index j = inner[e];
      const double kij = -fscale_[i] * value[e] / s_[j];
      value[e] = j == i ? -fscale_[i] * ha[i] / s_[i] + kij : kij;
    }
  return true;
}

void OdeSystem::finish_build(Index n, Index nr) {
  jdiag_ = jac_.diagonal();
  const auto nrs = static_cast<std::size_t>(nr);
  pos_tt_.assign(nrs, 0);
  pos_tl_.assign(consume_ ? nrs : 0, 0);
  pos_lt_.assign(consume_ ? nrs : 0, 0);
  pos_ll_.assign(consume_ ? nrs : 0, 0);
  for (std::size_t r = 0; r < nrs; ++r) {
    const Index i = rx_node_[r];
    pos_tt_[r] = find_entry(jac_, i, i);
    if (!consume_) continue;
    const Index l = n + static_cast<Index>(r);
    pos_tl_[r] = find_entry(jac_, i, l);
    pos_lt_[r] = find_entry(jac_, l, i);
    pos_ll_[r] = find_entry(jac_, l, l);
  }
  d_tt_ = d_tl_ = d_lt_ = d_ll_ = Eigen::VectorXd::Zero(nr);
  cache_valid_ = false;
  t_work_.resize(n);
  w_work_.resize(n);
}

MatrixPtr OdeSystem::make_jacobian_matrix(SUNContext ctx) const {
  SUNMatrix a = SUNSparseMatrix(static_cast<sunindextype>(state_size()), static_cast<sunindextype>(state_size()),
                                static_cast<sunindextype>(jac_.nonZeros()), CSR_MAT, ctx);
  check_ptr(a, "SUNSparseMatrix", "thermal");
  return MatrixPtr(a);
}

int OdeSystem::rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* self = static_cast<OdeSystem*>(user_data);
  try {
    self->problem_->transport_heat_rate(t, self->temperatures(N_VGetArrayPointer(y)), self->w_work_);
    self->finish_rhs(self->problem_->reaction(), N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
    return 0;
  } catch (...) {
    return -1;  // unrecoverable: SUNDIALS reports *_RHSFUNC_FAIL
  }
}

void OdeSystem::reaction_blocks(N_Vector y) {
  const Index n = nodes();
  const Index nr = reacting();
  const auto yv = view(y);
  const Index nkey = consume_ ? 2 * nr : nr;
  if (cache_valid_ && cache_key_.size() == nkey) {
    bool same = true;
    for (Index r = 0; r < nr && same; ++r) {
      same = cache_key_[r] == yv[rx_node_[static_cast<std::size_t>(r)]] && (!consume_ || cache_key_[nr + r] == yv[n + r]);
    }
    if (same) return;
  }
  cache_key_.resize(nkey);
  evaluate_reaction_blocks(problem_->reaction(), reaction_nodes(), yv.data(), n, s_, fscale_, reaction_blocks());
  for (Index r = 0; r < nr; ++r) {
    cache_key_[r] = yv[rx_node_[static_cast<std::size_t>(r)]];
    if (consume_) cache_key_[nr + r] = yv[n + r];
  }
  cache_valid_ = true;
}

int OdeSystem::jac(sunrealtype, N_Vector y, N_Vector, SUNMatrix J, void* user_data, N_Vector, N_Vector,
                   N_Vector) {
  auto* self = static_cast<OdeSystem*>(user_data);
  const SparseMatrix& a = self->jac_;  // constant part: copy the precomputed CSR arrays
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
  if (!self->has_reaction()) return 0;
  self->reaction_blocks(y);  // the reaction's 2×2 blocks at y
  for (std::size_t r = 0; r < self->rx_node_.size(); ++r) {
    const auto ri = static_cast<Index>(r);
    val[self->pos_tt_[r]] += self->d_tt_[ri];
    if (!self->consume_) continue;
    val[self->pos_tl_[r]] = self->d_tl_[ri];
    val[self->pos_lt_[r]] = self->d_lt_[ri];
    val[self->pos_ll_[r]] = self->d_ll_[ri];
  }
  return 0;
}

int OdeSystem::jtimes(N_Vector v, N_Vector jv, sunrealtype, N_Vector y, N_Vector, void* user_data,
                      N_Vector) {
  auto* self = static_cast<OdeSystem*>(user_data);
  auto out = view(jv);
  const auto in = view(v);
  out.noalias() = self->jac_ * in;  // exact stencil apply
  if (!self->has_reaction()) return 0;
  self->reaction_blocks(y);  // exact J·v at the current iterate
  add_reaction_jv(self->reaction_nodes(), self->reaction_blocks_view(), in.data(), out.data(), self->nodes());
  return 0;
}

int OdeSystem::psetup(sunrealtype, N_Vector y, N_Vector, sunbooleantype, sunbooleantype* jcur, sunrealtype,
                      void* user_data) {
  auto* self = static_cast<OdeSystem*>(user_data);
  self->reaction_blocks(y);
  *jcur = SUNTRUE;
  return 0;
}

int OdeSystem::psolve(sunrealtype, N_Vector, N_Vector, N_Vector r, N_Vector z, sunrealtype gamma,
                      sunrealtype, int, void* user_data) {
  const auto* self = static_cast<const OdeSystem*>(user_data);
  // P = diag(I − γJ) = 1 + γ·diag(M^{-1/2}K_eff M^{-1/2}) > 0 (Jacobi, thermal-notes §1)
  auto zv = view(z);
  const auto rv = view(r);
  zv = rv.array() / (1.0 - gamma * self->jdiag_.array());
  if (!self->has_reaction()) return 0;
  // Reacting nodes: exact inverse of the 2×2 block of I − γJ (1×1 when zero-order). A
  // non-positive pivot means the step is too long for the self-heating: recoverable failure.
  return invert_reaction_blocks(self->reaction_nodes(), self->reaction_blocks_view(), self->jdiag_.data(), gamma,
                                rv.data(), zv.data(), self->nodes());
}

}  // namespace frictherm::thermal::detail
