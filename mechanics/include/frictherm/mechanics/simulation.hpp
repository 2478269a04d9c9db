#pragma once
// Explicit MPM. Without contact all deformable materials share one velocity field (contact "for
// free": stick, no interpenetration). With contact enabled (enable_contact) every material has its
// own velocity field over the box of nodes its particles touch, and nodes reached by two or more
// materials resolve contact with a friction law per material pair (contact.hpp).
//
// Update schemes (Buzzi et al. 2008; Nairn 2003):
//   USF  - stress updated from the extrapolated nodal velocities before the forces are computed;
//   USL  - stress updated after the momentum update, from the new nodal velocities;
//   MUSL - USL, but the new particle velocities are mapped back to the grid first (default: it
//          removes the small-mass-node noise of USL while keeping its energy behaviour).
// Time step: dt = C * min(h) / max_p (c_p + |v_p|), with C the CFL factor and c_p the particle's
// dilatational wave speed (Nairn 2018 eq. 45 with the particle speed added).
// Shape functions: linear, uGIMP, quadratic B-spline, or the extended B-spline (Kakouris 2024 §3.3),
// rebuilt at the start of every step per velocity field (each body's field with contact, the shared
// field of all deformable particles without) and used for every transfer of the step (docs/ebs.md).
// Contact pairs may instead use penalty contact on boundary material points (ContactMethod::penalty,
// Kakouris 2024; docs/penalty_contact.md): the boundary loops of each body come from its region,
// the penalty forces join the nodal forces before the momentum update, the points move with their
// field's new grid velocity, and the frictional heat goes to frictional_work() like the
// multimaterial heat.
#include <frictherm/mechanics/contact.hpp>
#include <frictherm/mechanics/ebs.hpp>
#include <frictherm/mechanics/energy/energy_books.hpp>  // EnergyBalance
#include <frictherm/mechanics/geometry.hpp>
#include <frictherm/mechanics/grid.hpp>
#include <frictherm/mechanics/loads.hpp>
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/particles.hpp>
#include <frictherm/mechanics/penalty_contact.hpp>
#include <frictherm/mechanics/shape_functions.hpp>
#include <frictherm/mechanics/state/body_list.hpp>
#include <frictherm/mechanics/state/body_loops.hpp>
#include <frictherm/mechanics/state/contact_books.hpp>
#include <frictherm/mechanics/state/contact_node_state.hpp>
#include <frictherm/mechanics/state/contact_setup.hpp>
#include <frictherm/mechanics/state/ebs_state.hpp>
#include <frictherm/mechanics/state/field_layout.hpp>
#include <frictherm/mechanics/state/loads_and_conditions.hpp>
#include <frictherm/mechanics/state/nodal_fields.hpp>
#include <frictherm/mechanics/state/penalty_contact_state.hpp>
#include <frictherm/mechanics/state/stencil_store.hpp>
#include <frictherm/mechanics/state/step_clock.hpp>
#include <frictherm/mechanics/state/step_schedule.hpp>
#include <frictherm/mechanics/state/step_threads.hpp>
#include <frictherm/mechanics/state/wave_speeds.hpp>
#include <frictherm/mechanics/state/work_books.hpp>
#include <frictherm/mechanics/step/contact_method.hpp>
#include <frictherm/mechanics/step/phase_list.hpp>
#include <frictherm/mechanics/step/rigid_driver.hpp>
#include <frictherm/mechanics/step/step_load.hpp>
#include <frictherm/mechanics/step/velocity_filter.hpp>
#include <frictherm/mechanics/step_timing.hpp>
#include <frictherm/mechanics/thread_partition.hpp>
#include <frictherm/mechanics/transfer.hpp>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace frictherm::mechanics {

enum class UpdateScheme { usf, usl, musl };
UpdateScheme update_scheme_from_string(const std::string& name);  // throws std::invalid_argument
const char* to_string(UpdateScheme s);

struct SimulationOptions {
  Analysis analysis = Analysis::plane_strain;  // 2D: plane_strain or plane_stress; 3D: three_d
  double thickness = 1.0;                      // 2D out-of-plane thickness (m)
  ShapeKind shape = ShapeKind::ugimp;
  double ebs_occupation = 0.75;                // extended_bspline: C_c, a cell is interior if φ_c > C_c (Kakouris 2024 eq. 20)
  UpdateScheme scheme = UpdateScheme::musl;
  double cfl = 0.5;                            // C in (0, 1]
  // FLIP/PIC blend v_p ← (1 − α) v_p^FLIP + α Σ S_ip v_i with α = 1 − e^(−Δt/τ): the particle velocity
  // modes the grid cannot see decay as e^(−t/τ) whatever the time step (∞: pure FLIP).
  double pic_relaxation_time = std::numeric_limits<double>::infinity();
  // Grid-to-particle transfer (transfer.hpp): FLIP (with the PIC blend above), XPIC(m) or FMPM(k);
  // transfer_order is m or k (≥ 1; XPIC(1) and FMPM(1) are PIC).
  ParticleUpdate particle_update = ParticleUpdate::flip;
  int transfer_order = 1;
  // Mass-proportional (Rayleigh) damping f_i −= c p_i at every node while t < damping_until: a
  // quasi-static preload (dynamic relaxation) that leaves the body at rest instead of ringing. It
  // damps every mode the grid carries, unlike the PIC blend. 0: none.
  double damping_rate = 0.0;   // c (1/s)
  double damping_until = 0.0;  // s
  double max_time_step = std::numeric_limits<double>::infinity();
  Vec<3> gravity = Vec<3>::Zero();             // body force per unit mass (m/s^2)
};


template <int Dim>
struct ContactSide;  // contact internals (mechanics/src/contact_side.hpp)
// The contact methods (step/contact_method.hpp; mechanics/src/contact_methods/): their phases call
// the step's contact passes below.
template <int Dim>
class MultimaterialContactMethod;
template <int Dim>
class PenaltyContactMethod;
// The loads (step/step_load.hpp; mechanics/src/loads/): their phases call the step's load passes.
template <int Dim>
class ParticleLoads;
template <int Dim>
class MassDamping;
// The grid-velocity filters (step/velocity_filter.hpp; mechanics/src/filters/).
template <int Dim>
struct VelocityFilterPhases;
// The rigid drivers (step/rigid_driver.hpp; mechanics/src/rigids/).
template <int Dim>
class PrescribedRigidVelocity;

template <int Dim>
class Simulation {
 public:
  explicit Simulation(const Grid<Dim>& grid, const SimulationOptions& options = {});

  // ---- set-up -----------------------------------------------------------------------------
  int add_material(const Material& m);
  /// Fills `region` with particles on a regular lattice of `ppc` points per cell per direction.
  /// Points already taken by an earlier body are skipped. Returns the body id.
  int add_body(const std::string& name, const Region<Dim>& region, int ppc, const Vec<Dim>& velocity,
               double temperature = 293.15);
  void fix_face(const FixedFace& face);
  void add_point_load(const PointLoad<Dim>& load);
  void add_edge_traction(const EdgeTraction<Dim>& load);
  /// The point loads and tractions resolved to particles (after finalize(): particle indices in the
  /// finalized order), in the order the step applies them; what a decomposed run of the same scene
  /// applies (DecomposedMpm::Options::loads).
  std::vector<ParticleLoad<Dim>> particle_loads() const;
  /// Turns on contact (one velocity field per material); before finalize(), and before add_body()
  /// when the penalty boundary spacing is set.
  void enable_contact(const ContactOptions& options);
  /// Settings of one material pair (order matters only for a specified normal: from a to b).
  /// Penalty pairs (2D only) take a coulomb or frictionless law.
  void set_contact_pair(int material_a, int material_b, const ContactPairSettings& settings);
  /// Replaces the boundary loops of a body (penalty contact; material on the left of each loop),
  /// e.g. for an image body, whose region has none. Before finalize().
  void set_body_boundary(int body, const std::vector<std::vector<Vec<2>>>& loops);
  /// Groups particles by material and resolves loads; called by the first step if not before.
  void finalize();

  // ---- stepping ---------------------------------------------------------------------------
  /// Stable time step from the CFL condition at the current state.
  double stable_time_step() const;
  /// Advances one step of min(stable_time_step, dt_limit); returns the step taken.
  /// Throws SimulationError if the new state has non-finite values or a particle left the grid.
  double step(double dt_limit = std::numeric_limits<double>::infinity());

  // ---- state ------------------------------------------------------------------------------
  const Grid<Dim>& grid() const { return grid_; }
  const SimulationOptions& options() const { return opt_; }
  SimulationOptions& options() { return opt_; }
  const Particles<Dim>& particles() const { return p_; }
  Particles<Dim>& particles() { return p_; }
  const NodalFields<Dim>& nodes() const { return nodes_; }
  const std::vector<VelocityField<Dim>>& fields() const { return fields_; }
  /// Grid node of each slot of nodes().
  const std::vector<int>& slot_nodes() const { return layout_.slot_node; }
  bool contact_enabled() const { return contact_setup_.enabled; }
  const ContactOptions& contact_options() const { return contact_setup_.options; }
  const ContactPairSettings& contact_pair(int material_a, int material_b) const;
  const ContactStats& contact_stats() const { return contact_books_.stats; }
  /// The pairs given settings with set_contact_pair, in call order.
  const std::vector<std::pair<int, int>>& contact_pairs() const { return contact_setup_.explicit_pairs; }
  /// Penalty contact (after finalize()): nullptr without penalty pairs; pair k of it is
  /// penalty_pairs()[k]. Its books hold the last step's forces and the heat per pair.
  const PenaltyContact<Dim>* penalty_contact() const { return penalty_state_.contact ? &*penalty_state_.contact : nullptr; }
  const std::vector<PenaltyPairInfo>& penalty_pairs() const { return penalty_state_.pairs; }
  /// Boundary material points of the bodies in penalty pairs (field = velocity field index). The
  /// mutable access is for set-up (e.g. shifting a body with its particles before the first step).
  const BoundaryPoints<Dim>& boundary_points() const { return penalty_state_.boundary; }
  BoundaryPoints<Dim>& boundary_points() { return penalty_state_.boundary; }
  /// Frictional work of the last step per grid node (J), added once per contact node (eqs. 27, 34,
  /// 36, 40): what the coupling hands to the thermal solver. All zeros without contact.
  const std::vector<double>& frictional_work(HeatingOrder order) const {
    return order == HeatingOrder::first ? contact_books_.work_first : contact_books_.work_second;
  }
  /// Frictional work since the start (J): all pairs, or the unordered pair (a, b).
  double cumulative_frictional_work(HeatingOrder order) const;
  double cumulative_frictional_work(HeatingOrder order, int material_a, int material_b) const;
  const std::vector<Material>& materials() const { return materials_; }
  const std::vector<BodyInfo>& bodies() const { return bodies_.info; }
  /// extended_bspline: the extended basis of each velocity field (fields()[f]) as rebuilt at the
  /// start of the last step (classification, counts); empty for the other shape functions.
  const std::vector<EbsBasis<Dim>>& extended_bases() const { return ebs_.bases; }
  double time() const { return clock_.time; }
  long step_count() const { return clock_.step; }
  double last_time_step() const { return clock_.last_dt; }
  /// Wall time spent in each phase of step() since the start.
  const StepPhaseTimes& phase_times() const { return schedule_.times; }
  /// The names of the step's phases in order, for this scene's scheme and options (finalizes).
  std::vector<const char*> step_phase_names();
  /// The shape functions of every particle at the current positions, read-only, for code outside the
  /// step (the thermal coupling's M, K and map back: Nairn et al. 2018 eqs. 37-38 use the same
  /// S_ip and G_ip). They are the stencils the next step starts from: evaluated here if the last
  /// step moved the particles (timed as the step's shape_functions phase), and the next step then
  /// uses them instead of evaluating them again (same inputs, same numbers). Valid until the
  /// particles move (the next step). A change of positions or half-sizes through particles() between
  /// steps must be followed by forget_stencils(). Empty for the extended B-spline (built per field
  /// inside the step) and before finalize().
  StencilView<Dim> current_stencils();
  /// Drops the stencils current_stencils() evaluated (the next step evaluates its own).
  void forget_stencils() { stencil_store_.current = false; }

  double kinetic_energy() const;  // of deformable particles (J)
  /// Energy stored in the deformable materials (J): elastic strain energy (linear elastic, neo-Hookean)
  /// and, for Mie-Grüneisen, the equation-of-state energy m e − W_p plus the shear energy V s:s/(4G)
  /// (simulation_energy.cpp).
  double strain_energy() const;
  Vec<Dim> linear_momentum() const;  // of deformable particles (kg m/s)
  /// Work done by external loads and body force so far (J), accumulated each step.
  double external_work() const { return work_books_.external; }
  /// Work done by rigid materials (walls, pistons) on the deformable bodies so far (J): per step the
  /// momentum the rigid fields and rigid velocity conditions give the deformable material in the
  /// momentum update (what the particles receive) times the rigid velocity.
  double rigid_work() const { return work_books_.rigid; }
  /// Energy removed by the mass-proportional damping so far (J, ≥ 0): c |p_i|²/m_i dt per node and step.
  double damping_work() const { return work_books_.damping; }
  /// Energy removed by the normal contact impulses (contact_pair.hpp normal_stop_work) and by the
  /// velocity conditions' stops (energy_books.hpp condition_stop_work) since the start (J).
  double contact_normal_work() const { return work_books_.contact_normal; }
  double boundary_stop_work() const { return work_books_.boundary_stop; }
  /// Plastic work of the particles so far, Σ_p σ:Δε_p V (J).
  double plastic_work() const;
  /// The energy books now (frictional work of `order`). Before the first step initial = kinetic + stored.
  EnergyBalance energy_balance(HeatingOrder order) const;

  // ---- checkpoint -------------------------------------------------------------------------
  /// Calls v(name, member) for every member that changes while stepping and that the next step
  /// reads: with these restored into a simulation built from the same set-up (after finalize()),
  /// stepping continues bit-for-bit. Members are std::vector<T> (T double, int32, uint64 or a
  /// fixed-size Eigen type) or double, long, bool; visitors declare `static constexpr bool reading`.
  /// Penalty contact adds its boundary points and slip histories (PenaltyContact::visit_state); EBS
  /// bases, contact nodes and nodal fields are rebuilt each step from these.
  template <class Visitor> void visit_state(Visitor&& v) {
    if (!finalized_) finalize();
    if constexpr (std::decay_t<Visitor>::reading) stencil_store_.current = false;  // positions may change
    v("particles/position", p_.position);
    v("particles/initial_position", p_.initial_position);
    v("particles/velocity", p_.velocity);
    v("particles/half_size", p_.half_size);
    v("particles/mass", p_.mass);
    v("particles/initial_volume", p_.initial_volume);
    v("particles/volume", p_.volume);
    v("particles/deformation_gradient", p_.deformation_gradient);
    v("particles/stress", p_.stress);
    v("particles/stress_zz", p_.stress_zz);
    v("particles/temperature", p_.temperature);
    v("particles/plastic_strain", p_.plastic_strain);
    v("particles/internal_energy", p_.internal_energy);
    v("particles/plastic_work", p_.plastic_work);
    v("particles/material", p_.material);
    v("particles/body", p_.body);
    v("time", clock_.time);
    v("step", clock_.step);
    v("last_dt", clock_.last_dt);
    v("external_work", work_books_.external);
    v("rigid_work", work_books_.rigid);
    v("damping_work", work_books_.damping);
    v("contact_normal_work", work_books_.contact_normal);
    v("boundary_stop_work", work_books_.boundary_stop);
    v("initial_energy", work_books_.initial_energy);
    v("stored_energy_lead", work_books_.stored_lead);  // (checkpoint format 4, checkpoint_io.hpp)
    v("stress_power", work_books_.stress_power);
    v("stress_dt", work_books_.stress_dt);
    v("work_first", contact_books_.work_first);
    v("work_second", contact_books_.work_second);
    v("pair_work_first", contact_books_.pair_work_first);
    v("pair_work_second", contact_books_.pair_work_second);
    v("wave_speed", wave_speeds_.speed);
    v("wave_speed_ready", wave_speeds_.ready);
    if (contact_setup_.options.regularized()) {
      v("contact/lagged_normal_traction", contact_nodes_.lagged_normal_traction);
      v("contact/lagged_normal_step", contact_nodes_.lagged_normal_step);
    }
    // The last step's contact counters: only reported (series rows of a thermal continuation).
    for (auto [name, x] : {std::pair<const char*, long*>{"contact_stats/contact_nodes", &contact_books_.stats.contact_nodes},
                           {"contact_stats/multi_nodes", &contact_books_.stats.multi_nodes},
                           {"contact_stats/sliding_nodes", &contact_books_.stats.sliding_nodes},
                           {"contact_stats/guarded", &contact_books_.stats.guarded},
                           {"contact_stats/penalty_contacts", &contact_books_.stats.penalty_contacts},
                           {"contact_stats/penalty_sliding", &contact_books_.stats.penalty_sliding}})
      v(name, *x);
    if (penalty_state_.contact) {  // penalty contact: the boundary points move with the bodies; slip histories
      v("boundary/position", penalty_state_.boundary.position);
      v("boundary/velocity", penalty_state_.boundary.velocity);
      penalty_state_.contact->visit_state(v);
    }
  }

 private:
  friend class MultimaterialContactMethod<Dim>;
  friend class PenaltyContactMethod<Dim>;
  friend class ParticleLoads<Dim>;
  friend class MassDamping<Dim>;
  friend struct VelocityFilterPhases<Dim>;
  friend class PrescribedRigidVelocity<Dim>;
  using ContactEntry = typename ContactNodeState<Dim>::Entry;
  using ContactNodeListing = typename ContactNodeState<Dim>::Listing;
  using ContactThreadWork = typename ContactNodeState<Dim>::ThreadWork;
  // The step as phase lists (step/phase_list.hpp; simulation_step.cpp): built by the first step and
  // again when a setting they depend on changes (phase_key()).
  template <class Kernel> void build_phases();
  void build_phases();
  long phase_key() const;
  template <class Kernel> void prepare_step();  // threads, partition, stencils, field layout
  template <class Kernel> void contact_at_extrapolated(double dt);  // contact nodes, extents, first pass
  template <class Kernel> void stress_pass(double dt);  // USF, MUSL: the stress update alone
  void end_particle_update(StepContext& ctx, bool refreshed);  // time and step advance, particle checks
  // stable_time_step in parts (simulation_setup.cpp): the step takes the particles' largest speed in
  // its particle-to-grid scatter when the wave speeds are current (threads_.speed_max).
  bool wave_speeds_current() const;
  double particle_speed_max() const;             // max_p c_p + |v_p| (0 without deformable particles)
  double time_step_for_speed(double cmax) const;  // the CFL step for it, with rigid, contact and damping bounds
  /// take_speeds: also each part's largest c_p + |v_p| into threads_.speed_max (the CFL speed).
  template <class Kernel> void map_to_grid(bool with_forces, bool take_speeds);
  template <class Kernel> void add_internal_forces();
  template <class Kernel> void remap_momentum();
  /// The particle loops after the grid update (simulation_particle_pass.cpp): grid-to-particle
  /// (Kinematics), stress update from nodes_.velocity (Stress), or both in one pass (USL).
  struct ParticlePassResult {
    long bad = -1;     // the first particle with a non-finite state or outside the grid (check_particle)
    long beyond = -1;  // the first compressed past its Hugoniot's limit (throw_beyond_hugoniot)
    StressPower stress_power;  // Σ_p V_p σ_p:L_p before (stress-only passes) and after the update (W)
  };
  /// `refresh` (grid-to-particle with Stencil arrays): also the next step's stencils at the moved
  /// positions, the rigid materials moved (by layout_.rigid_motion, which the rigid driver sets:
  /// rigids/prescribed_velocity.cpp) and layout_.box_lo/layout_.box_hi, in the same pass.
  template <bool Kinematics, bool Stress, class Stencils>
  ParticlePassResult particle_pass(double dt, Stencils& st, bool refresh = false);
  void throw_beyond_hugoniot(long particle) const;  // particle >= 0: compressed past its Hugoniot's limit
  /// The step's stencils of kernel `Kernel`: vector of Stencil, or PrecomputedStencils for EBS.
  template <class Kernel> StencilArray<Dim, Kernel>& stencils() { return stencil_store_.template of<Kernel>(); }
  template <class Kernel> void evaluate_stencils();  // all particles; with contact also layout_.box_lo/layout_.box_hi
  void prepare_extended_stencils();  // EBS: rebuild per field, lay out the fields, flatten the weights
  void init_fields();
  void layout_fields(const std::vector<IVec<Dim>>& lo, const std::vector<IVec<Dim>>& hi);
  // Scatters under the thread partition (threads_.partition, thread_partition.hpp; simulation_fields.cpp):
  // which arrays a scatter accumulates.
  struct Accumulated {
    bool mass = false, momentum = false, force = false, contact_terms = false;
  };
  void update_partition();  // threads_.partition for threads_.count and the current fields
  /// Where thread tid scatters field f's values: the nodes themselves, or its buffer when it shares f.
  NodalFields<Dim>& scatter_target(int tid, int field) {
    return tid == threads_.partition.first_thread[static_cast<std::size_t>(field)] ? nodes_
                                                                            : threads_.nodes[static_cast<std::size_t>(tid - 1)];
  }
  void clear_scatter_targets(int tid, Accumulated which);  // inside a parallel region, before the scatter
  void sum_shared_fields(Accumulated which);  // inside a parallel region, after a barrier
  /// One scatter phase (simulation_step.cpp): a parallel region in which each part of the partition
  /// clears its targets and calls scatter(acc, index, m, k_begin, k_end) for each of its materials that
  /// has a field (rigid ones only with include_rigid), then the shared fields are summed.
  template <class Scatter> void scatter_phase(Accumulated which, bool include_rigid, Scatter&& scatter, int threads);
  /// Velocity boundary conditions on nodal momenta; with `force` (the momentum update, p + f dt to
  /// come) the forces are made consistent instead, and the rigid bodies' work is returned (0 without).
  double apply_velocity_bc(std::vector<Vec<Dim>>& momentum, std::vector<Vec<Dim>>* force, double dt,
                           double* stop = nullptr) const;
  // The grid update p_i^{n+1} = p_i^n + f_i dt in phases (simulation_fields.cpp).
  void save_start_velocity();                  // XPIC: v^n = p^n/m, before the momentum update
  void apply_grid_velocity_conditions(double dt);  // velocity conditions on p and f, rigid work
  void apply_damping(double dt);               // −c p_i on the free components, damping work
  void advance_grid_momentum(double dt);       // p_i += f_i dt
  void nodal_velocities();                     // v_i = p_i/m_i, a_i = f_i/m_i, driven components
  /// XPIC/FMPM (transfer.hpp): transfer_.filtered = Σ_{j<order} (I − S⁺S)^j w0 per deformable field,
  /// w0 = transfer_.start (XPIC) or nodes_.velocity (FMPM); simulation_transfer.cpp.
  template <class Stencils> void filter_grid_velocity(const Stencils& st);
  void velocity_from_momentum();
  enum class ContactPass { extrapolated, updated, remapped };
  void find_contact_nodes();
  void resolve_contact(ContactPass pass, double dt);
  /// Contact node `group`'s materials above min_mass_fraction (with the extent gap when measured),
  /// their slots, materials and contact entries; returns how many slivers were left out.
  int gather_contact_sides(std::size_t group, double dt, std::vector<ContactSide<Dim>>& sides, std::vector<int>& slots,
                           std::vector<int>& mats, std::vector<int>& entries) const;
  void compute_contact_normals();                                // extent separation: contact_nodes_.entry_normal
  template <class Stencils> void measure_contact_extents(const Stencils& st);  // extent separation: contact_extents.cpp
  using ResolvedLoad = typename LoadsAndConditions<Dim>::ResolvedLoad;
  void check_penalty_settings(const ContactPairSettings& s, int a, int b) const;  // throws std::invalid_argument
  void setup_penalty();                          // finalize(): penalty pairs and boundary points
  void apply_penalty_forces();                   // step: detection, forces into nodes_.force, heat
  void move_boundary_points(double dt, double t);  // step: with the new nodal momenta
  double penalty_wave_factor() const;            // time step: √(ε/(E/Δh)) when a penalty is stiffer than eq. 40
  double penalty_time_step_limit(double wave_speed) const;  // time step: the last step's penalty springs
  void check_particle(long bad, double dt) const;
  void resolve_loads();
  /// Energy stored by the contact methods (penalty springs), for the energy books.
  double contact_stored_energy() const {
    double e = 0.0;
    for (const StepContactMethod<Dim>* m : contact_methods_) e += m->stored_energy(*this);
    return e;
  }

  Grid<Dim> grid_;
  SimulationOptions opt_;
  Particles<Dim> p_;
  std::vector<Material> materials_;
  BodyList bodies_;                         // the bodies and the fill lattice they took
  NodalFields<Dim> nodes_;
  std::vector<VelocityField<Dim>> fields_;
  FieldLayout<Dim> layout_;                 // materials -> particle ranges, fields, node boxes; slot -> node
  ContactSetup contact_setup_;              // contact on/off, options, per-pair settings
  ContactNodeState<Dim> contact_nodes_;     // the step's contact nodes, extents, lagged normal traction
  ContactBooks contact_books_;              // frictional work per node and per pair, contact counters
  PenaltyContactState<Dim> penalty_state_;  // boundary points, penalty pairs and their histories
  BodyLoops<Dim> body_loops_;               // per body: boundary loops the boundary points come from
  StepThreads<Dim> threads_;                // thread count, partition, pass split, scatter buffers
  struct TransferScratch {  // XPIC/FMPM, per slot
    std::vector<Vec<Dim>> start;     // XPIC: lumped v^n at the momentum update
    std::vector<Vec<Dim>> filtered;  // v* (the series' sum)
    std::vector<Vec<Dim>> term;      // (I − S⁺S)^j w0
    std::vector<Vec<Dim>> round_trip;  // S⁺S term
    std::vector<std::vector<Vec<Dim>>> thread_acc;  // per-thread scatter buffers (threads 1..n-1)
  } transfer_;
  LoadsAndConditions<Dim> conditions_;      // fixed/rigid node masks, faces, loads, resolved loads
  StencilStore<Dim> stencil_store_;         // S_ip, G_ip of every particle for the scene's kernel
  EbsState<Dim> ebs_;                       // extended B-spline basis per field
  bool finalized_ = false;                  // finalize() has run
  StepClock clock_;                         // time, step count, last dt
  WorkBooks work_books_;                    // external, rigid and damping work; initial energy
  double empty_node_mass_ = 0.0;  // nodes lighter than this have no velocity (1e-12 of the heaviest particle)
  WaveSpeeds wave_speeds_;                  // per-particle wave speed for the CFL step
  StepSchedule schedule_;                   // the step's phase list and phase timers
  std::vector<const StepContactMethod<Dim>*> contact_methods_;  // the scene's, chosen by finalize() (contact_methods_for)
};

extern template class Simulation<2>;
extern template class Simulation<3>;

}  // namespace frictherm::mechanics
