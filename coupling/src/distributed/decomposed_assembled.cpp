// The assembled window of a decomposed run (decomposed_assembled.hpp): K's rows from every rank's
// particles summed at their owners through a PETSc matrix, then the distributed integrator.
#include "distributed/decomposed_assembled.hpp"

#include <frictherm/coupling/thermal_assembly.hpp>

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <petscmat.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace frictherm::coupling {

namespace {

void petsc_check(PetscErrorCode code, const char* call) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  throw std::runtime_error(std::string("decomposed heat: ") + call + " failed with PETSc error " +
                           std::to_string(static_cast<int>(code)) + (text != nullptr ? std::string(": ") + text : ""));
}

struct MatHolder {
  Mat A = nullptr;
  ~MatHolder() { MatDestroy(&A); }
};

}  // namespace

DecomposedAssembledSolve::DecomposedAssembledSolve(const std::string& name, const thermal::IntegratorOptions& options,
                                                   const std::string& preconditioner)
    : name_(name), preconditioner_(preconditioner), options_(options) {
  restart_integrator();
  stats_offset_ = thermal::IntegratorStats{};
}

DecomposedAssembledSolve::~DecomposedAssembledSolve() = default;

void DecomposedAssembledSolve::restart_integrator() {
  if (integrator_) stats_offset_ += integrator_->stats();
  thermal::DistributedOptions o;
  o.integrator = options_;
  o.preconditioner = preconditioner_;
  integrator_ = thermal::make_distributed_integrator(name_, o);
}

void DecomposedAssembledSolve::advance(MPI_Comm comm, const UnknownNumbering& ids, const KeptEntries& kept,
                                       const std::vector<double>& M, const std::vector<double>& q,
                                       const std::vector<double>& fixed, std::vector<double>& T, double t0,
                                       double t1) {
  assemble(comm, ids, kept, M, fixed);
  integrate(ids, &q, T, t0, t1);
}

void number_serially(MPI_Comm comm, const std::vector<int>& owned_grid_node, UnknownNumbering& ids) {
  std::vector<int> mine;
  for (std::size_t u = 0; u < ids.owned_id.size(); ++u)
    if (ids.owned_id[u] >= 0) mine.push_back(owned_grid_node[u]);
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  const int count = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(static_cast<std::size_t>(ranks), 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<int> all(static_cast<std::size_t>(ids.global));
  MPI_Allgatherv(mine.data(), count, MPI_INT, all.data(), counts.data(), offsets.data(), MPI_INT, comm);
  std::sort(all.begin(), all.end());  // the serial unknowns: in grid-node order (thermal_assembly.cpp)
  ids.serial_id.assign(ids.owned_id.size(), -1);
  for (std::size_t u = 0; u < ids.owned_id.size(); ++u)
    if (ids.owned_id[u] >= 0)
      ids.serial_id[u] = static_cast<long>(std::lower_bound(all.begin(), all.end(), owned_grid_node[u]) - all.begin());
}

void DecomposedAssembledSolve::assemble(MPI_Comm comm, const UnknownNumbering& ids, const KeptEntries& kept,
                                        const std::vector<double>& M, const std::vector<double>& fixed) {
  problem_.reset();
  const int dim = kept.dim;
  const auto n = static_cast<PetscInt>(ids.count), N = static_cast<PetscInt>(ids.global);
  // Columns per row: two nodes of one particle's stencil (at most 3 per axis for linear, uGIMP and the
  // quadratic B-spline) differ by at most 2 along each axis, so a row meets at most 5^dim columns. A
  // hint only: a larger stencil allocates more at assembly.
  const PetscInt columns = dim == 2 ? 25 : 125;
  MatHolder K;
  petsc_check(MatCreateAIJ(comm, n, n, N, N, columns, nullptr, columns, nullptr, &K.A), "MatCreateAIJ");
  petsc_check(MatSetOption(K.A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "MatSetOption");

  // K_ij += V_p k_p G'_ip·G'_jp for each particle's kept nodes (all unknowns), summed first on this rank
  // per row i of its ghosted box in slots indexed by the lattice offset of j from i (each component in
  // [−2, 2]: 5^dim slots), in particle order as the serial assembly; then one MatSetValues per row.
  const std::vector<int>& first = *kept.first;
  const std::vector<int>& node = *kept.node;
  const std::vector<double>& G = *kept.G;
  const std::vector<double>& c = *kept.conductance;
  const std::size_t nl = ids.local_id.size();
  const int slots = dim == 2 ? 25 : 125;
  std::vector<int> row_of(nl, -1), row_node;  // compact rows: the local nodes that are unknowns
  for (std::size_t l = 0; l < nl; ++l)
    if (ids.local_id[l] >= 0.0) row_of[l] = static_cast<int>(row_node.size()), row_node.push_back(static_cast<int>(l));
  std::vector<double> acc(row_node.size() * static_cast<std::size_t>(slots), 0.0);
  const std::array<int, 3>& ext = kept.box;
  auto lattice = [&](int l, int* x) {
    for (int d = 0; d < dim; ++d) x[d] = l % ext[static_cast<std::size_t>(d)], l /= ext[static_cast<std::size_t>(d)];
  };
  auto row_at = [&](int l) {
    return &acc[static_cast<std::size_t>(row_of[static_cast<std::size_t>(l)]) * static_cast<std::size_t>(slots)];
  };
  int xyz[27][3];  // at most 27 nodes per stencil (3 per axis)
  for (std::size_t k = 0; k + 1 < first.size(); ++k) {
    if (c[k] == 0.0) continue;
    const int b = first[k], m = first[k + 1] - b;
    if (m > 27) throw std::logic_error("decomposed heat: a stencil of more than 27 nodes");
    for (int a = 0; a < m; ++a) lattice(node[static_cast<std::size_t>(b + a)], xyz[a]);
    // K is symmetric: each product once, into row a at the offset of e and into row e at the mirrored
    // offset (slots − 1 − slot); every (row, slot) still gets one term per particle, in particle order.
    for (int a = 0; a < m; ++a) {
      const double* ga = &G[static_cast<std::size_t>(dim) * static_cast<std::size_t>(b + a)];
      double* r = row_at(node[static_cast<std::size_t>(b + a)]);
      for (int e = a; e < m; ++e) {
        const double* ge = &G[static_cast<std::size_t>(dim) * static_cast<std::size_t>(b + e)];
        double dot = 0.0;
        for (int d = 0; d < dim; ++d) dot += ga[d] * ge[d];
        int slot = 0;
        for (int d = dim - 1; d >= 0; --d) slot = 5 * slot + (xyz[e][d] - xyz[a][d] + 2);
        const double kae = c[k] * dot;
        r[slot] += kae;
        if (e != a) row_at(node[static_cast<std::size_t>(b + e)])[slots - 1 - slot] += kae;
      }
    }
  }
  std::vector<PetscInt> row_cols(static_cast<std::size_t>(slots));
  std::vector<double> row_vals(static_cast<std::size_t>(slots));
  std::size_t stride[3] = {1, static_cast<std::size_t>(ext[0]), static_cast<std::size_t>(ext[0]) * static_cast<std::size_t>(ext[1])};
  for (std::size_t r = 0; r < row_node.size(); ++r) {
    const double* a = &acc[r * static_cast<std::size_t>(slots)];
    PetscInt count = 0;
    for (int sl = 0; sl < slots; ++sl) {
      if (a[sl] == 0.0) continue;
      long j = row_node[r];
      for (int d = 0, rem = sl; d < dim; ++d, rem /= 5) j += static_cast<long>(rem % 5 - 2) * static_cast<long>(stride[d]);
      row_cols[static_cast<std::size_t>(count)] = static_cast<PetscInt>(ids.local_id[static_cast<std::size_t>(j)]);
      row_vals[static_cast<std::size_t>(count)] = a[sl];
      ++count;
    }
    if (count == 0) continue;
    const auto row = static_cast<PetscInt>(ids.local_id[static_cast<std::size_t>(row_node[r])]);
    petsc_check(MatSetValues(K.A, 1, &row, count, row_cols.data(), row_vals.data(), ADD_VALUES), "MatSetValues");
  }
  petsc_check(MatAssemblyBegin(K.A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  petsc_check(MatAssemblyEnd(K.A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");

  // The owned rows with global columns, the diagonal minus the off-diagonal sum (K·1 = 0 to the
  // round-off of that sum, as thermal_assembly.cpp: the conduction part then conserves Σ M_i T_i).
  PetscInt lo = 0, hi = 0;
  petsc_check(MatGetOwnershipRange(K.A, &lo, &hi), "MatGetOwnershipRange");
  if (lo != static_cast<PetscInt>(ids.first) || hi - lo != n)
    throw std::logic_error("decomposed heat: PETSc's row ownership differs from the unknowns' numbering");
  std::vector<Eigen::Triplet<double>> entries;
  for (PetscInt r = lo; r < hi; ++r) {
    PetscInt count = 0;
    const PetscInt* cols = nullptr;
    const PetscScalar* vals = nullptr;
    petsc_check(MatGetRow(K.A, r, &count, &cols, &vals), "MatGetRow");
    double off = 0.0;
    for (PetscInt j = 0; j < count; ++j) {
      if (cols[j] == r) continue;
      entries.emplace_back(static_cast<int>(r - lo), static_cast<int>(cols[j]), vals[j]);
      off += vals[j];
    }
    entries.emplace_back(static_cast<int>(r - lo), static_cast<int>(r), -off);
    petsc_check(MatRestoreRow(K.A, r, &count, &cols, &vals), "MatRestoreRow");
  }
  entries_ = static_cast<long>(entries.size());
  thermal::SparseMatrix rows_k(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(N));
  rows_k.setFromTriplets(entries.begin(), entries.end());
  const RowSumExtremes extremes = row_sum_extremes(rows_k, static_cast<Eigen::Index>(ids.first));
  double sums[2] = {extremes.sum, extremes.diagonal};  // the largest over ranks, as one serial system's
  MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_MAX, comm);
  row_sum_residual_ = RowSumExtremes{sums[0], sums[1]}.residual();

  // M on the owned unknowns (compact, in global-id order): the window's problem, kept.
  Eigen::VectorXd mass(n);
  for (std::size_t u = 0; u < ids.owned_id.size(); ++u)
    if (ids.owned_id[u] >= 0) mass[static_cast<Eigen::Index>(ids.owned_id[u] - ids.first)] = M[u];
  problem_ = std::make_unique<thermal::DistributedProblem>(comm, static_cast<thermal::Index>(N),
                                                           static_cast<thermal::Index>(ids.first), std::move(mass),
                                                           std::move(rows_k));
  if (!ids.serial_id.empty()) {  // the power estimate's start vector by the serial numbering
    std::vector<thermal::Index> start(static_cast<std::size_t>(n));
    for (std::size_t u = 0; u < ids.owned_id.size(); ++u)
      if (ids.owned_id[u] >= 0) start[static_cast<std::size_t>(ids.owned_id[u] - ids.first)] = ids.serial_id[u];
    problem_->set_power_start_ids(std::move(start));
  }
  if (!fixed.empty())  // the serial Problem::set_dirichlet of the fixed faces' unknowns
    for (std::size_t u = 0; u < ids.owned_id.size(); ++u)
      if (ids.owned_id[u] >= 0 && !std::isnan(fixed[u]))
        problem_->set_dirichlet(static_cast<thermal::Index>(ids.owned_id[u]), fixed[u]);
}

void DecomposedAssembledSolve::set_reaction(const UnknownNumbering& ids, const thermal::ArrheniusKinetics& kinetics,
                                            const std::vector<double>& reacting_mass) {
  if (!problem_) throw std::logic_error("decomposed heat: set_reaction before assemble");
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(ids.count));
  for (std::size_t u = 0; u < ids.owned_id.size(); ++u)
    if (ids.owned_id[u] >= 0) mass[static_cast<Eigen::Index>(ids.owned_id[u] - ids.first)] = reacting_mass[u];
  problem_->set_reaction(thermal::make_reaction(kinetics, mass));
}

double DecomposedAssembledSolve::integrate_reacting(const UnknownNumbering& ids, const std::vector<double>* q,
                                                   std::vector<double>& T, std::vector<double>& progress, double t0,
                                                   double t1) {
  if (!problem_) throw std::logic_error("decomposed heat: integrate before assemble");
  const auto n = static_cast<Eigen::Index>(ids.count);
  Eigen::VectorXd temperature(n), lambda(n), source = Eigen::VectorXd::Zero(n);
  for (std::size_t u = 0; u < ids.owned_id.size(); ++u) {
    const long id = ids.owned_id[u];
    if (id < 0) continue;
    const auto i = static_cast<Eigen::Index>(id - ids.first);
    temperature[i] = T[u];
    lambda[i] = progress[u];
    if (q) source[i] = (*q)[u];
  }
  problem_->set_source(std::move(source));
  const double released0 = problem_->released_heat(lambda);
  integrator_->advance(*problem_, temperature, lambda, t0, t1);  // T and λ (the serial advance_and_map)
  const double released = problem_->released_heat(lambda) - released0;
  for (std::size_t u = 0; u < ids.owned_id.size(); ++u) {
    const long id = ids.owned_id[u];
    if (id < 0) continue;
    const auto i = static_cast<Eigen::Index>(id - ids.first);
    T[u] = temperature[i];
    progress[u] = lambda[i];
  }
  return released;
}

void DecomposedAssembledSolve::integrate(const UnknownNumbering& ids, const std::vector<double>* q,
                                         std::vector<double>& T, double t0, double t1) {
  if (!problem_) throw std::logic_error("decomposed heat: integrate before assemble");
  const auto n = static_cast<Eigen::Index>(ids.count);
  // T and q on the owned unknowns (compact, in global-id order), then the window's integration.
  Eigen::VectorXd temperature(n), source = Eigen::VectorXd::Zero(n);
  for (std::size_t u = 0; u < ids.owned_id.size(); ++u) {
    const long id = ids.owned_id[u];
    if (id < 0) continue;
    const auto i = static_cast<Eigen::Index>(id - ids.first);
    temperature[i] = T[u];
    if (q) source[i] = (*q)[u];
  }
  problem_->set_source(std::move(source));  // constant over the window: ∫ q dt = W (design §4); zero: none
  integrator_->advance(*problem_, temperature, t0, t1);
  for (std::size_t u = 0; u < ids.owned_id.size(); ++u)
    if (ids.owned_id[u] >= 0) T[u] = temperature[static_cast<Eigen::Index>(ids.owned_id[u] - ids.first)];
}

}  // namespace frictherm::coupling
