#pragma once
// Matrix-free explicit conduction for one coupling window (issue 13 item 1), as the reference code
// NairnMPM does: lumped nodal heat capacities, the nodal conduction force from the particles'
// temperature gradients, forward-Euler sub-steps, no K assembled.
//
//   M_i = Σ_p m_p C_v,p S_ip,  T_i = Σ_p m_p C_v,p T_p S_ip / M_i       Nairn et al. 2018 eq. 38
//   (∇T)_p = Σ_j G'_jp T_j                                             eq. 37 (gradient on the particle)
//   f_i = −Σ_p V_p k_p G'_ip · (∇T)_p   (= −(K T)_i with K_ij = Σ_p V_p k_p G'_ip·G'_jp)
//   T_i ← T_i + h (f_i + q_i) / M_i,  h = window / n                    forward Euler
//   T_p += Σ_i S_ip ΔT_i                                                design §4
//
// G' is the gradient with the weights of nodes that are not thermal unknowns lumped onto the kept
// ones in proportion to S_ip, exactly as thermal_assembly.hpp builds K, so both paths integrate the
// same semi-discrete system and differ by round-off (one sub-step each). The sub-step count n comes
// from bounds of λ_max(M⁻¹K) computed in the same particle pass (the smaller of a Gershgorin bound,
//   Σ_j |K_ij| ≤ Σ_p V_p k_p |G'_ip| Σ_j |G'_jp|,
// and a Cauchy–Schwarz bound, λ ≤ max_i Σ_{p∋i} V_p k_p Σ_a |G'_ap|²/M_a), h ≤ safety · 2 / λ. Without
// K's cancellations they can be ~2× above the Gershgorin estimate the assembled path takes from K
// itself (linear, uGIMP) or below it (quadratic B-spline), so a window near the limit may take a
// different number of sub-steps here.
// Energy: Σ_i M_i ΔT_i = Σ_i q_i window + Σ_i h f_i, and Σ_i f_i = −Σ_p V_p k_p (Σ_i G'_ip)·(∇T)_p
// vanishes to round-off (Σ_i G'_ip = 0: partition of unity, the lumping keeps it).
#include <frictherm/coupling/thermal_assembly.hpp>
#include <frictherm/mechanics/grid.hpp>
#include <frictherm/mechanics/particles.hpp>
#include <frictherm/mechanics/shape_functions.hpp>

#include <Eigen/Core>

#include <cstddef>
#include <type_traits>
#include <vector>

namespace frictherm::coupling {

/// A node held at a fixed temperature (an unknown on a fixed-temperature face).
struct FixedNode {
  int unknown = 0;
  double temperature = 0.0;  // K
};

template <int Dim>
class ExplicitConduction {
 public:
  /// Pass over the particles at their current positions: stencils (kept for the map back), M and T
  /// on every node and the unknowns into `sys` (its conductance is left empty), the gradients G'
  /// with the dropped nodes lumped, and the bounds of M⁻¹K. Throws std::invalid_argument
  /// like assemble_thermal for a material id without thermal properties or no conducting particle.
  /// `stencils`: the MPM step's stencils at these positions (mechanics::Simulation::current_stencils),
  /// read instead of evaluating them again (same numbers); an empty view evaluates them here.
  void gather(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles,
              mechanics::ShapeKind shape, const std::vector<ThermalProperties>& materials,
              const AssemblyOptions& options, NodalThermalSystem& sys,
              const mechanics::StencilView<Dim>& stencils = {});

  /// What refresh() did.
  enum class Refresh {
    kept,       // no particle moved more than max_shift: the last gather serves this window as it is
    refreshed,  // the moved particles were gathered again at their positions, the others kept
    regather,   // a full gather() is needed (none made yet, particles added, too many moved, or the
                // unknowns would change); the kept state is then unusable until gather()
  };
  /// Reuse of the last gather (coupling.reuse_distance): a particle whose position differs from the
  /// one it was last gathered at by more than `max_shift` (m, along any axis) is gathered again —
  /// its old weights taken out of M_i and of the bounds, its stencil at its current position put in
  /// (from `stencils` when given, same numbers) — while the others keep theirs, so no particle's
  /// weights lag its position by more than max_shift and a window costs a pass over the particles
  /// that moved. M_i stays Σ_p m_p C_v,p S_ip over the kept weights to round-off, so the energy
  /// books stay exact. A full gather is asked for when more than a quarter of the heat-holding
  /// particles moved (cheaper) or when a node would become or stop being an unknown.
  Refresh refresh(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles,
                  mechanics::ShapeKind shape, const std::vector<ThermalProperties>& materials,
                  const AssemblyOptions& options, NodalThermalSystem& sys, double max_shift,
                  const mechanics::StencilView<Dim>& stencils = {});

  /// With the kept stencils and M (refresh() kept or refreshed): T_i from the current particle
  /// temperatures (eq. 38) into sys.temperature. M, the unknowns and the bounds stay. The sums
  /// Σ_p m_p C_v,p T_p S_ip are kept up to date by the gather, refresh() and map_back() (which adds
  /// m_p C_v,p ΔT_p S_ip for the particles it changes): nothing but the coupler may change particle
  /// temperatures between matrix-free windows.
  void reproject(const mechanics::Particles<Dim>& particles, NodalThermalSystem& sys);

  /// Upper bound of the largest eigenvalue of M⁻¹K over the free unknowns of the gathered system
  /// (1/s); 0 without conduction.
  double lambda_bound(const NodalThermalSystem& sys, const std::vector<FixedNode>& fixed) const;

  /// n forward-Euler sub-steps over `window` seconds from `temperature` (on the unknowns of the
  /// gathered system), with the constant source q = joules / window (W). Fixed nodes take their
  /// temperature first and keep it. Returns the temperatures at the end. A particle whose nodal
  /// temperatures agree to round-off (relative spread ≤ 256 ε) carries no flux; it is looked at again
  /// only when one of its nodes changes.
  Eigen::VectorXd advance(const NodalThermalSystem& sys, const Eigen::VectorXd& temperature,
                          const Eigen::VectorXd& joules, const std::vector<FixedNode>& fixed, double window,
                          long substeps);

  /// T_p += Σ_i S_ip ΔT_i with the stencils of the gather (same positions), and the optional sub-grid
  /// relaxation of add_nodal_change_to_particles (β, nodal end temperatures). Also adds
  /// m_p C_v,p ΔT_p S_ip to the sums of the next reproject(). Particles with no unknown of ΔT_i ≠ 0
  /// in the range of their unknowns keep their temperature exactly and are passed over.
  void map_back(mechanics::Particles<Dim>& particles, const NodalThermalSystem& sys, const Eigen::VectorXd& delta,
                double relaxation, const Eigen::VectorXd* end);

 private:
  static constexpr int capacity = Dim == 2 ? 9 : 27;  // the widest stencil: 3 nodes per axis
  /// One heat-holding particle's state of its last gather besides its stencil (kept whole: the 1D
  /// weights and derivatives, ~170 bytes in 3D): its nodes that are unknowns are those of its stencil
  /// with sys.unknown >= 0, in stencil order, S_ip and G_ip are evaluated again from the kept
  /// weights (the same products, so the same numbers) and G' lumped with s_kept and g_dropped. Each
  /// pass thus streams ~300 bytes per particle in 3D instead of expanded lists of ~1100 (issue 35).
  struct Kept {
    double heat_capacity = 0.0;  // m_p C_v,p (J/K)
    double conductance = 0.0;    // V_p k_p (W m/K): times G'·G' gives W/K; 0: carries no flux
    double rayleigh = 0.0;       // V_p k_p Σ_a |G'_ap|²/M_a as added to rayleigh_bound_ (M of that time)
    double s_kept = 0.0;         // Σ S_ip over its unknowns
    mechanics::Vec<Dim> g_dropped = mechanics::Vec<Dim>::Zero();  // Σ G_ip over its other nodes
    int count = 0;               // its nodes that are unknowns (0: holds no heat or reaches none)
    int lumped = 0;              // some node dropped: G'_ip = G_ip + (S_ip / s_kept) g_dropped
  };
  /// A particle's unknowns, S_ip and (when asked) G'_ip, in stencil order: the lists of its gather.
  struct Expanded {
    int count = 0;
    int unknown[capacity];
    double S[capacity];
    double G[Dim][capacity];  // by component (scalar stores: Vec temporaries through memory stalled)
    mechanics::Vec<Dim> g(int a) const {
      if constexpr (Dim == 2) return mechanics::Vec<Dim>(G[0][a], G[1][a]);
      else return mechanics::Vec<Dim>(G[0][a], G[1][a], G[2][a]);
    }
  };
  template <class Kernel>
  using StencilVector = std::vector<mechanics::Stencil<Dim, Kernel>>;
  /// Per-particle stencils of one of the kernels (the one of the gather).
  struct Stencils {
    StencilVector<mechanics::LinearKernel> linear;
    StencilVector<mechanics::UGIMPKernel> ugimp;
    StencilVector<mechanics::QuadraticBSplineKernel> bspline;
    template <class Kernel>
    StencilVector<Kernel>& of() {
      if constexpr (std::is_same_v<Kernel, mechanics::LinearKernel>) return linear;
      else if constexpr (std::is_same_v<Kernel, mechanics::UGIMPKernel>) return ugimp;
      else return bspline;
    }
    template <class Kernel>
    const StencilVector<Kernel>& of() const {
      return const_cast<Stencils*>(this)->template of<Kernel>();
    }
  };
  /// Particle k's kept stencil expanded onto the unknowns of `unknown` (sys.unknown of the gather);
  /// G' (lumped) only if WithG.
  template <class Kernel, bool WithG>
  void expand(std::size_t k, const std::vector<int>& unknown, Expanded& e) const;
  /// Particle k's Kept, runs and bounds from its kept stencil and the unknowns of `sys`; its
  /// expansion (S and G') into e.
  template <class Kernel>
  void keep(std::size_t k, const ThermalProperties& material, double volume, const NodalThermalSystem& sys,
            Expanded& e);
  /// Its bound contributions taken out again (a refresh), as keep() added them (e: its old expansion).
  void remove_bounds(const Kept& c, const Expanded& e);
  template <class Kernel>
  Refresh refresh_with(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p,
                       const std::vector<ThermalProperties>& materials, const AssemblyOptions& options,
                       NodalThermalSystem& sys, double max_shift, const mechanics::StencilView<Dim>& stencils);
  template <class Kernel>
  void gather_with(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p,
                   const std::vector<ThermalProperties>& materials, const AssemblyOptions& options,
                   NodalThermalSystem& sys, const mechanics::StencilView<Dim>& stencils);
  template <class Kernel>
  void substeps_with(const NodalThermalSystem& sys, Eigen::VectorXd& T, const Eigen::VectorXd& q,
                     const std::vector<FixedNode>& fixed, double h, long substeps);
  template <class Kernel>
  void map_back_with(mechanics::Particles<Dim>& p, const NodalThermalSystem& sys, const Eigen::VectorXd& delta,
                     double beta, const Eigen::VectorXd* end);

  mechanics::ShapeKind kind_ = mechanics::ShapeKind::linear;  // the kernel of the kept stencils
  mechanics::NodeIndexer<Dim> indexer_{};                    // the grid's node numbering
  Stencils stencils_;                     // by particle, at its gathered position (heat-holding ones)
  Stencils moved_stencils_;               // refresh scratch: the moved particles' stencils now
  std::vector<unsigned char> holds_heat_;  // gather: particle of a material with thermal properties
  std::vector<Kept> kept_;                // by particle; count 0 for particles that hold no heat
  std::vector<mechanics::Vec<Dim>> gathered_at_;  // positions at the gather
  std::vector<double> mct_;               // Σ_p m_p C_v,p T_p S_ip by grid node (gather)
  Eigen::VectorXd next_mct_;              // the same by unknown, kept with the T_p by refresh and map_back
  std::vector<double> row_bound_;         // Σ_j |K_ij| bound by unknown (W/K)
  std::vector<double> rayleigh_bound_;    // Σ_{p∋i} V_p k_p Σ_a |G'_ap|²/M_a by unknown (1/s)
  // Refreshes: each particle's terms of rayleigh_bound_ used M of their time; M_peak_a / M_a bounds
  // how much they can have grown since (1 after a gather).
  Eigen::VectorXd mass_peak_;              // largest M_a since the gather, by unknown
  double rayleigh_scale_ = 1.0;            // max_a M_peak_a / M_a
  std::vector<std::size_t> moved_;         // refresh scratch: particles to gather again
  Eigen::VectorXd force_;                 // scratch: f_i on the unknowns (W)
  bool first_force_ready_ = false;        // force_ holds f_i at flux_temperature_ (made by the gather)
  // Passing over particles whose nodes did not change (issue 13: the per-window passes were bound by
  // streaming every particle's kept lists): per particle the runs of its unknown numbers (row by row) and whether its
  // nodal temperatures agreed to round-off when last looked at; per unknown the temperature of the
  // last sub-step, and a prefix count of the nodes that changed.
  struct UnknownRun {
    int lo, hi;  // lo > hi: empty
  };
  static constexpr int kMaxRuns = Dim == 2 ? 3 : 9;  // rows of the widest stencil
  std::vector<UnknownRun> unknown_runs_;      // kMaxRuns per particle: its unknowns, row by row
  /// Whether an unknown of particle k changed (changed_before_ of this pass).
  bool any_changed(std::size_t k) const;
  std::vector<unsigned char> quiet_;          // by particle
  Eigen::VectorXd flux_temperature_;          // T_i of the last sub-step (empty: look at every particle)
  std::vector<int> changed_before_;           // scratch: changed unknowns with index < u
};

extern template class ExplicitConduction<2>;
extern template class ExplicitConduction<3>;

}  // namespace frictherm::coupling
