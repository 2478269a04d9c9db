// Distributed (MPI) thermal solve: M dT/dt = −K T + q(t), T_d fixed on Dirichlet nodes d
// (design §3 and §7, issue 16 item 2), with the nodes row-partitioned over the ranks of an MPI
// communicator. Each rank owns a contiguous range [first_row, first_row + local_size) of global
// node ids, their lumped capacities M_i, their rows of K (columns are global ids) and their
// sources. K·T needs the values of T at the columns another rank owns ("ghosts"): they are fetched
// by one PETSc VecScatter built once per layout. The integrators are the serial module's own
// (one implementation over an ODE interface, issue 32) on SUNDIALS N_Vector_Parallel vectors; the
// Krylov path is preconditioned by a PETSc PC (jacobi, bjacobi, hypre BoomerAMG) on P = I − γJ
// assembled as a parallel PETSc matrix.
//
// Built only when MPI, PETSc and SUNDIALS' nvecparallel are found (target frictherm::thermal_mpi,
// compile definition FRICTHERM_THERMAL_MPI). The Arrhenius reaction (reaction.hpp) of the owned
// nodes is carried as in the serial module: the state [s ⊙ T; λ of the free reacting nodes]
// (ode_system.hpp), GMRES and the 2×2 block-Jacobi preconditioner when it consumes its reactant;
// forward_euler's reaction sub-step limit is agreed over the ranks. Not distributed yet:
// convection and flux boundaries.
#pragma once

#include "frictherm/thermal/integrator.hpp"
#include "frictherm/thermal/reaction.hpp"
#include "frictherm/thermal/source_ramp.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <mpi.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace frictherm::thermal {

// Owns PETSc (and MPI, if not yet initialised) for the life of the object: PetscInitialize on
// construction, PetscFinalize (and MPI_Finalize if it initialised MPI) on destruction.
class PetscSession {
 public:
  PetscSession(int* argc, char*** argv);
  ~PetscSession();
  PetscSession(const PetscSession&) = delete;
  PetscSession& operator=(const PetscSession&) = delete;
};

struct RowRange {
  Index begin = 0, end = 0;  // global ids [begin, end)
  Index size() const { return end - begin; }
};

// The balanced contiguous split: rank r owns [r·N/P, (r+1)·N/P) (integer division). Collective-free.
RowRange partition_rows(Index global_size, MPI_Comm comm);

// Counts of MPI traffic, this rank's view. Ghost values are what one exchange (one K·v) moves.
struct CommunicationStats {
  long ghost_exchanges = 0;     // VecScatter forward calls (one per K·v or J·v)
  long reductions = 0;          // MPI_Allreduce calls made by N_Vector reductions and by the books
  Index ghosts_received = 0;    // values this rank receives per exchange
  Index ghosts_sent = 0;        // values this rank sends per exchange
  int neighbours = 0;           // ranks this rank receives ghosts from
};

class DistributedProblem {
 public:
  // Collective. mass: M_i of the owned nodes [J/K], all > 0 and finite. conductance: the owned
  // rows of K, size local × global_size, global column ids, finite with non-negative diagonal
  // (K symmetric positive semi-definite with zero row sums for closed energy books; symmetry
  // across ranks is the caller's duty: it is not checked). The owned ranges of all ranks must
  // tile [0, global_size) in rank order. Throws std::invalid_argument naming the bad input.
  // PETSc must be initialised (PetscSession).
  DistributedProblem(MPI_Comm comm, Index global_size, Index first_row, Eigen::VectorXd mass,
                     SparseMatrix conductance);
  ~DistributedProblem();
  DistributedProblem(const DistributedProblem&) = delete;
  DistributedProblem& operator=(const DistributedProblem&) = delete;

  MPI_Comm comm() const { return comm_; }
  int rank() const { return rank_; }
  Index global_size() const { return global_size_; }
  Index local_size() const { return mass_.size(); }
  Index first_row() const { return first_; }
  bool owns(Index global) const { return global >= first_ && global < first_ + local_size(); }
  const Eigen::VectorXd& mass() const { return mass_; }
  const SparseMatrix& conductance() const { return k_; }  // owned rows, global columns

  // ---- sources q(t) [W per owned node], constant or linear over [t0, t1] as in Problem ----
  void set_source(Eigen::VectorXd q);
  void set_source_ramp(Eigen::VectorXd q0, Eigen::VectorXd q1, double t0, double t1);
  // q(t) on the owned nodes (zero on Dirichlet nodes).
  void source(double t, Eigen::Ref<Eigen::VectorXd> q) const;

  // ---- Dirichlet nodes: global ids this rank owns (else invalid_argument) ----
  void set_dirichlet(Index global_node, double temperature);
  bool is_dirichlet_local(Index local) const { return fixed_[static_cast<std::size_t>(local)] != 0; }
  void apply_dirichlet(Eigen::Ref<Eigen::VectorXd> temperature) const;

  // ---- Arrhenius reaction (reaction.hpp): Q_i per owned node (heat.size() == local_size()) ----
  // Collective (the same kinetics on every rank; a rank's bad Q throws on every rank).
  void set_reaction(Reaction reaction);
  bool has_reaction() const { return has_reaction_; }
  bool reaction_consumes() const { return has_reaction_ && reaction_.consume; }
  const Reaction& reaction() const { return reaction_; }
  // Σ_i Q_i λ_i over all ranks [J] (collective; progress per owned node; 0 without a reaction).
  double released_heat(const Eigen::VectorXd& progress) const;

  // ---- evaluation (collective: each call exchanges ghosts once) ----
  // w = −K T + q(t) on owned free nodes, 0 on Dirichlet nodes [W]. T, w: owned values.
  void heat_rate(double t, const double* temperature, double* w) const;
  // The ghost values of an owned vector x (one VecScatter): the returned array is indexed like
  // ghost_ids() and stays valid until the next exchange.
  const double* exchange(const double* x) const;
  const std::vector<Index>& ghost_ids() const { return ghost_ids_; }
  // Local CSR of the owned rows with column c < local_size() an owned node and c ≥ local_size()
  // ghost c − local_size(); entries in K's original column order.
  const std::vector<Index>& row_start() const { return row_start_; }
  const std::vector<Index>& local_col() const { return local_col_; }

  // ---- energy books (collective: one MPI_Allreduce each) ----
  double thermal_energy(const Eigen::VectorXd& temperature) const;  // Σ_i M_i T_i over all ranks [J]
  double source_heat(double t0, double t1) const;  // ∫ Σ_free q dt over [t0, t1], exact [J]
  // Global λ_max Gershgorin bound of M⁻¹K over free rows (what forward_euler uses).
  double lambda_max_gershgorin() const;
  // Global λ_max of M⁻¹K over free rows by the serial power iteration (stability.hpp: the same
  // start vector, iterations and Rayleigh quotient; one ghost exchange and two reductions per
  // iteration), the estimate "power" of forward_euler. The start vector is indexed by the rows'
  // serial ids (set_power_start_ids; default: the global ids).
  double lambda_max_power(int iterations = 200) const;
  // The serial module's node id of each owned row (a caller whose ranks number the nodes otherwise
  // than the serial Problem), for lambda_max_power's start vector.
  void set_power_start_ids(std::vector<Index> ids);

  // Changes when M, K or a Dirichlet node changes (not sources): integrators rebuild then.
  std::uint64_t revision() const { return revision_; }
  CommunicationStats communication() const;  // ghost counts and exchanges so far
  // Adds n to the reduction counter of this process (used by the N_Vector counting wrappers).
  static void count_reductions(long n);
  static long reductions();

 private:
  void build_ghosts();
  void fail(const std::string& what) const;

  MPI_Comm comm_;
  int rank_ = 0, ranks_ = 1;
  Index global_size_ = 0, first_ = 0;
  Eigen::VectorXd mass_;
  SparseMatrix k_;
  SourceRamp source_;
  bool has_reaction_ = false;
  Reaction reaction_;
  std::vector<unsigned char> fixed_;
  std::vector<Index> dirichlet_local_;
  Eigen::VectorXd fixed_value_;
  std::vector<Index> ghost_ids_, row_start_, local_col_;
  std::vector<Index> power_start_ids_;  // empty: the global ids
  Index ghosts_sent_ = 0;
  int neighbours_ = 0;
  // PETSc objects (Vec, VecScatter) kept opaque here: petscvec.h stays out of this header.
  struct Petsc;
  std::unique_ptr<Petsc> petsc_;
  mutable std::vector<double> ghost_values_;
  mutable long exchanges_ = 0;
  std::uint64_t revision_ = 0;
};

struct DistributedOptions {
  IntegratorOptions integrator;  // rtol, atol, max_steps, krylov_maxl, fe_* as in the serial module
  // Implicit integrators: "pcg" (default; CG on the symmetric form y = M^{1/2}T) or "gmres"
  // (SPGMR, same form). "klu" (the serial sparse direct solve) is PCG preconditioned by MUMPS' sparse
  // direct LU of P = I − γJ over the ranks (the preconditioner below is then "mumps").
  // cvode_adams: "fixed_point" (default) or a Krylov solver as above.
  // PETSc preconditioner of P = I − γJ, one application per Krylov iteration: "jacobi" (default,
  // the serial module's), "bjacobi" (one ILU(0) block per rank), "hypre" (BoomerAMG V-cycle) or
  // "mumps" (PCLU with MATSOLVERMUMPS: P factored, refactored when γ changes).
  std::string preconditioner = "jacobi";
};

// Cumulative energy books of an integrator (summed over ranks): Σ M T at the start of its first
// window and after its last, and the source heat ∫ Σ q dt delivered. For an insulated problem
// (no Dirichlet nodes, K with zero row sums) stored − initial_stored = source_heat.
struct EnergyBooks {
  double initial_stored = 0.0;
  double stored = 0.0;
  double source_heat = 0.0;
  double imbalance() const { return stored - initial_stored - source_heat; }
};

namespace detail {
class Scheme;
class DistributedThermalOde;
}  // namespace detail

// The serial module's integrators (one implementation, thermal/src/scheme.hpp) on the
// DistributedProblem's owned rows.
class DistributedIntegrator {
 public:
  DistributedIntegrator(const DistributedIntegrator&) = delete;
  DistributedIntegrator& operator=(const DistributedIntegrator&) = delete;
  ~DistributedIntegrator();

  // Collective. Integrates from t0 to t1 (t1 ≥ t0), T holding the owned temperatures (written
  // with the Dirichlet values first). Throws std::invalid_argument for bad input, SolverError /
  // StabilityError on failure (on every rank; T is then left unchanged).
  void advance(const DistributedProblem& problem, Eigen::VectorXd& T, double t0, double t1);
  // The same with the reaction's progress λ per owned node (read and written on the free reacting
  // nodes; the serial Integrator::advance with progress). Without it a reacting problem starts from
  // fresh material (λ = 0) every window.
  void advance(const DistributedProblem& problem, Eigen::VectorXd& T, Eigen::VectorXd& progress, double t0,
               double t1);
  std::string name() const;

  const IntegratorStats& stats() const { return stats_; }  // global counts (same on all ranks)
  const EnergyBooks& books() const { return books_; }
  // This rank's traffic during advance() calls so far.
  const CommunicationStats& communication() const { return comm_; }

 private:
  friend std::unique_ptr<DistributedIntegrator> make_distributed_integrator(const std::string&,
                                                                           const DistributedOptions&);
  DistributedIntegrator(std::unique_ptr<detail::Scheme> scheme, const std::string& preconditioner);
  void window(const DistributedProblem& problem, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0, double t1);

  std::unique_ptr<detail::DistributedThermalOde> ode_;  // the SUNDIALS callbacks' user data:
  std::unique_ptr<detail::Scheme> scheme_;              // freed first
  IntegratorStats stats_;
  EnergyBooks books_;
  bool books_started_ = false;
  CommunicationStats comm_;
};

// Names: those of the serial module (integrator_names()): forward_euler, cvode_bdf,
// cvode_adams, arkode_erk, arkode_dirk. Throws std::invalid_argument for an unknown name, a bad
// option or an unknown preconditioner (listing the valid ones).
std::unique_ptr<DistributedIntegrator> make_distributed_integrator(const std::string& name,
                                                                   const DistributedOptions& options = {});

}  // namespace frictherm::thermal
