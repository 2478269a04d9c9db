#pragma once
// Matrix-free explicit conduction for one coupling window (issue 13 item 1), as the reference code
// NairnMPM does: lumped nodal heat capacities, the nodal conduction force from the particles'
// temperature gradients, forward-Euler sub-steps, no K assembled (with the gather reused, 2D: K kept
// at node level for the particles that have not moved, use_node_operator).
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
#include <frictherm/coupling/fixed_temperature.hpp>
#include <frictherm/coupling/thermal_assembly.hpp>
#include <frictherm/mechanics/grid.hpp>
#include <frictherm/mechanics/particles.hpp>
#include <frictherm/mechanics/shape_functions.hpp>

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <vector>

namespace frictherm::coupling {

template <int Dim>
class ExplicitConduction {
 public:
  /// Pass over the particles at their current positions: stencils (kept for the map back), M and T
  /// on every node and the unknowns into `sys` (its conductance is left empty), the gradients G'
  /// with the dropped nodes lumped, and the bounds of M⁻¹K. Throws std::invalid_argument
  /// like assemble_thermal for a material id without thermal properties or no conducting particle.
  /// `stencils`: the MPM step's stencils at these positions (mechanics::Simulation::current_stencils),
  /// read instead of evaluating them again (same numbers); an empty view evaluates them here.
  /// `keep_stencils` false (no refresh() will follow: a gather every window) with `stencils` given:
  /// the passes of this window read the step's stencils in place instead of a copy, so they must
  /// stay as they are until map_back() (the coupler's window); the next window must gather again.
  /// The exact bounds of M⁻¹K are made only when asked for (lambda_bound(), refresh()); the gather
  /// makes quick_bound()'s sums.
  void gather(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles,
              mechanics::ShapeKind shape, const std::vector<ThermalProperties>& materials,
              const AssemblyOptions& options, NodalThermalSystem& sys,
              const mechanics::StencilView<Dim>& stencils = {}, bool keep_stencils = true);

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

  /// refresh()'s decisions, also those of the decomposed run's reuse (DecomposedHeat, so that both
  /// decide alike): a particle last gathered at `at` is gathered again at `now` (Dim coordinates each)
  /// when some coordinate moved by more than max_shift; a full gather is asked for when more than a
  /// quarter of the heat-holding particles would be gathered again.
  static bool moved_beyond(const double* now, const double* at, double max_shift) {
    bool within = std::fabs(now[0] - at[0]) <= max_shift;
    for (int d = 1; d < Dim; ++d) within &= std::fabs(now[d] - at[d]) <= max_shift;
    return !within;
  }
  static bool too_many_moved(std::size_t moved, std::size_t holding) { return 4 * moved > holding; }

  /// With the kept stencils and M (refresh() kept or refreshed): T_i from the current particle
  /// temperatures (eq. 38) into sys.temperature. M, the unknowns and the bounds stay. The sums
  /// Σ_p m_p C_v,p T_p S_ip are kept up to date by the gather, refresh() and map_back() (which adds
  /// m_p C_v,p ΔT_p S_ip for the particles it changes): nothing but the coupler may change particle
  /// temperatures between matrix-free windows.
  void reproject(const mechanics::Particles<Dim>& particles, NodalThermalSystem& sys);

  /// Upper bound of the largest eigenvalue of M⁻¹K over the free unknowns of the gathered system
  /// (1/s); 0 without conduction. The first call after a gather makes the bounds (a pass over the
  /// particles with the gather's stencils and M: call it before the window's map_back()).
  double lambda_bound(const NodalThermalSystem& sys, const std::vector<FixedNode>& fixed);
  /// A cruder upper bound of the same eigenvalue, from sums the gather makes anyway (issue 35: the
  /// exact bounds cost a square root and a division per node and particle, and a window far below
  /// the stable step needs only to know that one sub-step is stable):
  ///   λ ≤ max_i Σ_{p∋i} V_p k_p A_p (|G_ip|₁ + [lumped] (S_ip / Σ_a S_ap) A_p) / M_i,
  ///   A_p = Σ_d (Σ_j |∂w_d,j|) Π_{e≠d} (Σ_j w_e,j) = Σ over the stencil of |G_ip|₁
  /// (A_p ≥ Σ_a |G'_ap|, and |G'_ip| ≤ |G_ip|₁ + (S_ip / Σ S)|Σ_dropped G|: lumping moves the dropped
  /// nodes' G onto the kept ones with shares S_ip / Σ S), so it is ≥ the Gershgorin bound of
  /// lambda_bound() (at most ~3–5× above it) and hence ≥ lambda_bound(); times (1 + 1e-6) against round-off. refresh() keeps
  /// its sums up to date (the moved particles' terms out and in), so it bounds the refreshed system.
  double quick_bound(const NodalThermalSystem& sys, const std::vector<FixedNode>& fixed) const;
  /// Whether lambda_bound()'s bounds are made (then refresh() keeps them up to date, as before issue
  /// 35); made anew by lambda_bound() after a refresh, they use M now throughout.
  bool has_exact_bounds() const { return bounds_ready_; }

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
  /// m_p C_v,p ΔT_p S_ip to the sums of the next reproject() when the stencils are kept (a refresh,
  /// and so a reproject(), may follow; without them the next window gathers the sums anew).
  /// Particles with no unknown of ΔT_i ≠ 0 in the range of their unknowns keep their temperature
  /// exactly and are passed over. `held`: the window's held unknowns, which pull their particles
  /// towards the face (FacePull; the window started from the gathered temperatures). Returns the heat
  /// the pull gave the particles, Σ_p m_p C_v,p (pull's ΔT_p) (J; 0 without held unknowns).
  double map_back(mechanics::Particles<Dim>& particles, const NodalThermalSystem& sys, const Eigen::VectorXd& delta,
                double relaxation, const Eigen::VectorXd* end,
                const std::vector<typename FacePull<Dim>::Held>* held = nullptr);

  /// Sub-steps with the operator at node level (issue 35) while the stencils are kept (reuse_distance
  /// > 0): K_ij = Σ_p V_p k_p G'_ip·G'_jp, i ≠ j, over the particles that have not moved since the
  /// gather (made once after it; refresh() takes a moved particle's terms out), and a sub-step's
  ///   f_i = −(K T)_i = −Σ_{j≠i} K_ij (T_j − T_i)      (Σ_j K_ij = 0: Σ_j G'_jp = 0)
  /// one product over each unknown's ≤ 5^Dim − 1 neighbours, plus the moved particles' fluxes as the
  /// per-particle pass makes them, instead of a look and a scatter per particle. A pair whose
  /// temperatures agree to round-off (kQuietSpread of T_i, as a quiet particle) carries no flux, so a node
  /// whose neighbours all agree with it keeps its temperature exactly.
  /// Differs from the per-particle sums by round-off (the terms regrouped). Off: the per-particle
  /// sub-steps. Memory 5^Dim doubles and two ints a unknown (the full rows of the assembly, and
  /// the slot map node_pos_) plus the compacted rows (the coupler turns it on in 2D only).
  void use_node_operator(bool on) {
    node_operator_on_ = on;
    node_operator_ready_ = false;
  }

 private:
  static constexpr int capacity = Dim == 2 ? 9 : 27;  // the widest stencil: 3 nodes per axis
  /// A particle's unknowns, S_ip and (when asked) G'_ip, in stencil order, evaluated again from its
  /// stencil of the gather and the unknowns of the gather (the same products in the same order, so
  /// the same numbers in every pass): its nodes that are unknowns are those of its stencil with
  /// sys.unknown >= 0, and G' lumps the dropped nodes' G_ip onto them in proportion to S_ip.
  struct Expanded {
    int count = 0;        // its nodes that are unknowns
    int total = 0;        // nodes of its stencil
    double s_kept = 0.0;  // Σ S_ip over its unknowns
    int unknown[capacity];
    double S[capacity];
    double G[Dim][capacity];  // by component (scalar stores: Vec temporaries through memory stalled)
    mechanics::Vec<Dim> g(int a) const {
      if constexpr (Dim == 2) return mechanics::Vec<Dim>(G[0][a], G[1][a]);
      else return mechanics::Vec<Dim>(G[0][a], G[1][a], G[2][a]);
    }
    /// Whether it conducts: some of its own heat capacity reaches an unknown (as assemble_thermal).
    bool reaches() const { return count > 0 && s_kept > 0.0; }
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
  /// The stencils of this window's passes: the kept ones, or the step's (gather without keep_stencils).
  template <class Kernel>
  const mechanics::Stencil<Dim, Kernel>* window_stencils() const {
    return static_cast<const mechanics::Stencil<Dim, Kernel>*>(window_stencils_);
  }
  /// Stencil st expanded onto the unknowns of `unknown` (sys.unknown of the gather); G' (lumped)
  /// only if WithG.
  template <class Kernel, bool WithG>
  void expand(const mechanics::Stencil<Dim, Kernel>& st, const std::vector<int>& unknown, Expanded& e) const;
  /// Particle k's terms of the two bounds of M⁻¹K (M of sys now) added (e: its expansion with G').
  void add_bounds(std::size_t k, const NodalThermalSystem& sys, const Expanded& e);
  /// Its bound contributions taken out again (a refresh), as add_bounds() added them.
  void remove_bounds(std::size_t k, const Expanded& e);
  /// quick_bound()'s sums of one particle with stencil st and expansion e (S, no G), in (sign 1) or
  /// out (−1); the lumping part only (pass 2 of the gather).
  template <class Kernel>
  void add_quick(const mechanics::Stencil<Dim, Kernel>& st, double conductance, const NodalThermalSystem& sys,
                 const Expanded& e, double sign);
  template <class Kernel>
  void add_quick_lumping(const mechanics::Stencil<Dim, Kernel>& st, double conductance,
                         const NodalThermalSystem& sys, const Expanded& e, double sign, const void* range = nullptr);
  /// Every heat-holding particle's bound terms, in particle order (as the gather made them before
  /// issue 35: the same sums), with the window's stencils and M of the gather.
  template <class Kernel>
  void make_bounds(const NodalThermalSystem& sys);
  /// split_ for `threads` from first_node_ of the heat-holding particles (one cut if threads <= 1).
  template <class Kernel>
  void split_nodes(int threads, int nodes);
  /// Whether an unknown of the stencil's nodes changed (changed_before_ of this pass, by grid node).
  template <class Kernel>
  bool any_changed(const mechanics::Stencil<Dim, Kernel>& st) const;
  /// Whether every node of the stencil is an unknown (dropped_before_, by grid node): then S and G'
  /// are the stencil's own S_ip and G_ip in its node order (no lumping), and the one-thread passes
  /// walk the stencil directly instead of expanding it (issue 35: the same products and sums in the
  /// same order, without the expansion's stores and loads).
  template <class Kernel>
  bool whole(const mechanics::Stencil<Dim, Kernel>& st) const;
  /// A whole particle's look (whole()): the lowest and highest nodal temperature, Σ S_ip (as
  /// Expanded::s_kept) and Σ_i G_ip T_i (eq. 37), with T by unknown.
  template <class Kernel>
  void look_whole(const mechanics::Stencil<Dim, Kernel>& st, const std::vector<int>& unknown, const double* T,
                  double& lo, double& hi, double& s, mechanics::Vec<Dim>& grad) const;
  /// f_i −= G_ip · g over a whole particle's nodes (by unknown).
  template <class Kernel>
  void scatter_whole(const mechanics::Stencil<Dim, Kernel>& st, const std::vector<int>& unknown,
                     const mechanics::Vec<Dim>& g, double* force) const;
  template <class Kernel>
  Refresh refresh_with(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p,
                       const std::vector<ThermalProperties>& materials, const AssemblyOptions& options,
                       NodalThermalSystem& sys, double max_shift, const mechanics::StencilView<Dim>& stencils);
  template <class Kernel>
  void gather_with(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p,
                   const std::vector<ThermalProperties>& materials, const AssemblyOptions& options,
                   NodalThermalSystem& sys, const mechanics::StencilView<Dim>& stencils, bool keep_stencils);
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
  const void* window_stencils_ = nullptr;  // Stencil<Dim, Kernel of kind_>* by particle (window_stencils)
  bool stencils_kept_ = false;             // window_stencils_ are stencils_ (a refresh may follow)
  std::vector<unsigned char> holds_heat_;  // gather: particle of a material with thermal properties
  std::vector<double> heat_capacity_;      // m_p C_v,p by particle at the gather (J/K); 0: holds no heat
  std::vector<double> conductance_;        // V_p k_p at the gather (W m/K); 0: no conduction
  std::vector<double> rayleigh_;           // V_p k_p Σ_a |G'_ap|²/M_a as added to rayleigh_bound_
  bool bounds_ready_ = false;              // row_bound_, rayleigh_bound_ and rayleigh_ made since the gather
  std::vector<double> quick_sum_;          // Σ_p V_p k_p A_p² by grid node (quick_bound)
  std::vector<mechanics::Vec<Dim>> gathered_at_;  // positions at the gather
  std::vector<double> mct_;               // Σ_p m_p C_v,p T_p S_ip by grid node (gather)
  Eigen::VectorXd next_mct_;              // the same by unknown, kept with the T_p by refresh and map_back
  double face_heat_ = 0.0;                 // map_back's heat from the pull
  FacePull<Dim> face_pull_;                   // map_back's held nodes (built per window, storage kept)
  std::vector<double> row_bound_;         // Σ_j |K_ij| bound by unknown (W/K)
  std::vector<double> rayleigh_bound_;    // Σ_{p∋i} V_p k_p Σ_a |G'_ap|²/M_a by unknown (1/s)
  // Refreshes: each particle's terms of rayleigh_bound_ used M of their time; M_peak_a / M_a bounds
  // how much they can have grown since (1 after a gather).
  Eigen::VectorXd mass_peak_;              // largest M_a since the gather, by unknown
  double rayleigh_scale_ = 1.0;            // max_a M_peak_a / M_a
  std::vector<std::size_t> moved_;         // refresh scratch: particles to gather again
  std::size_t holding_ = 0;                // particles that hold heat (gather)
  Eigen::VectorXd force_;                 // scratch: f_i on the unknowns (W)
  bool first_force_ready_ = false;        // force_ holds f_i at flux_temperature_ (made by the gather)
  // Passing over particles whose nodes did not change (issue 13: the per-window passes were bound by
  // streaming every particle's kept lists): per particle whether its nodal temperatures agreed to
  // round-off when last looked at; per unknown the temperature of the last sub-step, and per grid
  // node a prefix count of the nodes whose unknown changed (a stencil row is a run of grid nodes).
  std::vector<unsigned char> quiet_;          // by particle
  Eigen::VectorXd flux_temperature_;          // T_i of the last sub-step (empty: look at every particle)
  std::vector<int> changed_before_;           // scratch: changed unknowns at grid nodes < i
  std::vector<int> dropped_before_;           // grid nodes < i that are not unknowns (by the gather)
  std::vector<unsigned char> whole_;          // by heat-holding particle: whole() of its window stencil
  std::vector<int> first_node_;               // by heat-holding particle: its window stencil's first grid node
  // The gather's shared passes on 2+ threads: thread t's grid nodes [split_[t], split_[t + 1]), cut
  // between node rows (slowest axis) so each holds ~as many stencils (split_nodes); empty: one thread.
  std::vector<int> split_;
  std::vector<int> split_rows_;               // scratch of split_nodes: stencils by middle row
  // Threads (issue 35): each pass's per-particle work is shared by particle ranges; its sums into
  // nodes by node (or unknown) ranges, each thread adding only into its own nodes, over the particles
  // in order, so every sum has the same terms in the same order on any number of threads.
  std::vector<std::size_t> listed_;           // scratch: the particles a scatter visits, in order
  std::vector<double> particle_scratch_;      // scratch: a per-particle value of a pass
  std::vector<unsigned char> quiet_changed_;  // scratch: particles whose temperature the map back changed
  // The node-level operator (use_node_operator): by unknown i, one slot per grid-node offset of j
  // (−2..2 along each axis: two nodes of one stencil of ≤ 3 nodes an axis), K_ij and j (i itself where
  // no particle joins them: T_i − T_i = 0).
  static constexpr int offsets = Dim == 2 ? 25 : 125;
  bool node_operator_on_ = false;
  bool node_operator_ready_ = false;       // node_k_ made since the gather (kept by refresh)
  std::vector<double> node_k_;             // assembly scratch: K_ij by unknown i and slot (W/K)
  std::vector<int> node_col_;              // assembly scratch: j by unknown i and slot
  // The rows compacted to the slots some particle joined at the assembly (a row at a body's edge has
  // fewer than 5^Dim − 1; the others hold K_ij = 0 and j = i, which add exactly 0 to f_i), in slot
  // order: row i is [row_start_[i], row_start_[i + 1]) of node_kc_ and node_cc_; node_pos_ by unknown
  // and slot gives the place a refresh takes a term out of (−1: no particle joined the pair).
  bool node_compact_ = false;              // node_kc_ made from node_k_ (refresh writes there)
  std::vector<int> row_start_;
  std::vector<double> node_kc_;            // K_ij, compacted
  std::vector<int> node_cc_;               // j, compacted
  std::vector<int> node_pos_;
  Eigen::VectorXd node_force_;             // −(K T)_i of the last sub-step (rows not reached stand)
  std::array<std::vector<unsigned char>, 2> reach_;  // scratch: rows with a changed node in reach, by grid node
  // By particle: its terms are in node_k_. A refresh takes a moved particle's terms out and leaves
  // it out until the next gather (a particle that moved once moves again: the sliding body); the
  // sub-steps add the flux of those left out particle by particle, as the per-particle pass.
  std::vector<unsigned char> in_node_k_;
  std::vector<std::size_t> out_of_k_;      // in order: particles a refresh saw out of K since the assembly
  std::vector<std::size_t> out_of_k_merge_;  // scratch of refresh's merge into out_of_k_
  // A whole particle out of K walked once per stencil (issue 35): its unknowns and G_ip (the products
  // of for_each_unknown_whole) kept from its first sub-step after the refresh that took it out or
  // gave it a new stencil, so each later sub-step reads them instead of forming them again.
  struct OutOfKStencil {
    bool made = false;     // of the particle's stencil now (a refresh that moves it clears it)
    bool reaches = false;  // Σ S_ip > 0 (look_whole's s)
    int unknown[capacity];
    double G[Dim][capacity];
  };
  std::vector<OutOfKStencil> out_of_k_stencils_;  // by slot
  std::vector<int> out_of_k_slot_;                // by particle: its slot, −1 none since the assembly
  /// A kept walk's flux, packed by stencil rows (its unknowns are K consecutive ones a row): the
  /// look (lowest and highest T_i, Σ G_ip T_i) and, unless quiet, f_i −= G_ip·(V_p k_p Σ G_jp T_j),
  /// with the loop's products and sums in its order. Returns true (2D, or 3D with SSE2, no FMA).
  template <int K>
  static bool flux_whole_rows(const OutOfKStencil& c, const double* t, double conductance, double* f);
  /// The kept walk of whole particle k (made from its window stencil if it has none).
  template <class Kernel>
  const OutOfKStencil& out_of_k_stencil(std::size_t k, const mechanics::Stencil<Dim, Kernel>& st,
                                        const std::vector<int>& unknown);
  /// Particle k moves from its kept stencil `kept` to `fresh` (a refresh): out of the node operator
  /// with `kept` and its conductance so far, `kept` replaced, its kept walk forgotten, whole_ and
  /// first_node_ anew. Its other terms (M, eq. 38, the bounds) are the caller's.
  template <class Kernel>
  void restencil(std::size_t k, mechanics::Stencil<Dim, Kernel>& kept, const mechanics::Stencil<Dim, Kernel>& fresh,
                 const std::vector<int>& unknown, Expanded& e);
  /// V_p k_p G'_ip·G'_jp of the particle with stencil st added (sign 1) or taken out (−1) into the
  /// rows of its unknowns i at grid nodes in `range` (all without one).
  template <class Kernel>
  void add_to_node_operator(const mechanics::Stencil<Dim, Kernel>& st, double conductance,
                            const std::vector<int>& unknown, double sign, Expanded& e,
                            const void* range = nullptr);
  /// node_k_ anew from every heat-holding particle, in particle order (threads by rows).
  template <class Kernel>
  void assemble_node_operator(const NodalThermalSystem& sys, int threads);
  /// node_force_ = −K T from node_k_ in the rows with a changed node (changed_before_) within their
  /// reach; the other rows keep f_i of the last sub-step (threads by rows: each row alone, the same
  /// bits on any number).
  void node_operator_force(const NodalThermalSystem& sys, const Eigen::VectorXd& T, int threads);
  /// By grid node g, whether the K^Dim box of nodes from g holds a changed node (changed_before_):
  /// counts_in_rows_from as one flag per node (reach_ as scratch), for the map back's particle test.
  template <int K>
  const unsigned char* changed_in_box(int nodes);
  /// changed_before_ from whether unknown u changed.
  template <class Changed>
  void count_changed(const std::vector<int>& unknown, Changed&& changed);
};

extern template class ExplicitConduction<2>;
extern template class ExplicitConduction<3>;

}  // namespace frictherm::coupling
