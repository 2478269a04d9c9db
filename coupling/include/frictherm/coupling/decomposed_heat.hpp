#pragma once
// Frictional heating and conduction in a decomposed run (issue 16): the serial Coupler's window
// (coupler.hpp) on the decomposed mechanics' grid and particles (frictherm/mechanics/distributed.hpp).
//
//   M_i = Σ_p m_p C_v,p S_ip,  T_i = Σ_p m_p C_v,p T_p S_ip / M_i       eq. 38, summed over ranks
//   unknowns: M_i > active_mass_fraction · max_j M_j (max over ranks); a particle's gradient on the
//   other nodes is lumped onto its unknowns in proportion to S_ip (G', as thermal_assembly.hpp)
//   q_i = W_i / Δt over the window (W_i its frictional work at owned nodes, Δt its length)
//
// then one of the serial Coupler's two paths, chosen by its rule (Coupler::matrix_free_allowed):
//
//   * matrix-free forward Euler (integrator "forward_euler" or "auto", at most
//     matrix_free_max_substeps stable sub-steps; the serial ExplicitConduction, Nairn et al. 2018
//     eqs. 37–38): (∇T)_p = Σ_j G'_jp T_j with ghost T_j from the owners, f_i = −Σ_p V_p k_p G'_ip·(∇T)_p
//     summed over ranks, T_i ← T_i + h (f_i + q_i) / M_i, h = Δt / n, n from the bounds of
//     λ_max(M⁻¹K) of the serial code (maxima over ranks);
//   * assembled (every other window; decomposed_assembled.cpp): K_ij = Σ_p V_p k_p G'_ip·G'_jp summed
//     at the owners of the rows (a PETSc matrix, ADD_VALUES), M dT/dt = −K T + q integrated by the
//     thermal::DistributedIntegrator of the scene's name ("auto": cvode_bdf) on N_Vector_Parallel,
//     the Krylov path preconditioned by a PETSc PC (jacobi, bjacobi, hypre BoomerAMG);
//
// and T_p += Σ_i S_ip ΔT_i (design §4, ghost ΔT_i from the owners). With reuse_distance > 0 the
// matrix-free windows reuse the last gather as the serial ones (ExplicitConduction::refresh): S_ip,
// G'_ip, M_i and the bounds from where each particle was last gathered, the decisions over all ranks
// (decomposed_gather.cpp). Windows as the serial Coupler:
// every step, every n steps, or adaptive (closed when the pending heat would raise some node by more
// than max_temperature_rise, estimated as W_i / M_i with M of the last window: Coupler::mass_estimate
// over the node's lattice neighbours; or after max_duration / max_steps), and by the caller.
//
// W_i is the mechanics step's frictional work at owned nodes (N·27, 34/36, 40; second order by
// default). The particles' temperatures live in the swarm as the particle scalar named in the options
// (they migrate with the particles). Every call is collective.
//
// 2D and 3D: one class for DecomposedMpm<2> and DecomposedMpm<3> (the constructor taken fixes dim());
// the window is one template on Dim (decomposed_heat.cpp) with G'_ip stored flat, Dim per entry.
// It also hands the run's particles to the hot-spot tracker (update_hot_spots_across_ranks) and to
// the per-rank output (DecomposedOutput) without gathering them (frictherm/coupling/distributed.hpp).
//
// Work that lands on a node that is not an unknown goes to the unknowns among its lattice neighbours in
// proportion to M_i (the serial distribute_heat); with no unknown next to it (the serial code then
// takes the nearest unknown anywhere) it is refused with std::runtime_error on every rank. The
// adaptive estimate of such a node takes the smallest unknown M_i of all ranks (the serial one the
// nearest unknown's). Plastic heat and the sub-grid relaxation as the serial Coupler
// (decomposed_sources.cpp). Fixed-temperature faces as the serial Coupler (for_each_fixed_node: the
// same nodes, held in both paths). The sub-cell interface temperature on the owned nodes
// (decomposed_interface.cpp) and the Arrhenius reaction with λ_p as a particle scalar
// (decomposed_reaction.cpp), as the serial Coupler. Differences from the serial Coupler: that
// refusal; the KLU solver's place is taken by MUMPS' sparse
// direct LU preconditioning PCG (docs/distributed_coupling.md, docs/distributed_run.md).
#include <frictherm/coupling/coupler.hpp>
#include <frictherm/coupling/distributed.hpp>
#include <frictherm/coupling/interface_reaction.hpp>
#include <frictherm/coupling/thermal_assembly.hpp>
#include <frictherm/mechanics/contact.hpp>
#include <frictherm/mechanics/distributed.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace frictherm::coupling {

class DecomposedAssembledSolve;  // decomposed_assembled.hpp (internal)
struct UnknownNumbering;

struct DecomposedHeatOptions {
  std::vector<ThermalProperties> materials;  // by the mechanics' material index
  AssemblyOptions assembly;                  // active_mass_fraction of the unknowns
  double fe_safety = 0.9;                    // h ≤ fe_safety · 2 / λ bound (both paths; thermal::IntegratorOptions)
  mechanics::HeatingOrder order = mechanics::HeatingOrder::second;
  std::string temperature = "temperature";   // the particle scalar holding T_p (K)
  /// "forward_euler" (default), "auto" (CouplerOptions::integrator: matrix-free forward Euler for a
  /// window of at most matrix_free_max_substeps stable steps, cvode_bdf beyond) or another
  /// thermal::make_distributed_integrator name (cvode_bdf, cvode_adams, arkode_erk, arkode_dirk).
  std::string integrator = "forward_euler";
  /// rtol, atol, max_steps, krylov_maxl and linear_solver ("pcg", the default of the implicit
  /// integrators, "gmres", or "klu": PCG preconditioned by MUMPS' sparse direct LU; cvode_adams also
  /// "fixed_point", its default) of the assembled path; fe_safety above replaces theirs; forward
  /// Euler's stability policy and limit estimate as the serial Coupler (a policy other than "substep"
  /// or the "power" estimate: every window assembled).
  thermal::IntegratorOptions integrator_options;
  std::string preconditioner = "jacobi";  // of the Krylov path: "jacobi", "bjacobi" or "hypre"
  long matrix_free_max_substeps = 64;     // CouplerOptions::matrix_free_max_substeps (0: never matrix-free)
  /// CouplerOptions::reuse_distance (cells; 0: every matrix-free window gathers afresh): the serial
  /// reuse of the last matrix-free gather (ExplicitConduction::refresh, decomposed_gather.cpp), each
  /// particle's gather position, V_p and Rayleigh bound term in the particle scalars named
  /// reuse_scalar + "_0" … "_<Dim-1>", "_volume", "_rayleigh" (they migrate with the particles; the
  /// mechanics' ghosted box one node wider: DecomposedMpm::Options::extra_ghost_width).
  double reuse_distance = 0.0;
  std::string reuse_scalar = "gathered_at";
  WindowPolicy window;                    // every_step (default), every_n_steps, adaptive
  /// Plastic heating (CouplerOptions::plastic): after every step β Δw_p S_ip on the nodes joins the
  /// pending heat (decomposed_sources.cpp); Δw_p against the particle scalar named below, which
  /// carries the plastic work already handed over with the particles (its initial value: w_p).
  PlasticHeatingOptions plastic;
  std::string plastic_work_heated = "plastic_work_heated";
  /// CouplerOptions::subgrid_relaxation_time τ (s; infinite: none): the map back blends
  /// β = 1 − e^{−Δt/τ} of Σ_i S_ip T_i / Σ_i S_ip (the kept unknowns' end temperatures) into T_p.
  double subgrid_relaxation_time = std::numeric_limits<double>::infinity();
  /// CouplerOptions::fixed_faces: the unknowns on these grid faces (for_each_fixed_node, the serial
  /// rule) are held at the face's temperature: set before the window's sub-steps and after each
  /// (matrix-free), Dirichlet rows of the distributed problem (assembled), out of the λ bounds.
  std::vector<FixedTemperatureFace> fixed_faces;
  /// CouplerOptions::interface_temperature: the sub-cell interface temperature
  /// of the nodes this rank owns (decomposed_interface.cpp), each particle's T_int,p in the particle
  /// scalar named below; `thickness` the 2D out-of-plane thickness (CouplerOptions::thickness).
  InterfaceTemperatureOptions interface_temperature;
  std::string interface_scalar = "interface_temperature";
  double thickness = 1.0;
  /// CouplerOptions::reaction: Arrhenius heat in the reacting materials (decomposed_reaction.cpp),
  /// every window (during_loading) or from the continuation on; λ_p in the particle scalar named
  /// below. Reacting windows are assembled (cvode_bdf for "auto"; not forward_euler).
  ReactionOptions reaction;
  std::string progress_scalar = "reaction_progress";
  /// With the interface temperature and the reaction: the interface reaction's λ_int,p and its last
  /// rate k(T_int,p) (InterfaceReaction), particle scalars so that they migrate with the particles
  /// (the interface reaction runs during loading as well as in the continuation).
  std::string interface_progress_scalar = "interface_reaction_progress";
  std::string interface_rate_scalar = "interface_reaction_rate";
};

/// Energy books summed over ranks (J), as the serial EnergyBooks.
struct DecomposedHeatBooks {
  double work_received = 0.0;           // Σ over steps of the frictional work at owned nodes
  double heat_delivered = 0.0;          // Σ over windows of ∫ Σ_i q_i dt
  double heat_relocated = 0.0;          // part of the work that sat on nodes that are not unknowns
  double nodal_energy_change = 0.0;     // Σ over windows of Σ_i M_i ΔT_i
  double particle_energy_change = 0.0;  // Σ over windows of Σ_p m_p C_v,p ΔT_p
  double max_capacity_residual = 0.0;   // worst |Σ_i M_i − Σ_p m_p C_v,p| / Σ_p m_p C_v,p
  double max_row_sum_residual = 0.0;    // worst max_i |(K·1)_i| / max_i K_ii of assembled windows (over ranks)
  double plastic_work_received = 0.0;   // Σ over steps of Δw_p of the particles with β > 0
  double plastic_heat_received = 0.0;   // Σ over steps of Σ_i β Δw_p S_ip (part of the pending heat)
  double plastic_heat_delivered = 0.0;  // of it, handed to closed windows
  double reaction_heat_released = 0.0;  // Σ over windows and intervals of Σ_i Q_i Δλ_i
  long windows = 0;
  long continuation_intervals = 0;      // thermal-only intervals (continue_thermal)
  long substeps = 0;                    // matrix-free forward-Euler sub-steps
  long assembled_windows = 0;           // windows integrated by the distributed integrator
  long steps = 0;                       // mechanics steps seen (after_step)
  double min_window = 0.0, max_window = 0.0;  // s (0 before the first window)
  long dropped_nodes = 0;               // last window: nodes with mass that are not unknowns
  long gathers = 0, refreshes = 0;      // with reuse_distance: matrix-free gathers, refreshes (EnergyBooks)
  long exchanges = 0;                   // grid exchanges (sum_to_owned, owned_to_local): 4 + 2 n per window (+1 relocating, +1 per step with plastic heating)
};

/// One rank's thermal unknowns at a snapshot (DecomposedHeat::thermal_nodes): the serial grid node
/// numbers, T_i (K) and M_i (J/K, eq. 38), in the serial Coupler's system()->grid_node,
/// nodal_temperature() and system()->mass sense.
struct DecomposedThermalNodes {
  std::vector<int> grid_node;
  std::vector<double> temperature, heat_capacity;
};

class DecomposedHeat {
 public:
  /// The mechanics must carry the particle scalar options.temperature and hold its particles (the
  /// adaptive window's first estimate reads their M_i, as Coupler::start). Throws
  /// std::invalid_argument (every rank) for a mechanics material without thermal properties, a bad
  /// fe_safety, window, integrator name, option or preconditioner.
  DecomposedHeat(mechanics::DecomposedMpm<2>& mpm, DecomposedHeatOptions options);
  DecomposedHeat(mechanics::DecomposedMpm<3>& mpm, DecomposedHeatOptions options);
  ~DecomposedHeat();

  int dim() const { return mpm3_ ? 3 : 2; }
  /// After a mechanics step of dt seconds: adds its frictional work to the pending heat and closes the
  /// window when the policy says so or `must_close` (a snapshot time, the end). True if one closed.
  bool after_step(double dt, bool must_close = false);
  /// Closes the open window (a no-op when it has no length). True if it closed.
  bool close_window();
  /// One window of `dt` seconds with `joules` on the owned nodes (x fastest over owned_nodes()), the
  /// pending heat left alone.
  void window(const std::vector<double>& joules, double dt);
  /// Thermal-only continuation after the mechanics (Coupler::continue_thermal): one interval from the
  /// end of the last window or interval to `time` (s) without a source, the mechanics frozen; ΔT_i back
  /// to the particles. Close the window first (no pending heat; else std::logic_error).
  void continue_thermal(double time);
  /// Whether the continuation's first interval would gather and assemble afresh from the particles
  /// (the last window matrix-free, or none, or a reaction), so that a checkpoint taken before it lets
  /// a resume repeat it bit for bit; false when it goes on from the last assembled window's problem and
  /// end temperatures, which a checkpoint does not hold.
  bool continuation_regathers() const;
  /// Σ of the pending work over ranks (J).
  double pending_heat() const;
  /// The distributed integrator's global counts (zero before the first assembled window).
  thermal::IntegratorStats integrator_stats() const;

  const DecomposedHeatBooks& books() const { return books_; }
  /// The sub-cell interface temperature (options.interface_temperature): the hottest node's over all
  /// ranks at the last window or interval (−∞ before any heat), as InterfaceTemperature::max_temperature;
  /// Σ over ranks of the heat its histories recorded by then (J; equals the frictional work received).
  bool interface_enabled() const { return opt_.interface_temperature.enabled; }
  double max_interface_temperature() const { return interface_max_; }
  /// With patch_length > 0 max_interface_temperature() is the hottest patch's; this is the hottest
  /// single node's over all ranks (InterfaceTemperature::max_node_temperature; the series column
  /// max_node_interface_temperature).
  bool interface_patches() const { return interface_enabled() && opt_.interface_temperature.patch_length > 0.0; }
  double max_node_interface_temperature() const { return interface_node_max_; }
  double interface_heat_recorded() const { return interface_heat_; }
  /// The reaction (options.reaction): the largest λ_p over ranks (collective; 0 without particles
  /// of reacting materials), q Σ_p m_p λ_p over ranks (collective; Coupler::particle_reaction_heat).
  bool reaction_enabled() const { return opt_.reaction.enabled; }
  double max_reaction_progress() const;
  double particle_reaction_heat() const;
  /// The interface reaction (interface temperature and reaction, from the continuation on: the serial
  /// InterfaceReaction on this rank's particles, swarm order); its largest λ_int,p over ranks.
  const InterfaceReaction& interface_reaction() const { return interface_reaction_; }
  /// λ_int,p of this rank's particles in their current order (empty before the interface reaction
  /// starts): the particle scalar interface_progress_scalar.
  template <int Dim> std::vector<double> interface_reaction_progress(const mechanics::DecomposedMpm<Dim>& mpm) const;
  double max_interface_reaction_progress() const { return interface_reaction_max_; }
  /// Σ_p m_p C_v,p T_p over all ranks (J).
  double heat_content() const;

  /// The owned nodes that are unknowns of the last gather (the start's, a window's or an interval's),
  /// with the last window's or interval's end T_i (the gathered T_i before any window) and M_i: each
  /// thermal unknown on its owner only (the serial /nodes of a snapshot).
  DecomposedThermalNodes thermal_nodes() const;
  /// This rank's particles for DecomposedOutput::write (ids, x_p, v_p, T_p, materials; swarm order).
  DecomposedSnapshot snapshot() const;
  /// Collective: one update of `tracker` (built with dim()) over the particles of all ranks
  /// (update_hot_spots_across_ranks), T_p from the swarm and T0_p from the particle scalar named
  /// `reference` (carried with the particles, as T_p is).
  void update_hot_spots(HotSpotTracker& tracker, const std::string& reference, double time) const;

  /// Checkpoints (decomposed_checkpoint.cpp): v(name, member) for this rank's state that the next
  /// windows read, as Coupler::visit_state: the books (sums over ranks, the same on every rank), the
  /// pending work per owned node, the window's times, steps and adaptive estimate, and the last
  /// gather (M_i, T_i, M_i on the ghosted box, threshold, smallest unknown M_i) the adaptive estimate
  /// reads, and the interface temperature's flux histories. The assembled path's integrator starts
  /// afresh every window: only its counters (metadata) are not restored.
  template <class V> void visit_state(V&& v) {
    DecomposedHeatBooks& b = books_;
    for (auto [name, x] : {std::pair<const char*, double*>{"books/work_received", &b.work_received},
                           {"books/heat_delivered", &b.heat_delivered}, {"books/heat_relocated", &b.heat_relocated},
                           {"books/nodal_energy_change", &b.nodal_energy_change},
                           {"books/particle_energy_change", &b.particle_energy_change},
                           {"books/max_capacity_residual", &b.max_capacity_residual},
                           {"books/max_row_sum_residual", &b.max_row_sum_residual},
                           {"books/min_window", &b.min_window}, {"books/max_window", &b.max_window},
                           {"books/plastic_work_received", &b.plastic_work_received},
                           {"books/plastic_heat_received", &b.plastic_heat_received},
                           {"books/plastic_heat_delivered", &b.plastic_heat_delivered},
                           {"books/reaction_heat_released", &b.reaction_heat_released},
                           {"window/pending_plastic", &pending_plastic_},
                           {"window/time", &time_}, {"window/start", &window_start_}, {"window/max_rise", &max_rise_},
                           {"window/max_speed", &max_speed_},
                           {"window/last_lambda", &last_lambda_}, {"gather/threshold", &threshold_},
                           {"gather/min_unknown_mass", &min_unknown_mass_}})
      v(name, *x);
    for (auto [name, x] : {std::pair<const char*, long*>{"books/windows", &b.windows}, {"books/substeps", &b.substeps},
                           {"books/assembled_windows", &b.assembled_windows}, {"books/steps", &b.steps},
                           {"books/dropped_nodes", &b.dropped_nodes}, {"books/exchanges", &b.exchanges},
                           {"window/steps", &window_steps_}})
      v(name, *x);
    if (opt_.reuse_distance > 0.0) {  // the reuse (decomposed_gather.cpp): its counts
      v("books/gathers", b.gathers);
      v("books/refreshes", b.refreshes);
      // As the serial resume (Coupler::visit_state assembles, a new Coupler has no bound yet): the
      // first window after it gathers anew.
      if constexpr (std::decay_t<V>::reading) reuse_gathered_ = reuse_quick_ = reuse_exact_ = false, last_lambda_ = 0.0;
    }
    v("window/pending", pending_);
    v("gather/M", M_);
    v("gather/T", T0_);
    v("gather/local_M", local_M_);
    // The sub-cell interface temperature: the flux histories of this rank's owned heated nodes (the
    // serial InterfaceTemperature::visit_state) and the last maximum and recorded heat over ranks.
    if (interface2_) interface2_->visit_state(v);
    if (interface3_) interface3_->visit_state(v);
    if (interface2_ || interface3_) {
      v("interface/max_temperature", interface_max_);
      v("interface/heat", interface_heat_);
      if (interface_patches()) v("interface/node_max_temperature", interface_node_max_);
      if (opt_.reaction.enabled) {  // λ_int,p and k travel in particle scalars; the clock here
        std::vector<double> state{interface_reaction_.started() ? 1.0 : 0.0, interface_reaction_.time(),
                                  interface_reaction_max_};
        v("interface_reaction/state", state);
        if constexpr (std::decay_t<V>::reading)
          if (state.size() == 3) interface_reaction_.restore_time(state[0] != 0.0, state[1]), interface_reaction_max_ = state[2];
      }
    }
  }

 private:
  template <int Dim> void check_materials(mechanics::DecomposedMpm<Dim>& mpm);
  template <int Dim> void select_fixed_nodes(const mechanics::DecomposedMpm<Dim>& mpm);
  // Owned node u held at face_temperature_[u] when it is an unknown (NaN: on no fixed face).
  bool is_held(std::size_t u) const { return !face_temperature_.empty() && !std::isnan(face_temperature_[u]); }
  template <int Dim>
  void window_on(mechanics::DecomposedMpm<Dim>& mpm, const std::vector<double>& joules, double t0, double dt);
  // decomposed_gather.cpp: the gather (pass 1 M_i and T_i; pass 2 the kept entries and the bounds of
  // λ_max(M⁻¹K)) from the particles' current stencils or from `at` (their stencils where last gathered),
  // and the reuse of the last gather (reuse_window: the serial Coupler::matrix_free_window's decisions).
  template <int Dim>
  void gather_mass(mechanics::DecomposedMpm<Dim>& mpm, const typename mechanics::DecomposedMpm<Dim>::Stencils* at = nullptr);
  template <int Dim>
  double gather_window(mechanics::DecomposedMpm<Dim>& mpm,
                       const typename mechanics::DecomposedMpm<Dim>::Stencils* at = nullptr);
  bool matrix_free_allowed() const;
  bool reuse_on() const { return opt_.reuse_distance > 0.0 && matrix_free_allowed(); }
  template <int Dim> bool reuse_window(mechanics::DecomposedMpm<Dim>& mpm, double dt, long& substeps);
  template <int Dim> void continue_on(mechanics::DecomposedMpm<Dim>& mpm, double time);
  template <int Dim> double mass_estimate(const mechanics::DecomposedMpm<Dim>& mpm, std::size_t owned) const;
  template <int Dim> double rise_of_step(const mechanics::DecomposedMpm<Dim>& mpm, const std::vector<double>& work) const;
  template <int Dim> void number_unknowns(mechanics::DecomposedMpm<Dim>& mpm);
  // decomposed_sources.cpp: the step's plastic heat onto pending_ (this rank's Δw_p and heat in
  // `sums`), and the map back T_p += Σ_i S_ip ΔT_i with the sub-grid relaxation (energy changes in
  // `changes`: Σ_i M_i ΔT_i and Σ_p m_p C_v,p ΔT_p of this rank).
  template <int Dim> void collect_plastic(mechanics::DecomposedMpm<Dim>& mpm, double sums[2]);
  template <int Dim>
  // from_gathered: the window started from the gathered T_i (held nodes pull, FacePull).
  void map_back(mechanics::DecomposedMpm<Dim>& mpm, const std::vector<double>& Tn, double dt, std::vector<double>& T,
                double changes[2], bool from_gathered);
  bool is_unknown(double M) const { return M > threshold_ && M > 0.0; }
  template <int Dim>
  void hot_spots_on(const mechanics::DecomposedMpm<Dim>& mpm, HotSpotTracker& tracker, const std::string& reference,
                    double time) const;
  // decomposed_interface.cpp: InterfaceTemperature on the owned nodes (start, each step's heat, the
  // update after each window or interval, which writes T_int,p into the particle scalar).
  // Owned node u (x fastest over owned_nodes()) -> its serial grid node number.
  template <int Dim> static std::vector<int> owned_grid_nodes(const mechanics::DecomposedMpm<Dim>& mpm);
  template <int Dim> InterfaceTemperature<Dim>* interface_model();
  template <int Dim> void interface_start(mechanics::DecomposedMpm<Dim>& mpm);
  template <int Dim> void interface_step(const std::vector<double>& work);
  template <int Dim> void interface_update(mechanics::DecomposedMpm<Dim>& mpm);
  template <int Dim> void interface_patches(InterfaceTemperature<Dim>& model, MPI_Comm comm);
  template <int Dim> void interface_reaction_start(mechanics::DecomposedMpm<Dim>& mpm, double time);
  // decomposed_reaction.cpp: the reacting mass and λ_i gathered from the particles (gather_reaction),
  // and the unreacted ratio scattered back (scatter_progress), as the serial heat_sources.cpp.
  bool reaction_active() const { return opt_.reaction.enabled && (opt_.reaction.during_loading || continuing_); }
  template <int Dim> void reaction_gather(mechanics::DecomposedMpm<Dim>& mpm);
  template <int Dim> void reaction_scatter(mechanics::DecomposedMpm<Dim>& mpm);
  MPI_Comm communicator() const;
  mechanics::DecomposedLocalParticles local_particles() const;
  std::vector<double> temperatures() const;

  mechanics::DecomposedMpm<2>* mpm2_ = nullptr;  // one of the two
  mechanics::DecomposedMpm<3>* mpm3_ = nullptr;
  DecomposedHeatOptions opt_;
  int scalar_ = 0, heated_scalar_ = -1;  // T_p; the plastic work handed over (-1: no plastic heating)
  DecomposedHeatBooks books_;
  // Per window, this rank's heat-holding particles' kept nodes (unknowns), flat: particle k's entries
  // [kept_first_[k], kept_first_[k+1]) with local node, S_ip and the lumped G'_ip (Dim values per
  // entry; sized for every stencil entry, the first kept_first_.back() used) and |G'_ip|; V_p k_p per
  // particle.
  std::vector<int> kept_first_, kept_node_;
  std::vector<double> kept_S_, kept_G_, kept_norm_, conductance_, capacity_;
  std::vector<double> local_, owned_, local_T_, force_;  // scratch
  // The last gather: M_i and T_i (eq. 38) per owned node, M_i on the ghosted box, the unknowns'
  // threshold and smallest M_i over all ranks; the unknowns' global numbering of assembled windows.
  std::vector<double> M_, T0_, local_M_;
  std::vector<FacePull<2>::Held> held_nodes_2_;  // map_back's held nodes (FacePull), by dimension
  std::vector<FacePull<3>::Held> held_nodes_3_;
  std::vector<double> face_temperature_;  // per owned node: its fixed face's temperature (K), NaN if none; empty without faces
  double threshold_ = 0.0, min_unknown_mass_ = 0.0;
  std::unique_ptr<UnknownNumbering> ids_;
  // The window: pending work per owned node, times (s), steps, the adaptive estimate (K).
  std::vector<double> pending_;
  double pending_plastic_ = 0.0;  // of it, plastic heat (J, over ranks)
  double time_ = 0.0, window_start_ = 0.0, max_rise_ = 0.0;
  double max_speed_ = 0.0;  // adaptive max_travel: the largest conducting particle speed of the window (m/s)
  std::vector<std::uint8_t> conducting_;  // per material: 1 if it conducts (the max_travel speed's mask)
  long window_steps_ = 0;
  double last_lambda_ = 0.0;  // λ bound of the last matrix-free decision (Coupler::last_lambda_bound_)
  // The reuse (reuse_distance): the particle scalars (Dim gather positions, V_p, Rayleigh term), and
  // the serial Coupler's and ExplicitConduction's state: a gather to reuse, last_lambda_ the quick
  // bound, the exact bounds made since the gather, heat-holding particles (all ranks), M_peak / M,
  // and by owned node M_peak since the bounds and whether it was an unknown of the gather.
  std::vector<int> reuse_scalars_;
  bool reuse_gathered_ = false, reuse_quick_ = false, reuse_exact_ = false;
  double reuse_holding_ = 0.0, rayleigh_scale_ = 1.0;
  std::vector<double> mass_peak_, gathered_unknown_;
  // gather_window with reuse: V_p by particle (its gather's), the Rayleigh terms to sum (NaN: anew),
  // the new ones, and the maxima over ranks: Gershgorin, Rayleigh, quick, Rayleigh of the kept terms.
  const std::vector<double>* gather_volume_ = nullptr;
  std::vector<double> rayleigh_kept_, rayleigh_fresh_;
  double bounds_[4] = {0.0, 0.0, 0.0, 0.0};
  std::unique_ptr<DecomposedAssembledSolve> assembled_;  // the distributed integrator (assembled path)
  // The last window's (or interval's) end T_i per owned node and whether it was assembled (its problem
  // kept in assembled_): where the continuation starts (Coupler::nodal_temperature_, system_assembled_).
  std::vector<double> last_T_;
  bool last_assembled_ = false, continuing_ = false;
  // The interface temperature's state of the owned nodes (one of the two, with the option), its
  // particle scalar, owned node -> grid node and back (-1: not owned), the last maximum over ranks.
  std::unique_ptr<InterfaceTemperature<2>> interface2_;
  std::unique_ptr<InterfaceTemperature<3>> interface3_;
  int interface_scalar_ = -1, interface_progress_scalar_ = -1, interface_rate_scalar_ = -1;
  std::vector<int> owned_grid_node_, owned_of_grid_;
  double interface_max_ = -std::numeric_limits<double>::infinity(), interface_heat_ = 0.0;
  double interface_node_max_ = -std::numeric_limits<double>::infinity();
  // The reaction: λ_p's scalar (-1: none), the last gather's reacting mass and λ_i per owned node,
  // λ_i now, and the particles' λ_p at the gather (swarm order; the particles do not move in between).
  int progress_scalar_ = -1;
  std::vector<double> reacting_mass_, nodal_progress_ref_, nodal_progress_, particle_progress_ref_;
  InterfaceReaction interface_reaction_;
  double interface_reaction_max_ = 0.0;
};

}  // namespace frictherm::coupling
