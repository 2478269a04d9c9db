#pragma once
// Frictional heating and matrix-free explicit conduction in a decomposed run (issue 16): the serial
// matrix-free window (explicit_conduction.hpp, Nairn et al. 2018 eqs. 37–38) on the decomposed
// mechanics' grid and particles (frictherm/mechanics/distributed.hpp), one window per mechanics step
// (the serial "every_step" policy, gathered every window: reuse_distance 0).
//
//   M_i = Σ_p m_p C_v,p S_ip,  T_i = Σ_p m_p C_v,p T_p S_ip / M_i       eq. 38, summed over ranks
//   unknowns: M_i > active_mass_fraction · max_j M_j (max over ranks); a particle's gradient on the
//   other nodes is lumped onto its unknowns in proportion to S_ip (G', as thermal_assembly.hpp)
//   (∇T)_p = Σ_j G'_jp T_j                                              eq. 37, ghost T_j from owners
//   f_i = −Σ_p V_p k_p G'_ip · (∇T)_p                                   summed over ranks
//   T_i ← T_i + h (f_i + q_i) / M_i,  q_i = W_i / Δt,  h = Δt / n       forward Euler on owned unknowns
//   n from the bounds of λ_max(M⁻¹K) of the serial code, maxima over ranks (MPI_Allreduce)
//   T_p += Σ_i S_ip ΔT_i                                                design §4, ghost ΔT_i from owners
//
// W_i is the mechanics step's frictional work at owned nodes (N·27, 34/36, 40; second order by
// default). The particles' temperatures live in the swarm as the particle scalar named in the options
// (they migrate with the particles). Every call is collective.
//
// 2D and 3D: one class for DecomposedMpm<2> and DecomposedMpm<3> (the constructor taken fixes dim());
// the window is one template on Dim (decomposed_heat.cpp) with G'_ip stored flat, Dim per entry, so
// the 3D run is the serial ExplicitConduction<3> window as the 2D run is ExplicitConduction<2>'s.
// It also hands the run's particles to the hot-spot tracker (update_hot_spots_across_ranks) and to
// the per-rank output (DecomposedOutput) without gathering them (frictherm/coupling/distributed.hpp).
//
// Work that lands on a node that is not an unknown goes to the unknowns among its lattice neighbours in
// proportion to M_i (the serial distribute_heat); with no unknown next to it (the serial code then
// takes the nearest unknown anywhere) it is refused with std::runtime_error on every rank.
// Differences from the serial Coupler: that refusal; fixed-temperature faces, plastic and reaction
// heat, the sub-grid relaxation and the assembled / implicit paths are absent
// (docs/distributed_coupling.md).
#include <frictherm/coupling/distributed.hpp>
#include <frictherm/coupling/thermal_assembly.hpp>
#include <frictherm/mechanics/contact.hpp>
#include <frictherm/mechanics/distributed.hpp>

#include <string>
#include <vector>

namespace frictherm::coupling {

struct DecomposedHeatOptions {
  std::vector<ThermalProperties> materials;  // by the mechanics' material index
  AssemblyOptions assembly;                  // active_mass_fraction of the unknowns
  double fe_safety = 0.9;                    // h ≤ fe_safety · 2 / λ bound (thermal::IntegratorOptions)
  mechanics::HeatingOrder order = mechanics::HeatingOrder::second;
  std::string temperature = "temperature";   // the particle scalar holding T_p (K)
};

/// Energy books summed over ranks (J), as the serial EnergyBooks.
struct DecomposedHeatBooks {
  double work_received = 0.0;           // Σ over steps of the frictional work at owned nodes
  double heat_delivered = 0.0;          // Σ over windows of ∫ Σ_i q_i dt
  double heat_relocated = 0.0;          // part of the work that sat on nodes that are not unknowns
  double nodal_energy_change = 0.0;     // Σ over windows of Σ_i M_i ΔT_i
  double particle_energy_change = 0.0;  // Σ over windows of Σ_p m_p C_v,p ΔT_p
  double max_capacity_residual = 0.0;   // worst |Σ_i M_i − Σ_p m_p C_v,p| / Σ_p m_p C_v,p
  long windows = 0;
  long substeps = 0;
  long dropped_nodes = 0;               // last window: nodes with mass that are not unknowns
  long exchanges = 0;                   // grid exchanges (sum_to_owned, owned_to_local): 4 + 2 n per window (+1 relocating)
};

class DecomposedHeat {
 public:
  /// The mechanics must carry the particle scalar options.temperature. Throws std::invalid_argument
  /// (every rank) for a mechanics material without thermal properties or a bad fe_safety.
  DecomposedHeat(mechanics::DecomposedMpm<2>& mpm, DecomposedHeatOptions options);
  DecomposedHeat(mechanics::DecomposedMpm<3>& mpm, DecomposedHeatOptions options);

  int dim() const { return mpm3_ ? 3 : 2; }
  /// After a mechanics step of dt seconds: its frictional work is the heat of one window of dt.
  void after_step(double dt);
  /// One window of `dt` seconds with `joules` on the owned nodes (x fastest over owned_nodes()).
  void window(const std::vector<double>& joules, double dt);

  const DecomposedHeatBooks& books() const { return books_; }
  /// Σ_p m_p C_v,p T_p over all ranks (J).
  double heat_content() const;

  /// This rank's particles for DecomposedOutput::write (ids, x_p, v_p, T_p, materials; swarm order).
  DecomposedSnapshot snapshot() const;
  /// Collective: one update of `tracker` (built with dim()) over the particles of all ranks
  /// (update_hot_spots_across_ranks), T_p from the swarm and T0_p from the particle scalar named
  /// `reference` (carried with the particles, as T_p is).
  void update_hot_spots(HotSpotTracker& tracker, const std::string& reference, double time) const;

 private:
  template <int Dim> void check_materials(const mechanics::DecomposedMpm<Dim>& mpm);
  template <int Dim> void window_on(mechanics::DecomposedMpm<Dim>& mpm, const std::vector<double>& joules, double dt);
  template <int Dim>
  void hot_spots_on(const mechanics::DecomposedMpm<Dim>& mpm, HotSpotTracker& tracker, const std::string& reference,
                    double time) const;
  MPI_Comm communicator() const;
  mechanics::DecomposedLocalParticles local_particles() const;
  std::vector<double> temperatures() const;

  mechanics::DecomposedMpm<2>* mpm2_ = nullptr;  // one of the two
  mechanics::DecomposedMpm<3>* mpm3_ = nullptr;
  DecomposedHeatOptions opt_;
  int scalar_ = 0;
  DecomposedHeatBooks books_;
  // Per window, this rank's heat-holding particles' kept nodes (unknowns), flat: particle k's entries
  // [kept_first_[k], kept_first_[k+1]) with local node, S_ip and the lumped G'_ip (Dim values per
  // entry; sized for every stencil entry, the first kept_first_.back() used) and |G'_ip|; V_p k_p per
  // particle.
  std::vector<int> kept_first_, kept_node_;
  std::vector<double> kept_S_, kept_G_, kept_norm_, conductance_, capacity_;
  std::vector<double> local_, owned_, local_T_, force_;  // scratch
};

}  // namespace frictherm::coupling
