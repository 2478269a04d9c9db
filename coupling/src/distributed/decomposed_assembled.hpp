// The assembled window of a decomposed run (issue 16 item 2; decomposed_heat.hpp): the serial
// Coupler's assembled path (coupler.cpp, thermal_assembly.cpp) over the ranks. Internal header.
//
//   K_ij = Σ_p V_p k_p G'_ip · G'_jp          thermal_assembly.hpp (conduction term of eq. 37)
//
// summed over this rank's particles row by row on its ghosted box (slots by lattice offset, as the serial
// assembly), then into a PETSc MPIAIJ matrix (MatSetValues, ADD_VALUES: the rows of nodes another rank
// owns travel to that owner at MatAssemblyEnd and are added there), the
// diagonal then set to minus the off-diagonal row sum (K·1 = 0 exactly, as the serial assembly), and
// M dT/dt = −K T + q integrated over the window by a thermal::DistributedIntegrator of the serial
// name (distributed.hpp: N_Vector_Parallel, the Krylov path preconditioned by a PETSc PC).
#pragma once

#include <frictherm/thermal/distributed.hpp>

#include <mpi.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace frictherm::coupling {

/// A window's particle–unknown entries on this rank (DecomposedHeat's pass 2): particle k has the
/// entries [first[k], first[k+1]) with local node node[a] and lumped gradient G'_ip (dim values at
/// G[dim·a]); conductance[k] = V_p k_p (0: the particle conducts nothing).
struct KeptEntries {
  int dim = 2;
  std::array<int, 3> box{1, 1, 1};  // the ghosted box's nodes per direction (local numbering x fastest)
  const std::vector<int>* first = nullptr;
  const std::vector<int>* node = nullptr;
  const std::vector<double>* G = nullptr;
  const std::vector<double>* conductance = nullptr;
};

/// The unknowns' global numbering: this rank owns [first, first + count) of `global` unknowns, in
/// owned-node order; `owned_id[u]` is the global id of owned node u (−1: not an unknown), `local_id`
/// the same on the rank's ghosted box (the owners' ids, as doubles: exact below 2^53).
/// `serial_id[u]` (filled only for forward Euler's "power" estimate, whose start vector is indexed by
/// it): the serial Coupler's number of owned unknown u (the unknowns in grid-node order), −1 elsewhere.
struct UnknownNumbering {
  long global = 0, first = 0, count = 0;
  std::vector<long> owned_id;
  std::vector<double> local_id;
  std::vector<long> serial_id;
};

/// Fills ids.serial_id (collective): every rank's unknowns' grid nodes (`owned_grid_node` per owned
/// node, the serial grid numbers) gathered, an unknown's serial number the count of smaller ones.
void number_serially(MPI_Comm comm, const std::vector<int>& owned_grid_node, UnknownNumbering& ids);

class DecomposedAssembledSolve {
 public:
  /// `name`: thermal::make_distributed_integrator's (the serial names); throws std::invalid_argument
  /// for a bad name, option or preconditioner.
  DecomposedAssembledSolve(const std::string& name, const thermal::IntegratorOptions& options,
                           const std::string& preconditioner);
  ~DecomposedAssembledSolve();

  /// Collective. Assembles K from `kept`, then integrates M dT/dt = −K T + q from t0 to t1 on the
  /// unknowns: M, q and T are per owned node (read and written on the unknowns only); `fixed` per owned
  /// node (or empty: none) the temperature of an unknown held fixed (a Dirichlet row), NaN for a free
  /// one. Throws thermal::SolverError / StabilityError (every rank) when the integrator fails.
  void advance(MPI_Comm comm, const UnknownNumbering& ids, const KeptEntries& kept, const std::vector<double>& M,
               const std::vector<double>& q, const std::vector<double>& fixed, std::vector<double>& T, double t0,
               double t1);
  /// advance()'s two halves. assemble: the problem (M, K, Dirichlet rows) of the window, kept until
  /// the next assemble (the continuation integrates on the last one, as the serial Coupler keeps its
  /// Problem). integrate: from t0 to t1 on the kept problem with the source q per owned node (nullptr:
  /// none); the integrator keeps its history when t0 and T are where its last integrate left them.
  void assemble(MPI_Comm comm, const UnknownNumbering& ids, const KeptEntries& kept, const std::vector<double>& M,
                const std::vector<double>& fixed);
  void integrate(const UnknownNumbering& ids, const std::vector<double>* q, std::vector<double>& T, double t0,
                 double t1);
  /// The kept problem's Arrhenius reaction (the serial Coupler::assemble's set_reaction): Q_i = q m_i
  /// with the reacting mass m_i per owned node (thermal::make_reaction; collective).
  void set_reaction(const UnknownNumbering& ids, const thermal::ArrheniusKinetics& kinetics,
                    const std::vector<double>& reacting_mass);
  /// integrate() with the reaction's progress λ_i per owned node (read and written on the unknowns);
  /// returns the heat the reaction released over the interval, Σ_i Q_i Δλ_i over ranks (J).
  double integrate_reacting(const UnknownNumbering& ids, const std::vector<double>* q, std::vector<double>& T,
                            std::vector<double>& progress, double t0, double t1);
  bool assembled() const { return problem_ != nullptr; }
  /// A fresh integrator of the same name and options (the continuation's, as Coupler::continue_thermal):
  /// the counts so far stay in stats().
  void restart_integrator();

  thermal::IntegratorStats stats() const {
    thermal::IntegratorStats s = stats_offset_;
    s += integrator_->stats();
    return s;
  }
  std::string name() const { return integrator_->name(); }
  /// Stored entries of K's owned rows in the last window (this rank).
  long last_entries() const { return entries_; }
  /// The last assembly's max_i |(K·1)_i| / max_i K_ii over all ranks (row_sum_extremes, the serial
  /// NodalThermalSystem::row_sum_residual).
  double row_sum_residual() const { return row_sum_residual_; }

 private:
  std::string name_, preconditioner_;
  thermal::IntegratorOptions options_;
  std::unique_ptr<thermal::DistributedIntegrator> integrator_;
  thermal::IntegratorStats stats_offset_;  // of the integrators replaced by restart_integrator
  std::unique_ptr<thermal::DistributedProblem> problem_;  // the last window's
  long entries_ = 0;
  double row_sum_residual_ = 0.0;
};

}  // namespace frictherm::coupling
