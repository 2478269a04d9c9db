// Row-partitioned conduction problem (distributed.hpp): layout checks, the ghost VecScatter,
// the nodal heat rate w = −K T + q(t) (eq. 37 right-hand side) and the energy books.
#include "frictherm/thermal/distributed.hpp"
#include "frictherm/thermal/stability.hpp"

#include "petsc_check.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

namespace frictherm::thermal {

namespace {
std::atomic<std::uint64_t> next_revision{1};
std::atomic<long> reduction_count{0};
}  // namespace

// ---- PetscSession ----
PetscSession::PetscSession(int* argc, char*** argv) {
  detail::petsc_check(PetscInitialize(argc, argv, nullptr, nullptr), "PetscInitialize");
}
PetscSession::~PetscSession() { PetscFinalize(); }

RowRange partition_rows(Index global_size, MPI_Comm comm) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  return {global_size * rank / ranks, global_size * (rank + 1) / ranks};
}

struct DistributedProblem::Petsc {
  Vec owned = nullptr;   // MPI layout of the owned values, array placed per exchange
  Vec ghost = nullptr;   // sequential, over ghost_values_
  VecScatter scatter = nullptr;
  ~Petsc() {
    VecScatterDestroy(&scatter);
    VecDestroy(&ghost);
    VecDestroy(&owned);
  }
};

void DistributedProblem::count_reductions(long n) { reduction_count += n; }
long DistributedProblem::reductions() { return reduction_count.load(); }

void DistributedProblem::fail(const std::string& what) const {
  throw std::invalid_argument("DistributedProblem (rank " + std::to_string(rank_) + "): " + what);
}

DistributedProblem::DistributedProblem(MPI_Comm comm, Index global_size, Index first_row, Eigen::VectorXd mass,
                                       SparseMatrix conductance)
    : comm_(comm), global_size_(global_size), first_(first_row), mass_(std::move(mass)), k_(std::move(conductance)) {
  PetscBool up = PETSC_FALSE;
  PetscInitialized(&up);
  if (!up) throw std::logic_error("DistributedProblem: PETSc is not initialised (create a PetscSession first)");
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &ranks_);
  const Index n = local_size();
  // Local checks first, then one agreement so that every rank throws (no rank left waiting).
  std::ostringstream bad;
  if (k_.rows() != n || k_.cols() != global_size_) {
    bad << "conductance has " << k_.rows() << "x" << k_.cols() << " entries, expected the owned rows " << n << "x"
        << global_size_;
  }
  for (Index i = 0; i < n && bad.tellp() == 0; ++i) {
    if (!(std::isfinite(mass_[i]) && mass_[i] > 0.0)) bad << "mass of node " << first_ + i << " is " << mass_[i] << ", expected > 0";
  }
  k_.makeCompressed();
  // A diagonal below zero by more than round-off (kConductanceRoundOff of the largest |K| entry on
  // any rank, as thermal::Problem).
  double kmax = 0.0;
  for (Index e = 0; e < k_.nonZeros(); ++e) kmax = std::max(kmax, std::abs(k_.valuePtr()[e]));
  MPI_Allreduce(MPI_IN_PLACE, &kmax, 1, MPI_DOUBLE, MPI_MAX, comm_);  // (NaN entries are refused below)
  const double diagonal_tol = kConductanceRoundOff * kmax;
  for (Index i = 0; i < k_.rows() && bad.tellp() == 0; ++i) {
    for (SparseMatrix::InnerIterator it(k_, i); it; ++it) {
      if (!std::isfinite(it.value())) bad << "conductance row " << first_ + i << " has a non-finite entry";
      if (it.col() == i + first_ && it.value() < -diagonal_tol)
        bad << "conductance row " << first_ + i << " has a negative diagonal " << it.value() << " (tolerance "
            << diagonal_tol << ")";
    }
  }
  // Layout: the owned ranges tile [0, N) in rank order.
  std::vector<long> firsts(static_cast<std::size_t>(ranks_)), sizes(static_cast<std::size_t>(ranks_));
  const long my_first = static_cast<long>(first_), my_size = static_cast<long>(n);
  MPI_Allgather(&my_first, 1, MPI_LONG, firsts.data(), 1, MPI_LONG, comm_);
  MPI_Allgather(&my_size, 1, MPI_LONG, sizes.data(), 1, MPI_LONG, comm_);
  long next = 0;
  for (int r = 0; r < ranks_; ++r) {
    if (firsts[static_cast<std::size_t>(r)] != next && bad.tellp() == 0) {
      bad << "rank " << r << " starts at node " << firsts[static_cast<std::size_t>(r)] << ", expected " << next
          << " (owned ranges must tile [0, global_size) in rank order)";
    }
    next += sizes[static_cast<std::size_t>(r)];
  }
  if (next != static_cast<long>(global_size_) && bad.tellp() == 0) {
    bad << "the owned ranges hold " << next << " nodes, expected global_size = " << global_size_;
  }
  int local_bad = bad.tellp() == 0 ? 0 : 1, any_bad = 0;
  MPI_Allreduce(&local_bad, &any_bad, 1, MPI_INT, MPI_MAX, comm_);
  if (local_bad) fail(bad.str());
  if (any_bad) fail("another rank rejected its part of the problem");

  fixed_.assign(static_cast<std::size_t>(n), 0);
  fixed_value_ = Eigen::VectorXd::Zero(n);
  source_.q0 = source_.q1 = Eigen::VectorXd::Zero(n);

  // Owner of each ghost for the traffic figures.
  std::vector<int> owner_of_count(static_cast<std::size_t>(ranks_), 0);
  build_ghosts();
  for (Index g : ghost_ids_) {
    const auto it = std::upper_bound(firsts.begin(), firsts.end(), static_cast<long>(g));
    ++owner_of_count[static_cast<std::size_t>(it - firsts.begin() - 1)];
  }
  neighbours_ = 0;
  for (int c : owner_of_count) neighbours_ += c > 0 ? 1 : 0;
  int sent = 0;  // values the other ranks ask of this one per exchange
  MPI_Reduce_scatter_block(owner_of_count.data(), &sent, 1, MPI_INT, MPI_SUM, comm_);
  ghosts_sent_ = sent;
  revision_ = next_revision++;
}

DistributedProblem::~DistributedProblem() = default;

void DistributedProblem::build_ghosts() {
  const Index n = local_size();
  std::set<Index> ghosts;
  for (Index e = 0; e < k_.nonZeros(); ++e) {
    const Index c = k_.innerIndexPtr()[e];
    if (!owns(c)) ghosts.insert(c);
  }
  ghost_ids_.assign(ghosts.begin(), ghosts.end());
  row_start_.assign(k_.outerIndexPtr(), k_.outerIndexPtr() + n + 1);
  local_col_.resize(static_cast<std::size_t>(k_.nonZeros()));
  for (Index e = 0; e < k_.nonZeros(); ++e) {
    const Index c = k_.innerIndexPtr()[e];
    local_col_[static_cast<std::size_t>(e)] =
        owns(c) ? c - first_
                : n + static_cast<Index>(std::lower_bound(ghost_ids_.begin(), ghost_ids_.end(), c) - ghost_ids_.begin());
  }
  const auto ng = static_cast<PetscInt>(ghost_ids_.size());
  ghost_values_.assign(ghost_ids_.size() + 1, 0.0);  // +1: a valid pointer when there is no ghost
  petsc_ = std::make_unique<Petsc>();
  using detail::petsc_check;
  petsc_check(VecCreateMPIWithArray(comm_, 1, static_cast<PetscInt>(n), static_cast<PetscInt>(global_size_), nullptr,
                                    &petsc_->owned),
              "VecCreateMPIWithArray");
  petsc_check(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, ng, ghost_values_.data(), &petsc_->ghost),
              "VecCreateSeqWithArray");
  std::vector<PetscInt> from(ghost_ids_.begin(), ghost_ids_.end());
  IS is_from = nullptr, is_to = nullptr;
  petsc_check(ISCreateGeneral(PETSC_COMM_SELF, ng, from.data(), PETSC_COPY_VALUES, &is_from), "ISCreateGeneral");
  petsc_check(ISCreateStride(PETSC_COMM_SELF, ng, 0, 1, &is_to), "ISCreateStride");
  petsc_check(VecScatterCreate(petsc_->owned, is_from, petsc_->ghost, is_to, &petsc_->scatter), "VecScatterCreate");
  ISDestroy(&is_from);
  ISDestroy(&is_to);
}

const double* DistributedProblem::exchange(const double* x) const {
  using detail::petsc_check;
  // SCATTER_FORWARD only reads the owned array.
  petsc_check(VecPlaceArray(petsc_->owned, const_cast<double*>(x)), "VecPlaceArray");
  petsc_check(VecScatterBegin(petsc_->scatter, petsc_->owned, petsc_->ghost, INSERT_VALUES, SCATTER_FORWARD),
              "VecScatterBegin");
  petsc_check(VecScatterEnd(petsc_->scatter, petsc_->owned, petsc_->ghost, INSERT_VALUES, SCATTER_FORWARD),
              "VecScatterEnd");
  petsc_check(VecResetArray(petsc_->owned), "VecResetArray");
  ++exchanges_;
  return ghost_values_.data();
}

CommunicationStats DistributedProblem::communication() const {
  CommunicationStats s;
  s.ghost_exchanges = exchanges_;
  s.reductions = reductions();
  s.ghosts_received = static_cast<Index>(ghost_ids_.size());
  s.ghosts_sent = ghosts_sent_;
  s.neighbours = neighbours_;
  return s;
}

void DistributedProblem::set_source(Eigen::VectorXd q) {
  if (q.size() != local_size() || !q.allFinite()) {
    fail("set_source: need " + std::to_string(local_size()) + " finite owned values [W]");
  }
  source_.set_constant(std::move(q));
}

void DistributedProblem::set_source_ramp(Eigen::VectorXd q0, Eigen::VectorXd q1, double t0, double t1) {
  if (q0.size() != local_size() || q1.size() != local_size() || !q0.allFinite() || !q1.allFinite()) {
    fail("set_source_ramp: need q0, q1 with " + std::to_string(local_size()) + " finite owned values [W]");
  }
  if (!(std::isfinite(t0) && std::isfinite(t1) && t1 > t0)) fail("set_source_ramp: need finite t1 > t0");
  source_.set_ramp(std::move(q0), std::move(q1), t0, t1);
}

void DistributedProblem::source(double t, Eigen::Ref<Eigen::VectorXd> q) const {
  source_.evaluate(t, q);  // as Problem::transport_heat_rate
  for (Index d : dirichlet_local_) q[d] = 0.0;
}

void DistributedProblem::set_dirichlet(Index global_node, double temperature) {
  if (!owns(global_node)) {
    fail("set_dirichlet: node " + std::to_string(global_node) + " is not owned by this rank (owned: [" +
         std::to_string(first_) + ", " + std::to_string(first_ + local_size()) + "))");
  }
  if (!std::isfinite(temperature)) fail("set_dirichlet: temperature must be finite (K)");
  const Index i = global_node - first_;
  if (!fixed_[static_cast<std::size_t>(i)]) dirichlet_local_.push_back(i);
  fixed_[static_cast<std::size_t>(i)] = 1;
  fixed_value_[i] = temperature;
  revision_ = next_revision++;
}

void DistributedProblem::set_reaction(Reaction reaction) {
  std::string bad;
  if (reaction.heat.size() != local_size())
    bad = "set_reaction: " + std::to_string(reaction.heat.size()) + " heats Q_i for " + std::to_string(local_size()) +
          " owned nodes";
  else if (!reaction.heat.allFinite() || (reaction.heat.size() > 0 && reaction.heat.minCoeff() < 0.0))
    bad = "set_reaction: the heats Q_i must be finite and >= 0 (J)";
  else if (!(reaction.prefactor > 0.0 && reaction.activation_temperature > 0.0) || !std::isfinite(reaction.prefactor) ||
           !std::isfinite(reaction.activation_temperature))
    bad = "set_reaction: need finite Z > 0 and Θ > 0";
  int local_bad = bad.empty() ? 0 : 1, any_bad = 0;
  MPI_Allreduce(&local_bad, &any_bad, 1, MPI_INT, MPI_MAX, comm_);
  if (local_bad) fail(bad);
  if (any_bad) fail("another rank rejected its part of the reaction");
  reaction_ = std::move(reaction);
  has_reaction_ = true;
  revision_ = next_revision++;
}

double DistributedProblem::released_heat(const Eigen::VectorXd& progress) const {
  double local = 0.0, global = 0.0;
  if (has_reaction_) {
    if (progress.size() != local_size()) fail("released_heat: progress has the wrong size");
    local = reaction_.heat.dot(progress);
  }
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, comm_);
  count_reductions(1);
  return global;
}

void DistributedProblem::apply_dirichlet(Eigen::Ref<Eigen::VectorXd> temperature) const {
  for (Index d : dirichlet_local_) temperature[d] = fixed_value_[d];
}

void DistributedProblem::heat_rate(double t, const double* temperature, double* w) const {
  const double* g = exchange(temperature);
  const Index n = local_size();
  const double* kv = k_.valuePtr();
  double s = 0.0;
  const bool ramp = source_.ramped();
  if (ramp) s = source_.fraction(t);
  const double* q0 = source_.q0.data();
  const double* q1 = source_.q1.data();
  for (Index i = 0; i < n; ++i) {
    if (fixed_[static_cast<std::size_t>(i)]) {
      w[i] = 0.0;
      continue;
    }
    double acc = 0.0;  // (K T)_i in K's column order, as the serial product
    for (Index e = row_start_[static_cast<std::size_t>(i)]; e < row_start_[static_cast<std::size_t>(i) + 1]; ++e) {
      const Index c = local_col_[static_cast<std::size_t>(e)];
      acc += kv[e] * (c < n ? temperature[c] : g[c - n]);
    }
    double wi = -acc;
    if (source_.active) wi += ramp ? (1.0 - s) * q0[i] + s * q1[i] : q0[i];
    w[i] = wi;
  }
}

double DistributedProblem::thermal_energy(const Eigen::VectorXd& temperature) const {
  if (temperature.size() != local_size()) fail("thermal_energy: temperature has the wrong size");
  double local = mass_.dot(temperature), global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, comm_);
  count_reductions(1);
  return global;
}

double DistributedProblem::source_heat(double t0, double t1) const {
  // q is piecewise linear in t (kinks at the ramp ends): the midpoint rule is exact per piece.
  double local = 0.0;
  if (source_.active && t1 > t0) {
    std::vector<double> cuts{t0};
    if (source_.ramped()) {
      for (double c : {source_.t0, source_.t1}) {
        if (c > t0 && c < t1) cuts.push_back(c);
      }
    }
    cuts.push_back(t1);
    Eigen::VectorXd q(local_size());
    for (std::size_t p = 0; p + 1 < cuts.size(); ++p) {
      source(0.5 * (cuts[p] + cuts[p + 1]), q);
      local += (cuts[p + 1] - cuts[p]) * q.sum();
    }
  }
  double global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, comm_);
  count_reductions(1);
  return global;
}

double DistributedProblem::lambda_max_gershgorin() const {
  double lam = 0.0;  // as thermal::lambda_max_gershgorin, over the owned free rows
  for (Index i = 0; i < local_size(); ++i) {
    if (fixed_[static_cast<std::size_t>(i)]) continue;
    double row = 0.0;
    for (SparseMatrix::InnerIterator it(k_, i); it; ++it) row += std::abs(it.value());
    lam = std::max(lam, row / mass_[i]);
  }
  double global = 0.0;
  MPI_Allreduce(&lam, &global, 1, MPI_DOUBLE, MPI_MAX, comm_);
  count_reductions(1);
  return global;
}

void DistributedProblem::set_power_start_ids(std::vector<Index> ids) {
  if (static_cast<Index>(ids.size()) != local_size())
    fail("set_power_start_ids: " + std::to_string(ids.size()) + " ids for " + std::to_string(local_size()) +
         " owned nodes");
  power_start_ids_ = std::move(ids);
}

double DistributedProblem::lambda_max_power(int iterations) const {
  // thermal::lambda_max_power on the owned rows: S v = P M^{-1/2} K M^{-1/2} P v (no convection here),
  // the dot products and norms summed over ranks.
  const Index n = local_size();
  const Eigen::VectorXd rsm = mass_.cwiseSqrt().cwiseInverse();
  Eigen::VectorXd free = Eigen::VectorXd::Ones(n);
  for (Index d : dirichlet_local_) free[d] = 0.0;
  const double* kv = k_.valuePtr();
  auto apply = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
    const Eigen::VectorXd u = rsm.cwiseProduct(free.cwiseProduct(v));
    const double* g = exchange(u.data());
    for (Index i = 0; i < n; ++i) {
      double acc = 0.0;  // (K u)_i in K's column order
      for (Index e = row_start_[static_cast<std::size_t>(i)]; e < row_start_[static_cast<std::size_t>(i) + 1]; ++e) {
        const Index c = local_col_[static_cast<std::size_t>(e)];
        acc += kv[e] * (c < n ? u[c] : g[c - n]);
      }
      out[i] = free[i] * (rsm[i] * acc);
    }
  };
  auto dot = [this](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    double local = a.dot(b), global = 0.0;
    MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, comm_);
    count_reductions(1);
    return global;
  };
  auto norm = [&](const Eigen::VectorXd& a) { return std::sqrt(dot(a, a)); };
  Eigen::VectorXd v(n);
  for (Index i = 0; i < n; ++i)
    v[i] = power_iteration_start(power_start_ids_.empty() ? first_ + i : power_start_ids_[static_cast<std::size_t>(i)]);
  return power_iteration(Eigen::VectorXd(free.cwiseProduct(v)), iterations, apply, dot, norm);
}

}  // namespace frictherm::thermal
