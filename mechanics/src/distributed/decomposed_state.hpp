// State of the decomposed MPM, 2D and 3D (frictherm/mechanics/distributed.hpp): the DMDA of the grid's
// nodes with its local (ghosted) and global vectors, the DMSwarm of the particles and a scoped view of
// the swarm's fields. Internal header. Box extents are kept for three axes; in 2D the third has one
// node (start 0, size 1), so the node numbering l = ((k·ny) + j)·nx + i serves both.
#pragma once

#include "frictherm/mechanics/distributed.hpp"
#include "distributed/petsc_check.hpp"
#include "contact_side.hpp"

#include <frictherm/mechanics/constitutive/stress_update.hpp>
#include <frictherm/mechanics/ebs.hpp>
#include <frictherm/mechanics/penalty_contact.hpp>

#include <petscdmda.h>
#include <petscdmswarm.h>
#include <petscsf.h>

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

namespace frictherm::mechanics {

namespace swarm_field {
// Registered fields (DMSwarmRegisterPetscDatatypeField) besides PETSc's own DMSwarmPIC_coor (x_p),
// DMSwarm_pid, DMSwarm_rank and DMSwarm_cellid. Vectors have Dim components, tensors are Dim×Dim
// column-major (Eigen's layout); stress_zz (2D plane strain) is registered in 3D too and stays 0.
inline constexpr const char* id = "frictherm_id";
inline constexpr const char* mass = "frictherm_mass";
inline constexpr const char* volume = "frictherm_volume";
inline constexpr const char* volume0 = "frictherm_volume0";
inline constexpr const char* velocity = "frictherm_velocity";
inline constexpr const char* half_size = "frictherm_half_size";
inline constexpr const char* stress = "frictherm_stress";
inline constexpr const char* stress_zz = "frictherm_stress_zz";
inline constexpr const char* deformation = "frictherm_F";
inline constexpr const char* material = "frictherm_material";
inline constexpr const char* initial_position = "frictherm_x0";  // displacement separation (N·9)
inline constexpr const char* plastic_strain = "frictherm_plastic_strain";    // ε̄p (Mie-Grüneisen/J2)
inline constexpr const char* internal_energy = "frictherm_internal_energy";  // e (J/kg)
inline constexpr const char* plastic_work = "frictherm_plastic_work";        // J, since the start
inline constexpr const char* wave_speed = "frictherm_wave_speed";            // c_p of the state (CFL step)
inline constexpr const char* scalars = "frictherm_scalars";  // DecomposedOptions::particle_scalars, when any
}  // namespace swarm_field

/// Values of one velocity field at a node: after particle_to_grid m, p, f (and with contact Σ S m x,
/// Ω, g: N·4–6, 9); after nodal_velocities v and a in the slots of p and f. The DMDA carries, per
/// node, the first 1 + 2·Dim summed over the fields (exact for a node that one field reaches); the
/// per-field values live in Impl::field_values and travel over PetscSFs (sparse_exchange.cpp).
/// 2D: m | p p | f f | mx mx | Ω | g g (5 without contact, 10 with); 3D: 7 and 14.
template <int Dim>
struct NodeDof {
  static constexpr int mass = 0, momentum = 1, force = 1 + Dim, velocity = momentum, acceleration = force;
  static constexpr int mass_position = 1 + 2 * Dim, domain = 1 + 3 * Dim, domain_gradient = 2 + 3 * Dim;
  static constexpr int without_contact = 1 + 2 * Dim, with_contact = 2 + 4 * Dim;  // values per field
};

/// One particle's extended B-spline entries (LatticeStencils): the nodes as DMDA lattice coordinates
/// (the serial lattice counted from the first ghost node, as Stencil::first_node), so that the same
/// for_each call as Stencil's maps them through any indexer (a field's slots, the ghosted box).
template <int Dim>
struct LatticeStencil {
  const IVec<Dim>* node;
  const double* S;
  const Vec<Dim>* G;
  std::size_t begin, end;
  template <class F>
  void for_each(const NodeIndexer<Dim>& ix, F&& f) const {
    for (std::size_t e = begin; e < end; ++e) {
      int i = ix.shift;
      for (int d = 0; d < Dim; ++d) i += node[e][d] * ix.stride[d];
      f(i, S[e], G[e]);
    }
  }
};

/// N^e_I(x_p), ∇N^e_I(x_p) of every local particle this step (Kakouris 2024 eqs. 25–26), flattened as
/// the serial PrecomputedStencils (same entries, same order) but with lattice nodes instead of slots:
/// particle k owns entries begin[k] .. begin[k+1]−1 (none for a rigid wall's particle).
template <int Dim>
struct LatticeStencils {
  std::vector<std::size_t> begin{0};
  std::vector<IVec<Dim>> node;
  std::vector<double> S;
  std::vector<Vec<Dim>> G;
  LatticeStencil<Dim> operator[](std::size_t k) const { return {node.data(), S.data(), G.data(), begin[k], begin[k + 1]}; }
};

/// Every registered field of the swarm, gotten for the object's lifetime (no migration meanwhile).
struct SwarmFields {
  DM sw;
  PetscInt n = 0;
  double* x = nullptr;  // DMSwarmPIC_coor, Dim per particle
  long* id = nullptr;
  double *mass = nullptr, *volume = nullptr, *volume0 = nullptr, *velocity = nullptr, *half_size = nullptr;
  double *stress = nullptr, *stress_zz = nullptr, *F = nullptr, *x0 = nullptr;
  double *plastic_strain = nullptr, *internal_energy = nullptr, *plastic_work = nullptr, *wave_speed = nullptr;
  PetscInt* material = nullptr;

  explicit SwarmFields(DM swarm);
  ~SwarmFields();
  /// f(name, pointer) for every field the step reads, in one list for getting and restoring.
  template <class Visit>
  void each_field(Visit&& f) {
    f(DMSwarmPICField_coor, x);
    f(swarm_field::id, id);
    f(swarm_field::mass, mass);
    f(swarm_field::volume, volume);
    f(swarm_field::volume0, volume0);
    f(swarm_field::velocity, velocity);
    f(swarm_field::half_size, half_size);
    f(swarm_field::stress, stress);
    f(swarm_field::stress_zz, stress_zz);
    f(swarm_field::deformation, F);
    f(swarm_field::material, material);
    f(swarm_field::initial_position, x0);
    f(swarm_field::plastic_strain, plastic_strain);
    f(swarm_field::internal_energy, internal_energy);
    f(swarm_field::plastic_work, plastic_work);
    f(swarm_field::wave_speed, wave_speed);
  }
  SwarmFields(const SwarmFields&) = delete;
  SwarmFields& operator=(const SwarmFields&) = delete;
};

template <int Dim>
struct DecomposedMpm<Dim>::Impl {
  using Dof = NodeDof<Dim>;
  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0, size = 1;
  Grid<Dim> grid;
  std::vector<Material> materials;
  // Per material, hoisted out of the stress update's particle loop (constitutive/stress_update.hpp).
  std::vector<StressLaw> laws;
  bool has_mie_gruneisen = false;
  // Rigid materials (velocity boundary conditions on the nodes they touch, as the serial
  // rigid_conditions / apply_velocity_bc / nodal_velocities): per axis d and local node, the largest
  // rigid material prescribing component d whose particles' stencils reach the node with S > 0 (−1:
  // none; the serial loop lets the last material win), completed at the owners in sum_to_owners;
  // per owned node the driven components (bit d) and their prescribed velocity at the step's start.
  bool has_rigid = false;
  double time = 0.0;  // at the start of the step (the serial time_)
  std::array<std::vector<PetscInt>, 3> driver, root_driver;
  std::vector<std::uint8_t> drive_mask;
  std::vector<Vec<Dim>> drive_velocity;
  bool rigid(PetscInt material) const { return materials[static_cast<std::size_t>(material)].is_rigid(); }
  // A rigid material that drives the nodes it touches (every rigid one without contact, a boundary
  // one with it), and a rigid contact partner (contact, not a boundary: a velocity field of its own
  // that meets the others through the contact laws, as the serial rigid fields).
  bool rigid_wall(PetscInt material) const {
    const Material& m = materials[static_cast<std::size_t>(material)];
    return m.is_rigid() && (!opt.contact || m.rigid_boundary);
  }
  bool rigid_partner(PetscInt material) const { return rigid(material) && !rigid_wall(material); }
  std::vector<std::uint8_t> partner_field;  // per field: 1 for a rigid contact partner's field
  long beyond = -1;  // stress_update: the id of a particle compressed past its Hugoniot's limit, or −1
  /// The dilatational wave speed of a particle's state (as Simulation::stable_time_step before the
  /// first stress update).
  double initial_wave_speed(int material, double J, double energy) const;
  Options opt;
  int width = 1;                 // DMDA stencil width (stencil_reach)
  int fields = 1;                // velocity fields per node: 1, or one per material with contact
  int per_field = Dof::without_contact;  // values per field (Dof::with_contact with contact)
  static constexpr int dof = Dof::without_contact;  // DMDA values per node: m, p, f over all fields
  int field_of(PetscInt material) const { return opt.contact ? static_cast<int>(material) : 0; }
  // Per-field storage (field_storage.cpp), as the serial layout_fields: field f covers the box of
  // local nodes its local particles' stencils reach, stored contiguously from boxes[f].first; slot
  // s holds per_field values at field_values[s·per_field] and lies at local node slot_node[s]. So
  // memory and per-step work scale with the particles, not with fields × ghosted box.
  struct FieldBox {
    IVec<Dim> lo{}, extent{};   // first node (DMDA indices) and nodes per direction
    std::size_t first = 0, count = 0;
    NodeIndexer<Dim> index;     // DMDA node -> slot
  };
  std::vector<FieldBox> boxes;
  std::vector<IVec<Dim>> box_lo, box_hi;  // scratch of particle_to_grid: per field, nodes reached
  std::vector<double> field_values;
  std::vector<PetscInt> slot_node;
  long peak_slots = 0;
  double* slot_values(std::size_t slot) { return field_values.data() + slot * static_cast<std::size_t>(per_field); }
  void layout_fields();  // boxes, slot_node, field_values (zeroed) from box_lo / box_hi
  // field_lo / field_hi: the smallest and largest field whose particles' stencils reach local node l
  // (fields / −1 when none), at owned nodes over all ranks after exchange_field_ranges; multi: 1 where
  // they differ (two or more fields reach the node on some rank), at every local node.
  std::vector<PetscInt> field_lo, field_hi, multi, root_lo, root_hi;
  std::vector<std::uint8_t> owned_flag;          // per local node: 1 if this rank owns it
  std::vector<PetscInt> ghost_of_local;          // per local node: its index in ghost_local, or −1
  std::vector<PetscInt> owned_local;             // owned node q (x fastest) -> local node l
  PetscSF node_sf = nullptr;                     // leaves: this rank's ghost nodes; roots: owners' local nodes
  std::vector<PetscInt> ghost_local;             // leaves of node_sf (local node ids)
  std::vector<PetscSFNode> ghost_remote;         // their owners (rank, owner's local node id)
  // The complete per-field values at the owned multi-material nodes (fields_to_owners): group g is
  // owned node mt_q[g] (local node mt_l[g]) with entries [mt_first[g], mt_first[g + 1]) in field
  // order, entry e of field mt_field[e] with per_field values at mt_values[e·per_field].
  std::vector<PetscInt> mt_q, mt_l;
  std::vector<std::size_t> mt_first;
  std::vector<int> mt_field;
  std::vector<double> mt_values;
  std::vector<std::array<std::size_t, 2>> mt_own;  // (own slot, entry): written back after the step's grid phases
  std::vector<std::size_t> mt_recv_entry;          // per received entry: its group entry
  // The groups' sum in fields_to_mt's order (node, material, rank): entry, own slot or received
  // entry. Later sums over the same entries (USF's forces, the velocity filters' round trips) add in
  // this order too.
  struct MtItem {
    std::size_t entry, where;
    bool own;
  };
  std::vector<MtItem> mt_order;
  double* mt_at(std::size_t e) { return mt_values.data() + e * static_cast<std::size_t>(per_field); }
  // The entry exchange: leaves are this rank's (ghost node, field) entries at multi-material nodes
  // (send_slot: their slots), roots the owners' received entries; a unit is per_field values, the
  // field and the sending rank.
  PetscSF entry_sf = nullptr;
  MPI_Datatype field_unit = MPI_DATATYPE_NULL;   // per_field + 2 doubles
  int unit_size() const { return per_field + 2; }
  std::vector<std::size_t> send_slot;
  std::vector<int> send_field;
  std::vector<PetscInt> send_jth;  // the entry's place among this rank's entries at its node
  bool all_zero(const double* v) const {
    for (int c = 0; c < per_field; ++c)
      if (v[c] != 0.0) return false;
    return true;
  }
  std::vector<double> send_buf, recv_buf;
  std::vector<PetscInt> leaf_count, leaf_offset, root_count, entry_base;  // per local node
  std::vector<PetscSFNode> entry_remote;
  /// visit(q, values, field) for every field at owned node q: the total of the DMDA (`total`: the
  /// global vector's array) at a single-material node (the one field reaching it, or `fields` if
  /// none), each field's complete values at a multi-material one.
  template <class Visit>
  void for_each_owned_field(PetscScalar* total, Visit&& visit) {
    const PetscInt owned = owned_count();
    for (PetscInt q = 0; q < owned; ++q) {
      const std::size_t l = static_cast<std::size_t>(owned_local[static_cast<std::size_t>(q)]);
      if (!multi[l]) visit(q, total + dof * q, fields > 1 ? static_cast<int>(field_lo[l]) : 0);
    }
    for (std::size_t g = 0; g < mt_q.size(); ++g)
      for (std::size_t e = mt_first[g]; e < mt_first[g + 1]; ++e) visit(mt_q[g], mt_at(e), mt_field[e]);
  }
  /// Whether `field` is a rigid contact partner's, and its prescribed velocity at the step's start.
  bool partner(int field) const {
    return field >= 0 && static_cast<std::size_t>(field) < partner_field.size() && partner_field[static_cast<std::size_t>(field)];
  }
  Vec<Dim> partner_velocity(int field) const {
    return materials[static_cast<std::size_t>(field)].rigid_velocity_at(time).template head<Dim>();
  }
  /// The values a particle reads at its field's slot after the exchanges: its field's at a
  /// multi-material node, else the DMDA's ghosted total `local_total`.
  const double* node_values(const PetscScalar* local_total, std::size_t slot) {
    const PetscInt l = slot_node[slot];
    return multi[static_cast<std::size_t>(l)] ? slot_values(slot) : local_total + dof * l;
  }
  DM da = nullptr, swarm = nullptr;
  ::Vec local = nullptr, global = nullptr;  // PETSc vectors (mechanics::Vec is the Eigen one)
  // Owned nodes [start, start + size) and the ghosted box, per axis (x, y, z; in 2D z is 0, 1).
  std::array<PetscInt, 3> owned_start{{0, 0, 0}}, owned_size{{1, 1, 1}};
  std::array<PetscInt, 3> box_start{{0, 0, 0}}, box_size{{1, 1, 1}};
  std::array<PetscInt, 3> procs{{1, 1, 1}};
  std::array<std::vector<PetscInt>, 3> starts;  // first owned node per process column / row / layer, + end
  PetscInt owned_count() const { return owned_size[0] * owned_size[1] * owned_size[2]; }
  PetscInt local_count() const { return box_size[0] * box_size[1] * box_size[2]; }
  /// Local node of DMDA node (i, j, k) (k = 0 in 2D), inside the ghosted box.
  PetscInt local_node(PetscInt i, PetscInt j, PetscInt k) const {
    return ((k - box_start[2]) * box_size[1] + (j - box_start[1])) * box_size[0] + (i - box_start[0]);
  }
  double empty_node_mass = 0.0;                 // 1e-12 of the largest particle mass (as the serial step)
  DecomposedTraffic traffic;
  std::vector<std::uint8_t> fixed_mask;  // per owned node (x fastest): bit d set, component d fixed to 0
  // Contact (contact_phases.cpp): settings per ordered material pair, the owned nodes where two or
  // more fields have mass (indices into the owned block), frictional work per owned node (last step)
  // and since the start on this rank, counters of the last step on this rank.
  // As the serial pair_settings_ / pair_index_: [0] the default pair, then each explicit pair and its
  // reverse; pair_index (materials², [a·n + b], 4 B each) only when pairs were given.
  std::vector<ContactPairSettings> pair_settings;
  std::vector<int> pair_index;
  std::vector<std::array<std::size_t, 2>> contact_nodes;  // (owned node q, group of mt_*)
  // Extent separation (contact_extents.cpp): per mt entry the normal to its partners and the maxima
  // of its own particles' and its partners' extents along it and along the signed axes
  // (kExtentDirections each; kNoExtent: none measured); per local node its list of (field, normal,
  // own, other) items in extent_* (extent_start, −1: none).
  std::vector<Vec<Dim>> mt_normal;
  std::vector<double> mt_extent_own, mt_extent_other;
  std::vector<int> extent_field;
  std::vector<Vec<Dim>> extent_normal;
  std::vector<double> extent_own, extent_other;
  std::vector<std::size_t> extent_entry;  // at the owner: the item's mt entry
  std::vector<PetscInt> extent_start, extent_count, extent_nodes;
  std::vector<std::size_t> entry_group;             // per mt entry: its group
  std::vector<double> extent_root, extent_leaf;     // exchange buffers over entry_sf
  int extent_unit_items = 0;                        // items per unit of the datatypes below
  MPI_Datatype extent_list_unit = MPI_DATATYPE_NULL, extent_max_unit = MPI_DATATYPE_NULL;
  std::vector<double> work_first, work_second;
  // Normal-stress regularisation (ContactOptions::regularized): per owned node the lagged normal
  // traction σ̃ and the step it was last updated (the serial ContactNodeState's; contact_pair.hpp),
  // and the steps taken so far (the serial clock's step count).
  std::vector<double> lagged_normal_traction, lagged_normal_step;
  double steps_taken = 0.0;
  double cumulative_first = 0.0, cumulative_second = 0.0;
  // This rank's part of the cumulative frictional work per material pair (pair_book_index, materials²;
  // empty until the first contact work), as the serial Simulation's pair books.
  std::vector<double> pair_first, pair_second;
  void add_pair_work(int a, int b, double w1, double w2) {
    const std::size_t n = materials.size();
    if (pair_first.size() != n * n) pair_first.assign(n * n, 0.0), pair_second.assign(n * n, 0.0);
    pair_first[pair_book_index(a, b, n)] += w1;
    pair_second[pair_book_index(a, b, n)] += w2;
  }
  DecomposedContactStats stats;
  // The first friction law that threw in this step's contact phases on this rank ("" if none): the
  // step goes on at every rank (that node's contact as far as it got) and the run loop agrees on the
  // failure after it (issue 34: one rank's exception had left the others waiting in a collective).
  std::string contact_failure;
  // Loads (Options::loads sorted by particle id, and their ids), this step's loaded local particles
  // (swarm index, load) found by particle_to_grid for grid_to_particle, and this rank's books (J).
  std::vector<ParticleLoad<Dim>> loads;
  std::vector<std::int64_t> load_ids;
  std::vector<std::pair<PetscInt, std::size_t>> local_loads;
  std::vector<Vec<Dim>> load_start_position;  // their positions before grid_to_particle (the loads' work)
  double external_work = 0.0, damping_work = 0.0;
  // The energy books' rigid work (this rank's part: at its owned nodes, the momentum update's rigid
  // drives and the updated contact pass's rigid partners) and the start energy, kinetic + stored
  // before the first step (the same on every rank; NaN until then), energy_books.cpp.
  double rigid_work = 0.0;
  // This rank's energy removed by the normal contact impulses (the updated pass, owned nodes) and by
  // the velocity conditions' stops (the momentum update, owned nodes): energy_books.hpp, contact_pair.hpp.
  double contact_normal_work = 0.0, boundary_stop_work = 0.0;
  // This rank's share of the books' stored_lead and of the last stress update's power (energy_books.hpp).
  double stored_lead = 0.0, last_stress_power = 0.0, last_stress_dt = 0.0;
  // Per group entry (mt_field), the extrapolated contact pass's momentum change this step: the
  // velocity conditions' stops are measured from the momentum the particles brought (the serial
  // ContactNodeState::extrapolated_change). Recorded while recording_start_change.
  std::vector<Vec<Dim>> mt_start_change;
  bool recording_start_change = false;
  double initial_energy = std::numeric_limits<double>::quiet_NaN();
  std::array<double, 3> particle_books() const;  // this rank's kinetic, stored energy and plastic work
  void take_initial_energy();           // collective, at the start of the first step
  int scalars = 0;                       // particle scalars per particle (opt.particle_scalars)
  Stencils current;                      // current_stencils(), valid until the next step or add
  bool current_valid = false;
  void stencils_at(const double* x, Stencils& out) const;  // transfer.cpp (x null: the current positions)
  std::vector<int> owned_local_int;      // owned_local as int (owned_local_nodes())
  std::vector<Stencil<Dim, LinearKernel>> stencils_linear;
  std::vector<Stencil<Dim, UGIMPKernel>> stencils_ugimp;
  std::vector<Stencil<Dim, QuadraticBSplineKernel>> stencils_quadratic;
  // Extended B-splines (extended_bsplines.cpp): one serial EbsBasis per velocity field, rebuilt every
  // step on every rank from the field's particles gathered from all ranks in the serial order; the
  // kept nodes (fixed faces, rigid drives) over the whole grid; the gather's buffers.
  LatticeStencils<Dim> stencils_extended;
  std::vector<EbsBasis<Dim>> ebs;
  std::vector<std::uint8_t> ebs_kept;
  bool ebs_keeps = false;  // fixed faces or rigid walls: kept nodes to reduce
  std::vector<double> ebs_send, ebs_all;
  std::vector<Vec<Dim>> ebs_position;
  std::vector<double> ebs_volume;
  std::vector<std::size_t> ebs_order;
  void prepare_extended(SwarmFields& f);

  // Penalty contact (penalty_phases.cpp): the serial PenaltyContact and boundary points, the same on
  // every rank; the complete per-field nodal mass and velocity over the whole grid (slot f·N + node,
  // the serial FieldNodes::whole_grid layout) gathered from the owners; the forces and heat the
  // serial kernels scatter into them.
  std::optional<PenaltyContact<Dim>> penalty;
  BoundaryPoints<Dim> boundary;
  std::vector<FieldNodes<Dim>> penalty_boxes;
  std::vector<double> penalty_mass, penalty_heat_first, penalty_heat_second;
  std::vector<Vec<Dim>> penalty_force, penalty_velocity;
  std::vector<double> penalty_gather;
  std::vector<std::size_t> owned_grid_node;  // per owned node q: its grid node (serial numbering)
  std::vector<double> p2g_values;            // MUSL with several fields: the slots after particle_to_grid
  void setup_penalty();
  void penalty_forces(double dt);
  bool penalty_mass_current = false;  // penalty_mass gathered in this step (step() clears it)
  void gather_penalty_mass();
  void move_boundary_points(double dt);
  double penalty_time_step(double& cmax) const;  // the springs' limit; cmax times the penalty's wave factor
  void keep_grid_values(double dt);              // MUSL with several fields: p2g_values = field_values
  // USF (scheme_phases.cpp): the post-condition momenta of the owned fields in for_each_owned_field's
  // order, kept by velocity_from_momentum for forces_to_owners.
  std::vector<double> kept_momentum;
  // XPIC/FMPM (velocity_filter.cpp): a DMDA of Dim values per node (DMDACreateCompatibleDMDA, made at
  // the first filtered step) with its vectors; per owned node (q) and per group entry (e) XPIC's start
  // velocity, the series' term and its sum v*; per slot the term or v* a particle reads at a
  // multi-material node and the round trip's sums; the Dim-vector unit and buffers over entry_sf.
  DM filter_da = nullptr;
  ::Vec filter_local = nullptr, filter_global = nullptr;
  std::vector<Vec<Dim>> start_owned, start_mt, term_owned, term_mt, filtered_owned, filtered_mt, sums_owned, sums_mt;
  std::vector<Vec<Dim>> slot_vector, slot_sums;
  std::vector<double> vector_send, vector_recv;
  MPI_Datatype vector_unit = MPI_DATATYPE_NULL;
  bool filtered() const { return opt.particle_update != ParticleUpdate::flip; }
  void start_velocity(double dt);
  template <class Kernel>
  void velocity_filter(double dt);
  void vectors_to_ghosts(const std::vector<Vec<Dim>>& owned, const std::vector<Vec<Dim>>& entries);
  void vectors_to_owners(std::vector<Vec<Dim>>& owned, std::vector<Vec<Dim>>& entries);
  /// The value a particle reads at its field's slot: slot_vector at a multi-material node, else the
  /// Dim-vector DMDA's ghosted value `local_vectors` (filter_local's array).
  Vec<Dim> slot_vector_at(const PetscScalar* local_vectors, std::size_t slot) const {
    const PetscInt l = slot_node[slot];
    return multi[static_cast<std::size_t>(l)] ? slot_vector[slot] : Vec<Dim>(Eigen::Map<const Vec<Dim>>(local_vectors + Dim * l));
  }
  template <class Kernel>
  void internal_forces(double dt);
  void forces_to_owners(double dt);
  template <class Kernel>
  void add_loads(SwarmFields& f);  // the loads of this rank's particles into their slots' forces
  template <class Visit>
  void gather_owned_fields(int components, std::vector<double>& dense, Visit&& value);

  ~Impl();

  /// The kernel's stencils of the step: a Stencil per particle, or the extended entries (LatticeStencils).
  template <class Kernel>
  auto& stencils() {
    if constexpr (std::is_same_v<Kernel, ExtendedBSplineKernel>) return stencils_extended;
    else if constexpr (std::is_same_v<Kernel, LinearKernel>) return stencils_linear;
    else if constexpr (std::is_same_v<Kernel, UGIMPKernel>) return stencils_ugimp;
    else return stencils_quadratic;
  }
  /// Local-vector node index of a stencil's nodes (ghosted box, x fastest, then y, then z).
  NodeIndexer<Dim> local_indexer() const {
    NodeIndexer<Dim> ix;
    int stride = 1, shift = 0;
    for (int d = 0; d < Dim; ++d) {
      ix.stride[d] = stride;
      shift -= static_cast<int>(box_start[static_cast<std::size_t>(d)]) * stride;
      stride *= static_cast<int>(box_size[static_cast<std::size_t>(d)]);
    }
    ix.shift = shift;
    return ix;
  }
  /// Whether a stencil's nodes lie in the ghosted box.
  template <class Kernel>
  bool in_box(const Stencil<Dim, Kernel>& st) const {
    const IVec<Dim> b = st.first_node();
    for (int d = 0; d < Dim; ++d) {
      const auto u = static_cast<std::size_t>(d);
      if (b[d] < box_start[u] || b[d] + Kernel::K > box_start[u] + box_size[u]) return false;
    }
    return true;
  }
  /// The rank owning the node nearest to x.
  int owner_of(const double* x) const;

  std::vector<double> scalar_values() const;  // transfer.cpp: every particle scalar, particle-major
  void setup_contact();  // contact_phases.cpp: checks, pair_settings and pair_index
  void setup_fixed_faces();
  void setup_sparse_exchange();  // sparse_exchange.cpp: node_sf, owned_local, field_unit
  void fields_to_mt();           // sparse_exchange.cpp: the owner's groups from its slots and the received entries

  // The phases (usl_phases.cpp, contact_phases.cpp) and the migration (decomposition.cpp).
  template <class Kernel>
  void particle_to_grid(double dt);
  void sum_to_owners(double dt);
  void exchange_field_ranges(double dt);
  void fields_to_owners(double dt);
  void find_contact_nodes(double dt);
  void contact_extrapolated(double dt);
  void velocity_conditions(double dt);
  void damping(double dt);
  void momentum_update(double dt);
  void contact_updated(double dt);
  void contact_remapped(double dt);  // MUSL: contact on the remapped momenta
  void nodal_velocities(double dt);
  void ghost_velocities(double dt);
  void fields_to_ghosts(double dt);
  void resolve_contact(bool updated, double dt);
  /// The sides of contact group g as the serial gather_contact_sides (materials above min_mass_fraction
  /// of the node's mass, in material order, slivers marked; a rigid partner's prescribed motion), their
  /// materials and mt entries; returns how many were left out.
  long gather_sides(std::size_t g, double dt, std::vector<ContactSide<Dim>>& sides, std::vector<int>& mats,
                    std::vector<std::size_t>& entries) const;
  const ContactPairSettings& pair_of(int a, int b) const {
    if (pair_index.empty()) return pair_settings[0];
    const std::size_t n = materials.size();
    return pair_settings[static_cast<std::size_t>(pair_index[static_cast<std::size_t>(a) * n + static_cast<std::size_t>(b)])];
  }
  template <class Kernel>
  void measure_contact_extents(double dt);  // contact_extents.cpp
  void free_extent_units();
  template <class Kernel>
  void grid_to_particle(double dt);
  template <class Kernel>
  void stress_update(double dt);
  template <class Kernel>
  void remap_momentum(double dt);     // MUSL
  void velocity_from_momentum(double dt);
  void migrate(double dt);
};

}  // namespace frictherm::mechanics
