#pragma once
// Decomposed MPM on PETSc, 2D and 3D (issue 16, "Beyond one machine"): the structured grid as a DMDA
// (DMDACreate2d / DMDACreate3d) whose points are the grid's nodes (the serial Grid<Dim>'s nodes, its
// ghost layer included), particles in a DMSwarm of type DMSWARM_PIC with the DMDA as cell DM, and one
// explicit USL step with optional multimaterial contact and frictional heating (Nairn, Bardenhagen &
// Smith 2018), fixed grid faces, rigid boundary materials and gravity, written as a list of named
// phases in which the exchanges are phases of their own (docs/distributed.md). DecomposedMpm<Dim> is
// instantiated for Dim = 2 and 3; DecomposedMpm2D, DecomposedParticle, DecomposedOptions and
// DecomposedStencils name the 2D ones.
//
// Materials: linear elastic (hypoelastic, Jaumann), Neo-Hookean (Kakouris 2024 eq. 47) and the PBX
// materials, Mie-Grüneisen pressure with elastic shear and J2 plasticity (mie_gruneisen.hpp; 2D plane
// strain through plane_strain_update.hpp), by the serial step's own inline functions; the swarm
// carries their state (ε̄p, e, plastic work, wave speed) with the particles. Rigid materials act as
// velocity conditions on the nodes their particles touch (the serial rigid_boundary materials; every
// rigid material without contact), prescribing the components they control; a rigid contact partner
// (rigid_boundary = false with contact) stays serial. stable_time_step() is the serial CFL step over
// all ranks. docs/distributed_pbx.md: these pieces, their tests and the many-materials benchmark.
//
//   particle_to_grid       local: stencils; rigid particles mark the nodes they drive; per velocity
//                          field m_i, p_i, f_i (N·1–3) and, with contact, Σ S m x (or the displacement
//                          form), Ω_i, g_i (N·4–6, 9), into the field's box of slots; the point
//                          loads and tractions of the rank's particles (f_i += S_ip F)
//   sum_to_owners          exchange: every node's m, p, f summed over its fields into the DMDA,
//                          DMLocalToGlobal(ADD_VALUES) into the owners; the rigid drivers to the owners
//   exchange_field_ranges  exchange (PetscSF): which materials reach each node, completed at the
//                          owner; the multi-material flag back to every rank holding the node
//   fields_to_owners       exchange (PetscSF): per-material sums at multi-material ghost nodes placed
//                          at the owner (fetch-and-add), summed there per material
//   find_contact_nodes     owned nodes where two or more fields have mass
//   contact_extrapolated   contact on the extrapolated momenta (N·7–18), node-local
//   momentum_update        owned nodes: rigid drive (f = (m v_rigid − p)/dt), fixed faces (p, f
//                          components zeroed), damping (f −= c p), p_i += f_i dt
//   contact_updated        contact on p^{n+1} with consistent forces (N·19) and frictional work (N·27, 34, 36, 40)
//   nodal_velocities       owned nodes: v_i = p_i/m_i, a_i = f_i/m_i; driven components v = v_rigid
//   ghost_velocities       exchange: DMGlobalToLocal(INSERT_VALUES), ghost nodes get the totals' v_i, a_i
//   fields_to_ghosts       exchange (PetscSF): per-material v_i, a_i back to the ranks that sent the sums
//   grid_to_particle       FLIP: v_p += dt Σ S_ip a_i, x_p += dt Σ S_ip v_i (the particle's own field);
//                          rigid particles move with their prescribed velocity
//   stress_update          L_p = Σ v_i ⊗ G_ip, F ← (I + L dt) F, V = det F V0, the material's stress
//   migrate                exchange: DMSwarmMigrate, each particle to the rank owning its nearest node
//
// MUSL (Options::musl, without contact) runs particle_to_grid, sum_to_owners, momentum_update,
// nodal_velocities, ghost_velocities, grid_to_particle, then
//   remap_momentum         local: p_i = Σ S_ip m_p v_p^{n+1} into the slots (start-of-step stencils)
//   sum_to_owners          exchange, as above
//   velocity_from_momentum owned nodes: driven components p = m v_rigid, fixed ones 0; v_i = p_i/m_i
//   ghost_velocities       exchange, as above
// and stress_update, migrate (the serial MUSL list, simulation_step.cpp).
//
// USF (Options::usf) runs particle_to_grid (m, p only) and the exchanges and contact pass that
// follow it, then
//   velocity_from_momentum owned nodes: as above, the post-condition momenta kept for the momentum update
//   ghost_velocities, fields_to_ghosts, stress_update (from these velocities)
//   internal_forces        local: f_i = Σ (S_ip m_p g − V_p σ_p G_ip) and the loads into the slots
//   forces_to_owners       exchange: the forces summed to the owners (DMDA, per-field entries), the
//                          kept momenta back
// and USL's list from momentum_update on (the serial USF list, simulation_step.cpp).
//
// XPIC and FMPM (Options::particle_update) add, in every list,
//   start_velocity         owned nodes (XPIC): v^n = p/m before the momentum update
//   velocity_filter        before grid_to_particle: v* = Σ_{j<order} (I − S⁺S)^j w0 per field, each
//                          term's round trip over the local particles, its sums to the owners and the
//                          next term back to the ghosts (a Dim-vector DMDA and the per-field entries)
// and grid_to_particle reads v* (velocity_filter.cpp).
//
// Velocity fields: without contact every deformable material shares one field (as the serial
// Simulation); with contact each material has its own. Each rank stores each field over the box of
// local nodes its local particles' stencils reach (the serial layout_fields), so memory and work
// scale with the particles (field_slots()), not with materials × ghosted box. A node that one material
// reaches (on every rank) needs no per-material data: the DMDA's total is that material's field. Only
// at shared nodes that two or more materials reach do per-material values travel, as (node, material)
// entries over a PetscSF rebuilt each step (mechanics/src/distributed/sparse_exchange.cpp).
//
// Ownership: a particle belongs to the rank that owns the grid node nearest to it (the node's dual
// cell [x_n − h/2, x_n + h/2) along every axis). With that rule the stencil of the linear, uGIMP
// (l_p ≤ h/2) and quadratic B-spline kernels reaches one node beyond the nearest node on either side
// along each axis, so the DMDA's stencil width is 1 in 2D and 3D; it is measured from the kernel's
// own evaluation (stencil_reach), not assumed. The extended B-spline reaches search_radius + 2
// nodes (its extension stencils sit on the nearest interior cell); its per-body bases are the serial
// EbsBasis rebuilt on every rank from the body's particles gathered from all ranks
// (mechanics/src/distributed/extended_bsplines.cpp).
// Contact is resolved at owned nodes only, after the one exchange that completes their sums, by the
// serial module's node-local code (mechanics/src/contact_pair.hpp, templated on Dim).
// For coupled physics (the coupling's decomposed heat conduction, 2D and 3D) the run also carries named
// per-particle scalars in the swarm and offers the step's maps without physics: the particles' current
// stencils in local node numbering, local node values summed into their owners, owner values to the
// ghosts (transfer.cpp).
// Only this library needs PETSc; its header needs MPI only.
#include <frictherm/mechanics/contact.hpp>
#include <frictherm/mechanics/energy/energy_books.hpp>
#include <frictherm/mechanics/grid.hpp>
#include <frictherm/mechanics/loads.hpp>
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/penalty_contact.hpp>
#include <frictherm/mechanics/shape_functions.hpp>
#include <frictherm/mechanics/transfer.hpp>
#include <frictherm/mechanics/types.hpp>

#include <mpi.h>

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>
#include <utility>

namespace frictherm::mechanics {

/// PETSc initialised for the lifetime of the object (MPI too unless already initialised). A
/// process that already holds PETSc (e.g. through the distributed thermal solve) may create it too:
/// it then neither initialises nor finalises.
class DecomposedPetscSession {
 public:
  DecomposedPetscSession(int* argc, char*** argv);
  ~DecomposedPetscSession();
  DecomposedPetscSession(const DecomposedPetscSession&) = delete;
  DecomposedPetscSession& operator=(const DecomposedPetscSession&) = delete;

 private:
  bool owns_ = false;
};

/// Nodes beyond the particle's nearest node that a kernel's stencil reaches, the largest over a
/// cell (sampled on both sides of every break point of the kernel's node choice): the DMDA's
/// stencil width (the same along every axis: the stencils are tensor products). lp = h/2 for uGIMP
/// (its widest particle).
int stencil_reach(ShapeKind kind);

/// Settings of one material pair in contact (as Simulation::set_contact_pair).
struct DecomposedContactPair {
  int material_a = 0, material_b = 1;
  ContactPairSettings settings;
};

/// This rank's particles in swarm order (the order of the stencils and particle scalars).
struct DecomposedLocalParticles {
  std::vector<std::int64_t> id;
  std::vector<double> mass;    // m_p (kg; kg per unit thickness in 2D)
  std::vector<double> volume;  // V_p (m³; m² per unit thickness in 2D)
  std::vector<int> material;
  /// With local_particle_data(true): x_p, v_p and the uGIMP half-widths l_p, Dim values per particle
  /// (hot spots and output of a decomposed run read them without gathering every particle).
  std::vector<double> position, velocity, half_size;
  /// Plastic work done on each particle since the start (J; 0 for non-plastic materials).
  std::vector<double> plastic_work;
  /// With kinematics also the initial positions X_p (Dim per particle), the stress σ_p (Dim² per
  /// particle, Eigen's column-major Mat<Dim>) and the 2D out-of-plane σ_zz (0 in 3D).
  std::vector<double> initial_position, stress, stress_zz;
};

/// Contact counters of the last step, summed over ranks (as the serial ContactStats).
struct DecomposedContactStats {
  long contact_nodes = 0, multi_nodes = 0, sliding_nodes = 0, guarded = 0;
};

/// Traffic of the exchange phases, this rank's view, accumulated over steps.
struct DecomposedTraffic {
  long steps = 0;
  long ghost_nodes = 0;               // nodes of the local (ghosted) vector this rank does not own
  int values_per_node = 0;            // doubles per node in each grid exchange (1 + 2·Dim)
  long particles_sent = 0;            // by migration, over all steps
  long particles_received = 0;
  int particle_bytes = 0;             // payload per migrated particle (all swarm fields)
  // Per-field exchanges (contact): ghost nodes this rank found multi-material and (ghost node,
  // field) entries it sent to their owners (and received back), over all steps; bytes per entry.
  long multi_ghost_nodes = 0;
  long field_entries_sent = 0;
  int field_entry_bytes = 0;
  std::array<double, 18> phase_seconds{};  // per phase, in phase_names() order
};

template <int Dim>
class DecomposedMpm {
  static_assert(Dim == 2 || Dim == 3, "the decomposed MPM step is 2D or 3D");

 public:
  /// One particle as given to and gathered from the decomposed run.
  struct Particle {
    std::int64_t id = 0;   // global id, kept through migration
    double mass = 0.0;     // m_p (kg; kg per unit thickness in 2D)
    double volume = 0.0;   // V_p, current
    Vec<Dim> position = Vec<Dim>::Zero();
    Vec<Dim> velocity = Vec<Dim>::Zero();
    Vec<Dim> half_size = Vec<Dim>::Zero();  // uGIMP half-widths l_p (fixed)
    Mat<Dim> stress = Mat<Dim>::Zero();
    double stress_zz = 0.0;  // 2D plane strain σ_zz; unused (0) in 3D
    int material = 0;        // index into the materials given to DecomposedMpm
    /// Per-particle state of the Mie-Grüneisen/J2 materials (as Particles<Dim>): equivalent plastic
    /// strain ε̄p, specific internal energy e (J/kg) and the plastic work done on the particle since
    /// the start (J). Zero (and unchanged) for the other materials.
    double plastic_strain = 0.0;
    double internal_energy = 0.0;
    double plastic_work = 0.0;
    /// Values of Options::particle_scalars, in that order (empty: zeros).
    std::vector<double> scalars;
  };

  struct Options {
    ShapeKind shape = ShapeKind::linear;
    /// Extended B-splines (shape extended_bspline): C_c, as SimulationOptions::ebs_occupation.
    double ebs_occupation = 0.75;
    /// 2D: plane_strain or plane_stress; 3D: three_d (as the serial Simulation<3> sets it).
    Analysis analysis = Dim == 2 ? Analysis::plane_strain : Analysis::three_d;
    double thickness = 1.0;               // 2D out-of-plane thickness (m), as SimulationOptions::thickness; unused in 3D
    Vec<Dim> gravity = Vec<Dim>::Zero();  // body force per unit mass (m/s²)
    /// The update scheme: USL (false) or MUSL (true: after the grid-to-particle update the momenta are
    /// remapped from the particles, p_i = Σ S_ip m_p v_p, and the stress is updated from v_i = p_i/m_i,
    /// as the serial UpdateScheme::musl); MUSL without contact only.
    bool musl = false;
    /// USF (true; not with musl): the stress updated from the extrapolated grid velocities before the
    /// forces, as the serial UpdateScheme::usf. particle_to_grid scatters m and p only; after the
    /// extrapolated contact pass velocity_from_momentum (the momenta kept), ghost_velocities,
    /// fields_to_ghosts and stress_update, then internal_forces (f_i from the new stress and the
    /// loads into the slots) and forces_to_owners (their exchange, DMDA and per-field entries), and
    /// the USL list from the momentum update on (scheme_phases.cpp).
    bool usf = false;
    /// FLIP/PIC blend time τ (s), as SimulationOptions::pic_relaxation_time: after the FLIP update
    /// v_p ← (1 − α) v_p + α Σ S_ip v_i, α = 1 − e^(−dt/τ); infinity: pure FLIP.
    double pic_relaxation_time = std::numeric_limits<double>::infinity();
    /// Grid-to-particle transfer (transfer.hpp), as SimulationOptions::particle_update and
    /// transfer_order: FLIP, XPIC(m) or FMPM(k), the filters' Neumann series over the ranks with a
    /// Dim-vector exchange per term (velocity_filter.cpp).
    ParticleUpdate particle_update = ParticleUpdate::flip;
    int transfer_order = 1;
    std::vector<FixedFace> fixed_faces;   // grid faces with velocity components fixed to 0 (Simulation::fix_face)
    /// Multimaterial contact (one velocity field per material), as Simulation::enable_contact and
    /// set_contact_pair. Supported: multimaterial pairs with any friction law, separation position,
    /// displacement or velocity_only; refused: penalty pairs, extent separation, regularisation.
    bool contact = false;
    ContactOptions contact_options;
    std::vector<DecomposedContactPair> contact_pairs;
    /// Point loads and tractions resolved to particles by id (Simulation::particle_loads of the
    /// scene's serial build): the rank holding a loaded particle adds f_i += S_ip F(t) to its slots in
    /// particle_to_grid (summed to the owners with the rest, so each load counts once) and books the
    /// work F(t)·v_p dt in grid_to_particle (the serial kernels, loads/grid_loads.hpp).
    std::vector<ParticleLoad<Dim>> loads;
    /// Mass-proportional damping f_i −= c p_i while t < damping_until, at the owned nodes in
    /// momentum_update after the velocity conditions (SimulationOptions::damping_rate, damping_until).
    double damping_rate = 0.0, damping_until = 0.0;
    /// Penalty contact (ContactMethod::penalty, Kakouris 2024 §3.4–3.7; 2D; every present pair penalty):
    /// the serial build's boundary points (Simulation::boundary_points, field = material), its pairs
    /// (PenaltyContact::pair, master and slave fields = materials), each pair's (master, slave) materials
    /// and each material's mean particle mass (the sliver test of the points' weights). Every rank holds
    /// every point and runs the serial kernels on the complete nodal fields (penalty_phases.cpp).
    BoundaryPoints<Dim> penalty_points;
    std::vector<PenaltyPairSettings> penalty_pairs;
    std::vector<std::array<int, 2>> penalty_materials;
    std::vector<double> penalty_reference_mass;
    /// Per-particle scalars the swarm carries for coupled physics (e.g. "temperature"): registered as
    /// one swarm field, migrated with the particles, untouched by the step.
    std::vector<std::string> particle_scalars;
    /// Ghost layers beyond the kernel's reach (stencil_width() = reach + this): stencils at positions
    /// up to this many cells from the current ones stay in the ghosted box (stencils_at).
    int extra_ghost_width = 0;
  };

  /// The shape functions of this rank's particles at their current positions (after the last step's
  /// migration), in the local node numbering of the rank's ghosted box (x fastest, then y, then z):
  /// particle k (swarm order) has entries [first[k], first[k+1]) with node, S_ip and G_ip (1/m), in
  /// stencil order.
  struct Stencils {
    std::vector<int> first;
    std::vector<int> node;
    std::vector<double> S;
    std::vector<Vec<Dim>> G;
  };

  /// Collective over comm. The grid is the serial Grid<Dim> (nodes −1 … cells+1 per direction);
  /// PETSc must be initialised. Throws std::invalid_argument for a material the serial
  /// add_material refuses, a rigid contact partner (rigid_boundary = false with contact), the
  /// extended B-spline, an analysis that does not fit Dim and unsupported contact settings.
  DecomposedMpm(MPI_Comm comm, const Grid<Dim>& grid, const std::vector<Material>& materials, const Options& options);
  /// One material.
  DecomposedMpm(MPI_Comm comm, const Grid<Dim>& grid, const Material& material, const Options& options);
  ~DecomposedMpm();
  DecomposedMpm(const DecomposedMpm&) = delete;
  DecomposedMpm& operator=(const DecomposedMpm&) = delete;

  /// Collective, once: each rank passes any particles (ids unique over all ranks); they are
  /// migrated to their owners. Every particle must lie inside the grid's physical region.
  void add_particles(const std::vector<Particle>& particles);

  /// One USL, MUSL or USF step of size dt (collective): the phases listed above, in that order. Throws
  /// std::runtime_error on every rank when a particle is compressed past its Hugoniot's limit.
  void step(double dt);
  static const std::array<const char*, 18>& phase_names();
  /// Penalty contact (Options::penalty_pairs): the contact of the last step, the same on every rank
  /// (nullptr without penalty pairs), and the boundary points.
  const PenaltyContact<Dim>* penalty_contact() const;
  const BoundaryPoints<Dim>& boundary_points() const;
  /// The same for checkpoints (PenaltyContact::visit_state; the points' positions and velocities):
  /// restored on every rank alike.
  PenaltyContact<Dim>* penalty_contact();
  BoundaryPoints<Dim>& boundary_points();

  int stencil_width() const;
  /// DMDA processes per direction and this rank's owned node range [begin, end) per direction
  /// (x begin, x end, y begin, y end[, z begin, z end]) in DMDA indices (= serial lattice index +
  /// Grid<Dim>::ghost).
  std::array<int, Dim> processes() const;
  std::array<int, 2 * Dim> owned_nodes() const;
  std::size_t local_particles() const;
  const DecomposedTraffic& traffic() const;

  /// Collective reductions over all ranks.
  long long global_particles() const;
  double total_mass() const;
  Vec<Dim> total_momentum() const;
  double total_momentum_scale() const;  // Σ m_p |v_p|
  /// max |v_p| over this rank's particles whose material m has counted[m] != 0 (not collective).
  double local_speed_max(const std::vector<std::uint8_t>& counted) const;
  /// Velocity fields per node (1 without contact, one per material with it).
  int velocity_fields() const;
  /// Frictional work of the last step at this rank's owned nodes (J; x fastest over owned_nodes()),
  /// added once per contact node (N·27, 34, 36, 40). Zeros without contact.
  const std::vector<double>& frictional_work(HeatingOrder order) const;
  /// Collective: frictional work since the start, summed over owned nodes and ranks (J).
  double cumulative_frictional_work(HeatingOrder order) const;
  /// Collective: the same per material pair, materials² entries at pair_book_index(a, b, materials)
  /// (as Simulation::cumulative_frictional_work(order, a, b)), summed over ranks (J).
  std::vector<double> cumulative_pair_work(HeatingOrder order) const;
  /// Collective: the last step's contact counters summed over ranks.
  DecomposedContactStats contact_stats() const;
  /// Not collective: the first friction law that threw during the last step's contact on this rank
  /// (its message naming the pair's scene key and the state), "" if none. The step went on at every
  /// rank (that node's contact as far as it got); the caller agrees on it and ends the run.
  const std::string& contact_failure() const;
  /// Collective: every particle of every rank, sorted by id, on every rank.
  std::vector<Particle> gather() const;
  /// Collective: the largest stable step over all ranks, C min(h) / max_p (c_p + |v_p|) (Nairn 2018
  /// eq. 45 with the particle speed added, as Simulation::stable_time_step), c_p the dilatational wave
  /// speed of the particle's state after the last stress update (before the first step: of its
  /// initial state), capped at max_time_step (also when no particle moves or carries a wave).
  double stable_time_step(double cfl, double max_time_step = std::numeric_limits<double>::infinity()) const;
  /// Collective: plastic work done on all particles since the start (J; Mie-Grüneisen/J2 materials).
  double total_plastic_work() const;
  /// Collective: the work of Options::loads and the energy removed by the damping since the start,
  /// summed over ranks (J; as Simulation::external_work and damping_work).
  double external_work() const;
  double damping_work() const;
  /// Collective: the mechanical energy books (J; docs/output.md "Energy balance"), the serial
  /// Simulation::energy_balance's definitions from the same kernels (energy/energy_books.hpp): kinetic
  /// and stored energy and plastic work summed over the particles, the rigid work over the owned nodes,
  /// the loads' and the damping's work, the frictional work of `order`, all over ranks (one reduction);
  /// the start energy taken at the start of the first step (before it: the current kinetic + stored).
  EnergyBalance energy_balance(HeatingOrder order) const;
  /// Velocity-field slots this rank stores (Σ over its fields of their boxes' nodes; see the header
  /// comment) and the largest over the run's steps.
  long field_slots() const;
  long peak_field_slots() const;

  // ---- Transfers for coupled physics (transfer.cpp): the particle–grid maps of the step, without
  // any physics of their own, so that a caller (the coupling's decomposed heat conduction) can
  // scatter particle values to the nodes and read node values back on the particles. ----
  MPI_Comm communicator() const;
  /// Index of a name in Options::particle_scalars; std::invalid_argument if absent.
  int particle_scalar_index(const std::string& name) const;
  /// This rank's values of one particle scalar, in swarm order; set them (same size) back.
  std::vector<double> particle_scalar(int index) const;
  void set_particle_scalar(int index, const std::vector<double>& values);
  DecomposedLocalParticles local_particle_data(bool kinematics = false) const;
  /// S_ip and G_ip at the particles' current positions, evaluated once after each step (the serial
  /// Stencil, as the step evaluates them).
  const Stencils& current_stencils();
  /// The same at positions x (Dim values per local particle, swarm order; the particles' own
  /// half-widths), e.g. where each was last gathered; std::logic_error if a stencil leaves the ghosted
  /// box (Options::extra_ghost_width widens it).
  Stencils stencils_at(const std::vector<double>& x) const;
  /// Nodes of the ghosted box (the local numbering) and, per owned node (x fastest over
  /// owned_nodes()), its local node.
  int local_node_count() const;
  const std::vector<int>& owned_local_nodes() const;
  /// The run's grid (serial lattice index = DMDA index − Grid<Dim>::ghost).
  const Grid<Dim>& grid() const;
  /// The ghosted box in DMDA indices, [begin, end) per direction as owned_nodes(): the local
  /// numbering is x fastest over it.
  std::array<int, 2 * Dim> ghosted_nodes() const;
  /// Collective: values on the ghosted box (`components` per node, ≤ max_transfer_components) summed
  /// over every rank holding the node into its owner (DMLocalToGlobal, ADD_VALUES): `owned` gets,
  /// per owned node, the sum over ranks.
  static constexpr int max_transfer_components = 1 + 2 * Dim;  // the DMDA's values per node
  void sum_to_owned(const std::vector<double>& local, int components, std::vector<double>& owned);
  /// Collective: owned node values to every rank holding the node (DMGlobalToLocal, INSERT_VALUES):
  /// `local` gets the owners' values on the whole ghosted box.
  void owned_to_local(const std::vector<double>& owned, int components, std::vector<double>& local);

  // ---- Checkpoints (checkpoint_state.cpp; the coupling's decomposed checkpoints) ----
  /// Everything of this rank that the next step reads besides the scene: every registered swarm
  /// field of every local particle in swarm order (PETSc's DMSwarmPIC_coor as "coor", the particle
  /// scalars as "scalars"; integer fields as int64), the step's start time, the frictional work books
  /// (this rank's part), the last step's work per owned node and contact counters, and the empty-node
  /// mass threshold, the regularisation's lagged normal tractions. Restored on the same rank of a decomposition built from the same scene and rank
  /// count, the run steps on bit-for-bit (same particles in the same swarm order).
  struct CheckpointState {
    std::vector<std::pair<std::string, std::vector<double>>> reals;          // name, n × components
    std::vector<std::pair<std::string, std::vector<std::int64_t>>> integers;  // id, material
    double time = 0.0, cumulative_first = 0.0, cumulative_second = 0.0, empty_node_mass = 0.0;
    double external_work = 0.0, damping_work = 0.0, rigid_work = 0.0;  // this rank's part of the books
    double contact_normal_work = 0.0, boundary_stop_work = 0.0;        // (EnergyBalance's terms)
    double stored_lead = 0.0, stress_power = 0.0, stress_dt = 0.0;      // this rank's parts of them
    double initial_energy = std::numeric_limits<double>::quiet_NaN();  // the books' start (every rank's)
    std::vector<double> work_first, work_second;
    std::vector<double> pair_first, pair_second;  // this rank's part of the pair books (materials² or empty)
    std::vector<long> stats;  // contact_nodes, multi_nodes, sliding_nodes, guarded (this rank)
    // The normal-stress regularisation's state per owned node (empty when off or before the first
    // contact: NaN where a node had no contact yet) and the steps taken, its clock.
    std::vector<double> lagged_normal_traction, lagged_normal_step;
    double steps_taken = 0.0;
  };
  CheckpointState checkpoint_state() const;
  /// This rank alone: replaces its particles and books by `state` (no migration: the particles stay
  /// in the given order on this rank). Throws std::invalid_argument for arrays of the wrong size
  /// or a missing field. With `migrate` (collective; a checkpoint of another rank count, each rank
  /// given some of its particles): every particle then goes to its owner, as after add_particles.
  void restore_checkpoint_state(const CheckpointState& state, bool migrate = false);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Explicitly instantiated for Dim = 2 and 3 in mechanics/src/distributed/.

/// The 2D names (the first decomposed step was 2D only; the coupling's decomposed heat uses them).
using DecomposedMpm2D = DecomposedMpm<2>;
using DecomposedMpm3D = DecomposedMpm<3>;
using DecomposedParticle = DecomposedMpm<2>::Particle;
using DecomposedOptions = DecomposedMpm<2>::Options;
using DecomposedStencils = DecomposedMpm<2>::Stencils;

}  // namespace frictherm::mechanics
