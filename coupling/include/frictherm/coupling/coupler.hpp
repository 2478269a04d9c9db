#pragma once
// One-way thermal coupling of MPM mechanics to a thermal integrator, window by window
// (design §4; Nairn et al. 2018 §2.11, eqs. 37–38):
//
//   Coupler<2> c(grid, shape, options);
//   c.start(particles, t0);
//   each mechanics step: c.after_step(particles, nodal_work /* J by grid node */, t);
//   c.close_window(particles, t_end);            // deliver what is pending
//   c.continue_thermal(particles, t_end + more);  // optional thermal-only phase
//
// A window ends when its policy says so (every step, every n steps, adaptive) or when the caller
// closes it. Then: M, T (eq. 38) and K are built from the particles as they are now; the work
// accumulated over the window is delivered as the constant source W_i / Δt_window (exact:
// ∫ q dt = W_i); the integrator advances the nodal temperatures over the window; the particles get
// T_p += Σ_i S_ip ΔT_i; hot spots are updated. Σ_p m_p C_v,p ΔT_p = Σ_i M_i ΔT_i, which equals the
// heat delivered when conduction conserves energy (adiabatic edges; exact for forward_euler and
// the KLU-based integrators, to the solver tolerance for PCG).
//
// Optional sources (issue 5, heat_sources.hpp): plastic work times a Taylor–Quinney fraction joins
// the frictional work in the window's pending heat (separate books); an Arrhenius reaction
// (thermal::Reaction) on the nodes of reacting materials, with the progress λ kept on the particles
// and gathered at every assembly. Books: Σ_i M_i ΔT_i = frictional + plastic heat delivered +
// reaction heat released (adiabatic edges; to the solver tolerance with a reaction).
#include <frictherm/coupling/explicit_conduction.hpp>
#include <frictherm/coupling/fixed_temperature.hpp>
#include <frictherm/coupling/heat_handoff.hpp>
#include <frictherm/coupling/heat_sources.hpp>
#include <frictherm/coupling/hotspot_fates.hpp>
#include <frictherm/coupling/hotspots.hpp>
#include <frictherm/coupling/interface_temperature.hpp>
#include <frictherm/coupling/interface_reaction.hpp>
#include <frictherm/coupling/state_visit.hpp>
#include <frictherm/coupling/thermal_assembly.hpp>
#include <frictherm/thermal/integrator.hpp>

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <string>
#include <unordered_map>
#include <vector>

namespace frictherm::coupling {

struct WindowPolicy {
  enum class Kind { every_step, every_n_steps, adaptive };
  Kind kind = Kind::every_step;
  long steps = 1;  // every_n_steps: n
  /// adaptive: close when the pending heat would raise some node by more than this (K), estimated
  /// as W_i / M_i with M from the last assembly (the smallest unknown's M for nodes that were none).
  double max_temperature_rise = 1.0;
  double max_duration = std::numeric_limits<double>::infinity();  // adaptive: longest window (s)
  long max_steps = 0;                                              // adaptive: most steps (0: no limit)
  /// adaptive: close when the fastest conducting particle may have travelled this many cells (the
  /// smallest cell edge) since the window opened, estimated as max |v_p| over the window's steps times
  /// its duration (an upper bound). A node's pending heat goes to the particles on it at the window's
  /// end, so a slider that moved on leaves part of its heat behind (docs/coupling.md). 0: no limit.
  double max_travel = 0.0;
};

/// Throws std::invalid_argument, the message starting with `who`, when the window policy or the
/// matrix-free sub-step limit is out of range: the serial Coupler and DecomposedHeat check alike.
void check_window_options(const WindowPolicy& w, long matrix_free_max_substeps, const std::string& who);

struct CouplerOptions {
  std::vector<ThermalProperties> materials;  // by material id
  /// thermal::make_integrator name, or "auto": matrix-free forward Euler (explicit_conduction.hpp)
  /// for a window of at most matrix_free_max_substeps stable steps, cvode_bdf (assembled) beyond,
  /// with a reaction and in the continuation.
  std::string integrator = "cvode_bdf";
  thermal::IntegratorOptions integrator_options;
  /// The thermal::make_integrator name of the assembled windows: `integrator`, with "auto" as cvode_bdf.
  std::string assembled_integrator() const { return integrator == "auto" ? "cvode_bdf" : integrator; }
  /// forward_euler and auto: a window that needs at most this many stable forward-Euler sub-steps is
  /// integrated matrix-free (no K assembled; 0: never). Longer windows assemble K (forward_euler
  /// sub-steps on it, or cvode_bdf for auto). Only with the "substep" stability policy and the
  /// Gershgorin estimate, and not while a reaction is part of the problem. Measured crossover:
  /// docs/performance.md.
  long matrix_free_max_substeps = 64;
  /// Matrix-free windows: the stencils, M and G' of the last gather serve the next windows while no
  /// particle has moved more than this fraction of the cell size along any axis since it (T_i is
  /// re-projected from the particles every window; energy stays exact, the weights lag by at most
  /// this shift). 0: gather every window. Error against gathering every window: docs/performance.md.
  double reuse_distance = 0.0;
  /// Matrix-free windows with the gather reused, 2D (issue 35): the sub-steps take f = −K T from K
  /// kept at node level (ExplicitConduction::use_node_operator) instead of a pass over the particles.
  /// Differs from the per-particle sums by round-off (docs/performance.md, session of 29 Nov, evening). false: the
  /// per-particle sub-steps.
  bool matrix_free_node_operator = true;
  AssemblyOptions assembly;
  WindowPolicy window;
  HotSpotOptions hotspots;
  std::vector<FixedTemperatureFace> fixed_faces;
  double thickness = 1.0;  // 2D out-of-plane thickness (m), for hot-spot areas
  /// Sub-grid relaxation time τ (s): each window blends β = 1 − exp(−Δt/τ) of the PIC value into the
  /// incremental update (add_nodal_change_to_particles), so particle-scale structure the grid cannot
  /// resolve decays as exp(−t/τ) whatever the window length. Infinite (default): pure incremental
  /// update (design §4), which keeps such structure forever.
  double subgrid_relaxation_time = std::numeric_limits<double>::infinity();
  PlasticHeatingOptions plastic;  // plastic work as a heat source (off by default)
  ReactionOptions reaction;       // Arrhenius reaction heat (off by default)
  HotSpotFateOptions fates;       // runaway criteria of the continuation
  /// Sub-cell interface temperature of rubbing contacts (interface_temperature.hpp; off by default).
  InterfaceTemperatureOptions interface_temperature;
  /// Hot spots judged by the interface temperature instead of T_p (needs interface_temperature).
  bool hotspots_by_interface_temperature = false;
};

/// Where the heat went (J). Without fixed faces nodal_energy_change equals heat_delivered up to the
/// integrator's conservation error; with them the difference is the heat taken by the faces.
struct EnergyBooks {
  double work_received = 0.0;        // Σ nodal (frictional) work handed to after_step
  double plastic_work_received = 0.0;  // Σ_p Δw_p of the materials with a Taylor–Quinney fraction
  double plastic_heat_received = 0.0;  // Σ_p β Δw_p added to the pending heat
  double heat_delivered = 0.0;       // Σ over closed windows of ∫ Σ_i q_i dt (frictional + plastic)
  double plastic_heat_delivered = 0.0;  // the plastic part of heat_delivered
  double reaction_heat_released = 0.0;  // Σ over windows and intervals of Σ_i Q_i Δλ_i
  double heat_relocated = 0.0;       // the part that sat on nodes that were not unknowns
  double nodal_energy_change = 0.0;  // Σ over windows of Σ_i M_i ΔT_i (= Σ_p m_p C_v,p ΔT_p)
                                     // = heat_delivered + reaction_heat_released (adiabatic)
  long windows = 0;                  // closed windows with mechanics
  long continuation_intervals = 0;   // thermal-only intervals
  long steps = 0;                    // mechanics steps seen
  double min_window = std::numeric_limits<double>::infinity();  // s
  double max_window = 0.0;                                      // s
  double max_assembly_residual = 0.0;  // worst of M partition-of-unity and K·1 = 0 residuals
  long matrix_free_windows = 0;        // windows integrated matrix-free (explicit_conduction.hpp)
  long matrix_free_substeps = 0;       // their forward-Euler sub-steps
  long matrix_free_gathers = 0;        // particle passes that built M and G' for them (the rest reused)
  long matrix_free_refreshes = 0;      // windows that gathered again only the particles that moved
};

template <int Dim>
class Coupler {
 public:
  /// Throws std::invalid_argument for a bad integrator name or options.
  Coupler(const mechanics::Grid<Dim>& grid, mechanics::ShapeKind shape, CouplerOptions options);

  /// Where the particles' current shape functions come from: typically the MPM step's own,
  /// [&sim] { return sim.current_stencils(); }. Asked once per gather or assembly (and its map back),
  /// with the particles where they will be read; the coupler then evaluates no stencil itself (the
  /// numbers are the same). Without a source, or when it gives an empty view (EBS), it evaluates its own.
  void set_stencil_source(std::function<mechanics::StencilView<Dim>()> source) { stencil_source_ = std::move(source); }

  /// Records each particle's initial temperature and the initial energy, assembles once (for the
  /// adaptive policy's estimate) and finds the initial hot spots. Throws std::invalid_argument if
  /// no particle belongs to a conducting material.
  void start(const mechanics::Particles<Dim>& particles, double time);
  /// After a mechanics step that ended at `time`: adds its nodal work (J by grid node, empty for
  /// none) and closes the window if the policy says so. Returns true when a window closed.
  bool after_step(mechanics::Particles<Dim>& particles, const std::vector<double>& nodal_work, double time);
  /// Closes the open window at `time` (a no-op when it has zero length). Returns true if it closed.
  bool close_window(mechanics::Particles<Dim>& particles, double time);
  /// Thermal-only phase (no pending work allowed): integrates the last assembled problem, without
  /// sources, from the end of the last window or interval to `time`, and maps the change back. The
  /// first call starts following the fates of the hot spots alive then (hotspot_fates.hpp).
  void continue_thermal(mechanics::Particles<Dim>& particles, double time);
  /// End of the continuation: settles the fates of undecided hot spots (HotSpotFates::finish).
  void finish_continuation() { fates_.finish(); }

  const EnergyBooks& books() const { return books_; }
  double pending_heat() const { return pending_.total(); }
  double window_start() const { return window_start_; }
  long window_steps() const { return window_steps_; }
  /// Σ_p m_p C_v,p (T_p − T_p(start)) (J).
  double particle_energy_change(const mechanics::Particles<Dim>& particles) const;
  const thermal::Integrator& integrator() const { return *integrator_; }
  /// Statistics of all integration so far: the loading's integrator and the continuation's (a fresh
  /// one of the same kind: the continuation starts without the loading's step history, so that it
  /// depends only on the state at the end of loading; checkpoints, issue 17), and those restored
  /// from a checkpoint.
  thermal::IntegratorStats integrator_stats() const;
  const HotSpotTracker& hotspots() const { return tracker_; }
  const HotSpotFates& fates() const { return fates_; }
  /// The sub-cell interface temperatures (enabled() false unless options().interface_temperature asks).
  const InterfaceTemperature<Dim>& interface_temperature() const { return interface_; }
  /// Reaction progress at the interface temperature (interface_reaction.hpp); started() only with the
  /// interface model and a reaction, from the time the reaction joins the problem.
  const InterfaceReaction& interface_reaction() const { return interface_reaction_; }
  /// Reaction progress λ_p of every particle (0 for non-reacting ones); empty without a reaction.
  const std::vector<double>& reaction_progress() const { return particle_progress_; }
  /// q Σ_p m_p λ_p over reacting particles (J): the reaction heat the particles carry.
  double particle_reaction_heat(const mechanics::Particles<Dim>& particles) const;
  /// The system of the last window (nullptr before the first assembly).
  const NodalThermalSystem* system() const { return has_system_ ? &system_ : nullptr; }
  /// The nodal temperatures T_i (K) at the end of the last window or continuation interval, one per
  /// unknown of system() (grid node system()->grid_node[k]): the thermal grid's own state.
  const Eigen::VectorXd& nodal_temperature() const { return nodal_temperature_; }
  const mechanics::Grid<Dim>& grid() const { return grid_; }
  const CouplerOptions& options() const { return opt_; }

  /// Checkpoints (issue 17; state_visit.hpp visitors): everything the next step, window or the
  /// continuation reads — pending heat, window state, books, hot-spot tracker, reaction progress,
  /// plastic-work marks, nodal temperatures, the last system's unknowns and masses (adaptive
  /// estimate) and the integrator's counts (not its wall time). Reading restores them into a coupler built with the
  /// same grid and options after start(), and reassembles from `particles` (which must already hold
  /// the restored state): M and K depend only on positions, masses and volumes, so at the end of
  /// loading (a window just closed) the system equals the one written. Throws std::logic_error once
  /// the continuation has begun (checkpoints are taken during loading and at its end).
  template <class V> void visit_state(V&& v, const mechanics::Particles<Dim>& particles);
  /// True until the continuation begins.
  bool checkpointable() const { return !continuing_; }

 private:
  void assemble(const mechanics::Particles<Dim>& particles);
  mechanics::StencilView<Dim> step_stencils() const {
    return stencil_source_ ? stencil_source_() : mechanics::StencilView<Dim>{};
  }
  /// The checks and caches that follow a new system (assembled or gathered).
  void system_changed();
  // Lattice index along an axis of the gathered system's unknown u (for_each_fixed_node).
  auto fixed_lattice_along() const {
    return [this](std::size_t u, int axis) {
      return grid_.node_lattice(system_.grid_node[u])[static_cast<std::size_t>(axis)];
    };
  }
  /// Integrates the window [window_start_, time] matrix-free if it is short enough; false otherwise.
  bool matrix_free_window(mechanics::Particles<Dim>& particles, double dt);
  bool matrix_free_allowed() const;
  // FacePull's held unknowns of the system after a window that ends at nodal temperatures T (null
  // without fixed faces).
  const std::vector<typename FacePull<Dim>::Held>* face_pull_nodes(const Eigen::VectorXd& T);
  // The window's Σ M_i ΔT_i for the books, the held unknowns' terms replaced by the heat their pull
  // gave the particles (FacePull).
  double nodal_change(const Eigen::VectorXd& delta, const std::vector<typename FacePull<Dim>::Held>* held,
                      double face_heat) const;
  // from_gathered: the window started from the particles' temperatures (held nodes pull, FacePull).
  void advance_and_map(mechanics::Particles<Dim>& particles, double t0, double t1, bool from_gathered);
  double mass_estimate(std::size_t node) const;

  mechanics::Grid<Dim> grid_;
  mechanics::ShapeKind shape_;
  std::function<mechanics::StencilView<Dim>()> stencil_source_;
  CouplerOptions opt_;
  std::unique_ptr<thermal::Integrator> integrator_;
  HeatAccumulator pending_;
  double pending_plastic_ = 0.0;  // plastic part of pending_ (J)
  PlasticHeatSource<Dim> plastic_;
  HotSpotTracker tracker_;
  HotSpotFates fates_;
  InterfaceTemperature<Dim> interface_;
  InterfaceReaction interface_reaction_;
  /// The interface model's update after a window or interval ending at `time`, then the hot spots.
  void update_interface_and_hotspots(mechanics::Particles<Dim>& particles, double time);
  /// The particle temperatures hot spots are judged by: the interface's when the scene asks for them
  /// and the model has a reading for every particle, nullptr for T_p.
  const std::vector<double>* hotspot_temperature(const mechanics::Particles<Dim>& particles) const;
  std::vector<double> particle_progress_;       // λ_p (reaction only)
  std::vector<double> particle_progress_ref_;   // λ_p at the last assembly
  Eigen::VectorXd nodal_progress_;              // λ_i on the unknowns, current
  Eigen::VectorXd nodal_progress_ref_;          // λ_i gathered at the last assembly
  NodalThermalSystem system_;
  bool has_system_ = false;
  bool system_assembled_ = false;  // system_ has K and problem_ is built on it (not a matrix-free gather)
  bool system_gathered_ = false;   // system_ is explicit_'s last gather (reusable for matrix-free windows)
  ExplicitConduction<Dim> explicit_;
  double last_lambda_bound_ = 0.0;     // bound of λ_max(M⁻¹K) of the last gather or refresh (1/s)
  bool lambda_bound_is_quick_ = false;  // last_lambda_bound_ is ExplicitConduction::quick_bound (cruder)
  std::vector<FixedNode> fixed_nodes_;  // unknowns of the gathered system on fixed-temperature faces
  std::vector<typename FacePull<Dim>::Held> face_pull_;  // face_pull_nodes' storage
  bool continuing_ = false;  // continue_thermal has been called
  /// The Arrhenius heat is part of the problem: enabled, and during loading or in the continuation.
  bool reaction_active() const { return opt_.reaction.enabled && (opt_.reaction.during_loading || continuing_); }
  std::optional<thermal::Problem> problem_;
  Eigen::VectorXd nodal_temperature_;  // state at the end of the last window or interval
  double min_unknown_mass_ = 0.0;
  mutable std::unordered_map<std::size_t, double> nearest_mass_;  // mass_estimate of isolated nodes
  double window_start_ = 0.0;
  long window_steps_ = 0;
  double max_rise_ = 0.0;               // adaptive estimate for the open window (K)
  double max_speed_ = 0.0;              // adaptive: the largest max_p |v_p| of the open window (m/s)
  double initial_energy_ = 0.0;
  EnergyBooks books_;
  thermal::IntegratorStats stats_offset_;  // integrators before the current one, and restored counts
};

template <int Dim>
template <class V>
void Coupler<Dim>::visit_state(V&& v, const mechanics::Particles<Dim>& particles) {
  constexpr bool reading = std::decay_t<V>::reading;
  if (continuing_) throw std::logic_error("Coupler: checkpoints are taken during loading, not in the continuation");
  pending_.visit_state(v);
  v("pending_plastic", pending_plastic_);
  if (interface_.enabled()) interface_.visit_state(v);
  if (interface_.enabled()) interface_reaction_.visit_state(v);  // empty until a reaction starts
  if (opt_.plastic.enabled) plastic_.visit_state(v);
  tracker_.visit_state(v);
  std::vector<double> progress = particle_progress_;  // empty without a reaction
  v("reaction/particle_progress", progress);
  // Said explicitly (issue 34): whether the loading had a reaction, so that an emptied progress is
  // refused instead of read as a loading without one (check_arrays compares the two).
  bool reacting = !particle_progress_.empty();
  v("reaction/enabled", reacting);
  if constexpr (reading) {
    // A reaction the loading did not have (frictherm continue): fresh material, λ = 0.
    if (opt_.reaction.enabled) particle_progress_ = progress.empty() ? std::vector<double>(particles.size(), 0.0) : progress;
  }
  std::vector<int> grid_node = system_.grid_node, unknown = system_.unknown;
  Eigen::VectorXd mass = system_.mass;
  v("system/grid_node", grid_node);
  v("system/unknown", unknown);
  state::vector(v, "system/mass", mass);
  state::vector(v, "nodal_temperature", nodal_temperature_);
  v("window_start", window_start_);
  v("window_steps", window_steps_);
  v("max_rise", max_rise_);
  v("max_speed", max_speed_);
  v("initial_energy", initial_energy_);
  EnergyBooks& b = books_;
  for (auto [name, x] : {std::pair<const char*, double*>{"books/work_received", &b.work_received},
                         {"books/plastic_work_received", &b.plastic_work_received},
                         {"books/plastic_heat_received", &b.plastic_heat_received},
                         {"books/heat_delivered", &b.heat_delivered},
                         {"books/plastic_heat_delivered", &b.plastic_heat_delivered},
                         {"books/reaction_heat_released", &b.reaction_heat_released},
                         {"books/heat_relocated", &b.heat_relocated},
                         {"books/nodal_energy_change", &b.nodal_energy_change},
                         {"books/min_window", &b.min_window},
                         {"books/max_window", &b.max_window},
                         {"books/max_assembly_residual", &b.max_assembly_residual}})
    v(name, *x);
  v("books/windows", b.windows);
  v("books/continuation_intervals", b.continuation_intervals);
  v("books/steps", b.steps);
  thermal::IntegratorStats s = integrator_stats();
  for (auto [name, x] : {std::pair<const char*, long*>{"integrator/steps", &s.steps},
                         {"integrator/rhs_evals", &s.rhs_evals},
                         {"integrator/jac_evals", &s.jac_evals},
                         {"integrator/nonlinear_iters", &s.nonlinear_iters},
                         {"integrator/linear_iters", &s.linear_iters},
                         {"integrator/error_test_failures", &s.error_test_failures},
                         {"integrator/convergence_failures", &s.convergence_failures},
                         {"integrator/reinits", &s.reinits}})
    v(name, *x);
  // Counts only: wall time is the process's own (after a resume /meta times the resumed part), and
  // equal states give byte-equal checkpoints.
  s.wall_seconds = integrator_stats().wall_seconds;
  if constexpr (reading) {
    stats_offset_ = s;
    stats_offset_ -= integrator_->stats();  // integrator_stats() == s from here on
    const double residual = books_.max_assembly_residual;
    assemble(particles);  // problem and reaction state from the restored particles
    books_.max_assembly_residual = residual;
    // The written system was assembled from these particles unless the last window was a matrix-free
    // gather (or an older one reused): then it differs, and like the uninterrupted run the
    // continuation must assemble afresh and start from its projected temperatures.
    system_assembled_ = grid_node == system_.grid_node && unknown == system_.unknown &&
                        mass.size() == system_.mass.size() && mass == system_.mass;
    system_.grid_node = std::move(grid_node);  // the adaptive estimate's M: the last window's
    system_.unknown = std::move(unknown);
    system_.mass = std::move(mass);
    min_unknown_mass_ = system_.mass.size() > 0 ? system_.mass.minCoeff() : 0.0;
    nearest_mass_.clear();
    if (interface_.enabled())
      interface_.update(particles, shape_, step_stencils(), system_, nodal_temperature_, window_start_);
    if (tracker_.options_changed()) tracker_.redetect(particles, opt_.materials, window_start_);
  } else {
    (void)particles;
  }
}

extern template class Coupler<2>;
extern template class Coupler<3>;

}  // namespace frictherm::coupling
