// Decomposed MPM, 2D and 3D (frictherm/mechanics/distributed.hpp): the DMDA of the grid's nodes
// (DMDACreate2d / DMDACreate3d), the DMSwarm of the particles, ownership by nearest node, migration,
// fixed faces, reductions and the gather by global id.
#include "distributed/decomposed_state.hpp"

#include <frictherm/mechanics/loads/grid_loads.hpp>
#include <frictherm/mechanics/mie_gruneisen.hpp>
#include <frictherm/mechanics/time_step/cfl_time_step.hpp>

// PETSc 3.18 has no public setter of the swarm's migration type (DMSwarmSetMigrateType came in
// 3.19); the private header gives the field. Needed because the PIC default (DMSWARM_MIGRATE_
// DMCELLNSCATTER, DMLocatePoints on the DMDA) counts the cell straddling two ranks on both and can
// duplicate points at corners; basic migration sends each particle to the rank we name.
#if !PETSC_VERSION_GE(3, 19, 0)
#include <petsc/private/dmswarmimpl.h>
#endif

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace frictherm::mechanics {

using detail::petsc_check;

DecomposedPetscSession::DecomposedPetscSession(int* argc, char*** argv) {
  PetscBool done = PETSC_FALSE;
  petsc_check(PetscInitialized(&done), "PetscInitialized");
  if (!done) {
    petsc_check(PetscInitialize(argc, argv, nullptr, nullptr), "PetscInitialize");
    owns_ = true;
  }
}
DecomposedPetscSession::~DecomposedPetscSession() {
  if (owns_) PetscFinalize();
}

// Reach of a kernel's stencil beyond the particle's nearest node n = round(s): the node choice
// (Weights1D::base) is piecewise constant with break points at s = j and j + 1/2, so samples on
// both sides of each within one cell give the largest reach.
// The extended B-spline of a particle in boundary cell c (its nearest node) adds to the block
// c − 1 .. c + 1 the stencils of its degenerate nodes J: Q_J − 1 .. Q_J + 1 with Q_J within
// search_radius of J (docs/ebs.md, eqs. 22–26), so it reaches search_radius + 2 nodes.
int stencil_reach(ShapeKind kind) {
  if (kind == ShapeKind::extended_bspline) return EbsOptions{}.search_radius + 2;
  return dispatch_shape(kind, [](auto kernel) {
    using Kernel = decltype(kernel);
    constexpr double eps = 1e-9;
    int reach = 0;
    for (double s : {0.0, eps, 0.25, 0.5 - eps, 0.5, 0.5 + eps, 0.75, 1.0 - eps}) {
      Weights1D<Kernel::K> w;
      Kernel::eval(s, 0.0, 1.0, 1.0, 0.5, w);  // cell [0, 1), h = 1, l_p = h/2
      const int n = static_cast<int>(std::floor(s + 0.5));
      reach = std::max({reach, n - w.base, w.base + Kernel::K - 1 - n});
    }
    return reach;
  });
}

SwarmFields::SwarmFields(DM swarm) : sw(swarm) {
  petsc_check(DMSwarmGetLocalSize(sw, &n), "DMSwarmGetLocalSize");
  each_field([&](const char* name, auto*& ptr) {
    petsc_check(DMSwarmGetField(sw, name, nullptr, nullptr, reinterpret_cast<void**>(&ptr)), "DMSwarmGetField");
  });
}

SwarmFields::~SwarmFields() {
  each_field([&](const char* name, auto*& ptr) {
    DMSwarmRestoreField(sw, name, nullptr, nullptr, reinterpret_cast<void**>(&ptr));
  });
}

template <int Dim>
DecomposedMpm<Dim>::Impl::~Impl() {
  PetscSFDestroy(&entry_sf);
  PetscSFDestroy(&node_sf);
  if (field_unit != MPI_DATATYPE_NULL) MPI_Type_free(&field_unit);
  free_extent_units();
  VecDestroy(&local);
  VecDestroy(&global);
  VecDestroy(&filter_local);
  VecDestroy(&filter_global);
  DMDestroy(&filter_da);
  if (vector_unit != MPI_DATATYPE_NULL) MPI_Type_free(&vector_unit);
  DMDestroy(&swarm);
  DMDestroy(&da);
}

template <int Dim>
int DecomposedMpm<Dim>::Impl::owner_of(const double* x) const {
  int p[3] = {0, 0, 0};
  for (int d = 0; d < Dim; ++d) {
    const auto& st = starts[static_cast<std::size_t>(d)];
    const double s = (x[d] - grid.lo()[d]) * grid.inverse_cell_size()[d];
    const PetscInt node = std::clamp<PetscInt>(static_cast<PetscInt>(std::floor(s + 0.5)) + Grid<Dim>::ghost, 0,
                                               st.back() - 1);
    p[d] = static_cast<int>(std::upper_bound(st.begin(), st.end(), node) - st.begin()) - 1;
  }
  return p[0] + static_cast<int>(procs[0]) * (p[1] + static_cast<int>(procs[1]) * p[2]);  // DMDA ranks: x fastest
}

template <int Dim>
DecomposedMpm<Dim>::DecomposedMpm(MPI_Comm comm, const Grid<Dim>& grid, const Material& material,
                                  const Options& options)
    : DecomposedMpm(comm, grid, std::vector<Material>{material}, options) {}

template <int Dim>
DecomposedMpm<Dim>::DecomposedMpm(MPI_Comm comm, const Grid<Dim>& grid, const std::vector<Material>& materials,
                                  const Options& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  if (materials.empty()) throw std::invalid_argument("decomposed mechanics: no material given");
  // The serial add_material's checks (a Mie-Grüneisen material's EOS density is its density).
  std::vector<Material> mats = materials;
  for (Material& material : mats) {
    const std::string where = "decomposed mechanics: material '" + material.name + "'";
    if (!(material.density > 0.0)) throw std::invalid_argument(where + ": density must be > 0");
    if (material.is_rigid()) {
      if (!material.rigid_boundary && !(material.rigid_controls[0] && material.rigid_controls[1] && material.rigid_controls[2]))
        throw std::invalid_argument(where + ": only a boundary rigid material may leave velocity components free");
      continue;
    }
    if (material.kind == MaterialKind::mie_gruneisen) {
      material.mie_gruneisen.density = material.density;
      validate(material.mie_gruneisen, options.analysis, "material '" + material.name + "'");
      continue;
    }
    if (!(material.youngs_modulus > 0.0)) throw std::invalid_argument(where + ": E must be > 0");
    if (!(material.poisson_ratio > -1.0 && material.poisson_ratio < 0.5))
      throw std::invalid_argument(where + ": Poisson ratio must be in (-1, 0.5)");
    if (material.kind == MaterialKind::neo_hookean && options.analysis == Analysis::plane_stress)
      throw std::invalid_argument(where + ": neo_hookean needs plane_strain or 3D (expected analysis plane_strain)");
  }
  for (const FixedFace& face : options.fixed_faces)
    if (face.axis < 0 || face.axis >= Dim)
      throw std::invalid_argument("decomposed mechanics: fixed face axis " + std::to_string(face.axis) +
                                  (Dim == 2 ? " (expected 0 or 1)" : " (expected 0, 1 or 2)"));
  if (Dim == 2 ? options.analysis == Analysis::three_d : options.analysis != Analysis::three_d)
    throw std::invalid_argument(std::string("decomposed mechanics: analysis ") +
                                (options.analysis == Analysis::three_d ? "three_d" : "plane_strain/plane_stress") +
                                (Dim == 2 ? " in 2D (expected plane_strain or plane_stress)" : " in 3D (expected three_d)"));
  if (options.shape == ShapeKind::extended_bspline && !(options.ebs_occupation >= 0.0 && options.ebs_occupation <= 1.0))
    throw std::invalid_argument("decomposed mechanics: ebs_occupation " + std::to_string(options.ebs_occupation) +
                                " (expected a number in [0, 1])");
  if (options.extra_ghost_width < 0) throw std::invalid_argument("decomposed mechanics: extra_ghost_width < 0");
  s.width = stencil_reach(options.shape) + options.extra_ghost_width;
  s.comm = comm;
  MPI_Comm_rank(comm, &s.rank);
  MPI_Comm_size(comm, &s.size);
  s.grid = grid;
  s.materials = mats;
  for (const Material& m : mats) {
    const bool mg = m.kind == MaterialKind::mie_gruneisen;
    s.has_rigid = s.has_rigid || m.is_rigid();
    s.laws.push_back(stress_law(m, options.analysis));
    s.has_mie_gruneisen = s.has_mie_gruneisen || mg;
  }
  s.opt = options;
  // The loads by particle id (stable: a particle's loads in the serial order), found by particle_to_grid.
  s.loads = options.loads;
  std::stable_sort(s.loads.begin(), s.loads.end(),
                   [](const ParticleLoad<Dim>& a, const ParticleLoad<Dim>& b) { return a.particle < b.particle; });
  for (const ParticleLoad<Dim>& L : s.loads) s.load_ids.push_back(L.particle);
  s.opt.loads.clear();
  s.setup_contact();  // checks the contact settings before any collective PETSc call
  s.setup_penalty();  // penalty_phases.cpp
  s.fields = options.contact ? static_cast<int>(materials.size()) : 1;
  s.per_field = options.contact ? NodeDof<Dim>::with_contact : NodeDof<Dim>::without_contact;
  const IVec<Dim>& nodes = grid.nodes_per_dim();
  if constexpr (Dim == 2)
    petsc_check(DMDACreate2d(comm, DM_BOUNDARY_NONE, DM_BOUNDARY_NONE, DMDA_STENCIL_BOX, nodes[0], nodes[1],
                             PETSC_DECIDE, PETSC_DECIDE, s.dof, s.width, nullptr, nullptr, &s.da),
                "DMDACreate2d");
  else
    petsc_check(DMDACreate3d(comm, DM_BOUNDARY_NONE, DM_BOUNDARY_NONE, DM_BOUNDARY_NONE, DMDA_STENCIL_BOX, nodes[0],
                             nodes[1], nodes[2], PETSC_DECIDE, PETSC_DECIDE, PETSC_DECIDE, s.dof, s.width, nullptr,
                             nullptr, nullptr, &s.da),
                "DMDACreate3d");
  petsc_check(DMSetUp(s.da), "DMSetUp(DMDA)");
  const Vec<Dim> first = grid.lo() - grid.cell_size(), last = grid.hi() + grid.cell_size();  // ghost layer
  petsc_check(DMDASetUniformCoordinates(s.da, first[0], last[0], first[1], last[1], Dim == 3 ? first[Dim - 1] : 0.0,
                                        Dim == 3 ? last[Dim - 1] : 0.0),
              "DMDASetUniformCoordinates");
  // In 2D PETSc reports the z extent as start 0, size 1 (the layout of Impl's boxes).
  petsc_check(DMDAGetCorners(s.da, &s.owned_start[0], &s.owned_start[1], &s.owned_start[2], &s.owned_size[0],
                             &s.owned_size[1], &s.owned_size[2]),
              "DMDAGetCorners");
  petsc_check(DMDAGetGhostCorners(s.da, &s.box_start[0], &s.box_start[1], &s.box_start[2], &s.box_size[0],
                                  &s.box_size[1], &s.box_size[2]),
              "DMDAGetGhostCorners");
  if (Dim == 2 && (s.owned_start[2] != 0 || s.owned_size[2] != 1 || s.box_start[2] != 0 || s.box_size[2] != 1))
    throw std::logic_error("decomposed mechanics: a 2D DMDA with a z extent other than one node");
  petsc_check(DMDAGetInfo(s.da, nullptr, nullptr, nullptr, nullptr, &s.procs[0], &s.procs[1], &s.procs[2], nullptr,
                          nullptr, nullptr, nullptr, nullptr, nullptr),
              "DMDAGetInfo");
  const PetscInt* counts[3] = {nullptr, nullptr, nullptr};
  petsc_check(DMDAGetOwnershipRanges(s.da, &counts[0], &counts[1], Dim == 3 ? &counts[2] : nullptr),
              "DMDAGetOwnershipRanges");
  for (std::size_t d = 0; d < 3; ++d) {
    auto& st = s.starts[d];
    st.assign(1, 0);
    if (static_cast<int>(d) >= Dim) {  // 2D: one layer of one node
      s.procs[d] = 1;
      st.push_back(1);
      continue;
    }
    for (PetscInt p = 0; p < s.procs[d]; ++p) st.push_back(st.back() + counts[d][p]);
  }
  petsc_check(DMCreateLocalVector(s.da, &s.local), "DMCreateLocalVector");
  petsc_check(DMCreateGlobalVector(s.da, &s.global), "DMCreateGlobalVector");

  // The swarm: PIC type over the DMDA (DMSwarmSetType(PIC) registers DMSwarmPIC_coor, Dim per point).
  petsc_check(DMCreate(comm, &s.swarm), "DMCreate(DMSwarm)");
  petsc_check(DMSetType(s.swarm, DMSWARM), "DMSetType(DMSWARM)");
  petsc_check(DMSetDimension(s.swarm, Dim), "DMSetDimension");
  petsc_check(DMSwarmSetType(s.swarm, DMSWARM_PIC), "DMSwarmSetType");
  petsc_check(DMSwarmSetCellDM(s.swarm, s.da), "DMSwarmSetCellDM");
  auto reg = [&](const char* name, PetscInt bs, PetscDataType type) {
    petsc_check(DMSwarmRegisterPetscDatatypeField(s.swarm, name, bs, type), "DMSwarmRegisterPetscDatatypeField");
  };
  static_assert(sizeof(long) == 8, "global ids are stored as PETSC_LONG");
  reg(swarm_field::id, 1, PETSC_LONG);
  reg(swarm_field::mass, 1, PETSC_DOUBLE);
  reg(swarm_field::volume, 1, PETSC_DOUBLE);
  reg(swarm_field::volume0, 1, PETSC_DOUBLE);
  reg(swarm_field::velocity, Dim, PETSC_DOUBLE);
  reg(swarm_field::half_size, Dim, PETSC_DOUBLE);
  reg(swarm_field::stress, Dim * Dim, PETSC_DOUBLE);
  reg(swarm_field::stress_zz, 1, PETSC_DOUBLE);
  reg(swarm_field::deformation, Dim * Dim, PETSC_DOUBLE);
  reg(swarm_field::material, 1, PETSC_INT);
  reg(swarm_field::initial_position, Dim, PETSC_DOUBLE);
  reg(swarm_field::plastic_strain, 1, PETSC_DOUBLE);
  reg(swarm_field::internal_energy, 1, PETSC_DOUBLE);
  reg(swarm_field::plastic_work, 1, PETSC_DOUBLE);
  reg(swarm_field::wave_speed, 1, PETSC_DOUBLE);
  s.scalars = static_cast<int>(options.particle_scalars.size());
  if (s.scalars > 0) reg(swarm_field::scalars, s.scalars, PETSC_DOUBLE);
  petsc_check(DMSwarmFinalizeFieldRegister(s.swarm), "DMSwarmFinalizeFieldRegister");
  petsc_check(DMSwarmSetLocalSizes(s.swarm, 0, 64), "DMSwarmSetLocalSizes");
  petsc_check(DMSetUp(s.swarm), "DMSetUp(DMSwarm)");
#if PETSC_VERSION_GE(3, 19, 0)
  petsc_check(DMSwarmSetMigrateType(s.swarm, DMSWARM_MIGRATE_BASIC), "DMSwarmSetMigrateType");
#else
  static_cast<DM_Swarm*>(s.swarm->data)->migrate_type = DMSWARM_MIGRATE_BASIC;
#endif

  // Traffic bookkeeping: ghost nodes of this rank and the bytes of one particle (every field).
  s.traffic.ghost_nodes = static_cast<long>(s.local_count() - s.owned_count());
  s.traffic.values_per_node = s.dof;
  s.traffic.field_entry_bytes = (s.per_field + 2) * static_cast<int>(sizeof(double));  // values, material, rank
  s.setup_fixed_faces();
  s.setup_sparse_exchange();
  if (s.has_rigid) {
    for (int d = 0; d < Dim; ++d) s.driver[static_cast<std::size_t>(d)].assign(static_cast<std::size_t>(s.local_count()), -1);
    s.drive_mask.assign(static_cast<std::size_t>(s.owned_count()), 0);
    s.drive_velocity.assign(static_cast<std::size_t>(s.owned_count()), Vec<Dim>::Zero());
  }
  int bytes = 0;
  for (const char* name : {DMSwarmPICField_coor, DMSwarmField_pid, DMSwarmField_rank, DMSwarmPICField_cellid,
                           swarm_field::id, swarm_field::mass, swarm_field::volume, swarm_field::volume0,
                           swarm_field::velocity, swarm_field::half_size, swarm_field::stress,
                           swarm_field::stress_zz, swarm_field::deformation, swarm_field::material,
                           swarm_field::initial_position, swarm_field::plastic_strain,
                           swarm_field::internal_energy, swarm_field::plastic_work, swarm_field::wave_speed}) {
    PetscInt bs = 0;
    PetscDataType type;
    void* ptr = nullptr;
    petsc_check(DMSwarmGetField(s.swarm, name, &bs, &type, &ptr), "DMSwarmGetField");
    size_t size = 0;
    petsc_check(PetscDataTypeGetSize(type, &size), "PetscDataTypeGetSize");
    petsc_check(DMSwarmRestoreField(s.swarm, name, &bs, &type, &ptr), "DMSwarmRestoreField");
    bytes += static_cast<int>(bs * static_cast<PetscInt>(size));
  }
  bytes += s.scalars * static_cast<int>(sizeof(double));
  s.traffic.particle_bytes = bytes;
  s.owned_local_int.assign(s.owned_local.begin(), s.owned_local.end());
}

template <int Dim>
DecomposedMpm<Dim>::~DecomposedMpm() = default;

template <int Dim>
void DecomposedMpm<Dim>::add_particles(const std::vector<Particle>& particles) {
  Impl& s = *impl_;
  double mmax = 0.0;
  for (const auto& p : particles) {
    if (!s.grid.contains(p.position))
      throw std::invalid_argument("decomposed mechanics: particle " + std::to_string(p.id) +
                                  " lies outside the grid's region");
    if (p.material < 0 || p.material >= static_cast<int>(s.materials.size()))
      throw std::invalid_argument("decomposed mechanics: particle " + std::to_string(p.id) + " has material " +
                                  std::to_string(p.material) + " (expected 0 … " +
                                  std::to_string(s.materials.size() - 1) + ")");
    if (!p.scalars.empty() && p.scalars.size() != static_cast<std::size_t>(s.scalars))
      throw std::invalid_argument("decomposed mechanics: particle " + std::to_string(p.id) + " has " +
                                  std::to_string(p.scalars.size()) + " scalars (expected " +
                                  std::to_string(s.scalars) + ", DecomposedOptions::particle_scalars)");
    mmax = std::max(mmax, p.mass);
  }
  MPI_Allreduce(MPI_IN_PLACE, &mmax, 1, MPI_DOUBLE, MPI_MAX, s.comm);
  s.empty_node_mass = 1e-12 * mmax;
  PetscInt before = 0;
  petsc_check(DMSwarmGetLocalSize(s.swarm, &before), "DMSwarmGetLocalSize");
  petsc_check(DMSwarmSetLocalSizes(s.swarm, before + static_cast<PetscInt>(particles.size()), 64),
              "DMSwarmSetLocalSizes");
  {
    SwarmFields f(s.swarm);
    for (std::size_t q = 0; q < particles.size(); ++q) {
      const Particle& p = particles[q];
      const std::size_t k = static_cast<std::size_t>(before) + q;
      f.id[k] = static_cast<long>(p.id);
      f.mass[k] = p.mass;
      f.volume[k] = f.volume0[k] = p.volume;
      for (int d = 0; d < Dim; ++d) {
        f.x[Dim * k + d] = f.x0[Dim * k + d] = p.position[d];
        f.velocity[Dim * k + d] = p.velocity[d];
        f.half_size[Dim * k + d] = p.half_size[d];
      }
      Eigen::Map<Mat<Dim>>(f.stress + Dim * Dim * k) = p.stress;
      f.stress_zz[k] = p.stress_zz;
      f.material[k] = static_cast<PetscInt>(p.material);
      Eigen::Map<Mat<Dim>>(f.F + Dim * Dim * k) = Mat<Dim>::Identity();
      f.plastic_strain[k] = p.plastic_strain;
      f.internal_energy[k] = p.internal_energy;
      f.plastic_work[k] = p.plastic_work;
      f.wave_speed[k] = s.initial_wave_speed(p.material, 1.0, p.internal_energy);  // V = V0 here
    }
  }
  if (s.scalars > 0) {
    double* v = nullptr;
    petsc_check(DMSwarmGetField(s.swarm, swarm_field::scalars, nullptr, nullptr, reinterpret_cast<void**>(&v)),
                "DMSwarmGetField");
    for (std::size_t q = 0; q < particles.size(); ++q)
      for (int c = 0; c < s.scalars; ++c)
        v[(static_cast<std::size_t>(before) + q) * static_cast<std::size_t>(s.scalars) + static_cast<std::size_t>(c)] =
            particles[q].scalars.empty() ? 0.0 : particles[q].scalars[static_cast<std::size_t>(c)];
    DMSwarmRestoreField(s.swarm, swarm_field::scalars, nullptr, nullptr, reinterpret_cast<void**>(&v));
  }
  s.current_valid = false;
  const long sent = s.traffic.particles_sent, received = s.traffic.particles_received;
  s.migrate(0.0);
  s.traffic.particles_sent = sent, s.traffic.particles_received = received;  // the set-up is not a step
}

// Exchange 3: every particle to the rank owning its nearest node (DMSwarm_rank, basic migration).
template <int Dim>
void DecomposedMpm<Dim>::Impl::migrate(double /*dt*/) {
  PetscInt n = 0;
  petsc_check(DMSwarmGetLocalSize(swarm, &n), "DMSwarmGetLocalSize");
  long sent = 0;
  {
    double* x = nullptr;
    PetscInt* dest = nullptr;
    PetscDataType type;
    petsc_check(DMSwarmGetField(swarm, DMSwarmPICField_coor, nullptr, nullptr, reinterpret_cast<void**>(&x)),
                "DMSwarmGetField");
    petsc_check(DMSwarmGetField(swarm, DMSwarmField_rank, nullptr, &type, reinterpret_cast<void**>(&dest)),
                "DMSwarmGetField");
    if (type != PETSC_INT) throw std::logic_error("decomposed mechanics: DMSwarm_rank is not a PetscInt field");
    for (PetscInt k = 0; k < n; ++k) {
      dest[k] = owner_of(x + Dim * k);
      if (dest[k] != rank) ++sent;
    }
    DMSwarmRestoreField(swarm, DMSwarmField_rank, nullptr, nullptr, reinterpret_cast<void**>(&dest));
    DMSwarmRestoreField(swarm, DMSwarmPICField_coor, nullptr, nullptr, reinterpret_cast<void**>(&x));
  }
  // DMSwarmMigrate walks every particle and talks to every rank; most steps no particle changes
  // owner (one sum over the ranks says so) and it is skipped.
  long leaving = 0;
  MPI_Allreduce(&sent, &leaving, 1, MPI_LONG, MPI_SUM, comm);
  if (leaving == 0) return;
  petsc_check(DMSwarmMigrate(swarm, PETSC_TRUE), "DMSwarmMigrate");
  PetscInt after = 0;
  petsc_check(DMSwarmGetLocalSize(swarm, &after), "DMSwarmGetLocalSize");
  traffic.particles_sent += sent;
  traffic.particles_received += static_cast<long>(after) - (static_cast<long>(n) - sent);
}

template <int Dim>
int DecomposedMpm<Dim>::stencil_width() const {
  return impl_->width;
}
template <int Dim>
std::array<int, Dim> DecomposedMpm<Dim>::processes() const {
  std::array<int, Dim> p{};
  for (std::size_t d = 0; d < static_cast<std::size_t>(Dim); ++d) p[d] = static_cast<int>(impl_->procs[d]);
  return p;
}
template <int Dim>
std::array<int, 2 * Dim> DecomposedMpm<Dim>::owned_nodes() const {
  const Impl& s = *impl_;
  std::array<int, 2 * Dim> r{};
  for (std::size_t d = 0; d < static_cast<std::size_t>(Dim); ++d) {
    r[2 * d] = static_cast<int>(s.owned_start[d]);
    r[2 * d + 1] = static_cast<int>(s.owned_start[d] + s.owned_size[d]);
  }
  return r;
}
template <int Dim>
std::size_t DecomposedMpm<Dim>::local_particles() const {
  PetscInt n = 0;
  petsc_check(DMSwarmGetLocalSize(impl_->swarm, &n), "DMSwarmGetLocalSize");
  return static_cast<std::size_t>(n);
}
template <int Dim>
const DecomposedTraffic& DecomposedMpm<Dim>::traffic() const {
  return impl_->traffic;
}
template <int Dim>
int DecomposedMpm<Dim>::velocity_fields() const {
  return impl_->fields;
}

// Fixed faces as Simulation::fix_face: nodes at lattice index ≤ 0 (lower) or ≥ cells (upper) along
// the axis, i.e. DMDA index ≤ 1 or ≥ cells + 1 (DMDA index = lattice + Grid<Dim>::ghost).
template <int Dim>
void DecomposedMpm<Dim>::Impl::setup_fixed_faces() {
  fixed_mask.assign(static_cast<std::size_t>(owned_count()), 0);
  const auto& o = owned_start;
  const auto& n = owned_size;
  for (const FixedFace& face : opt.fixed_faces) {  // axes checked by the constructor
    const PetscInt last = grid.cells()[face.axis] + Grid<Dim>::ghost;
    std::size_t q = 0;  // owned node, x fastest
    for (PetscInt k = o[2]; k < o[2] + n[2]; ++k)
      for (PetscInt j = o[1]; j < o[1] + n[1]; ++j)
        for (PetscInt i = o[0]; i < o[0] + n[0]; ++i, ++q) {
          const PetscInt ijk[3] = {i, j, k};
          const PetscInt l = ijk[face.axis];
          if (face.upper ? l < last : l > Grid<Dim>::ghost) continue;
          for (int d = 0; d < Dim; ++d)
            if (face.components[static_cast<std::size_t>(d)]) fixed_mask[q] |= static_cast<std::uint8_t>(1u << d);
        }
  }
}

template <int Dim>
long long DecomposedMpm<Dim>::global_particles() const {
  long long n = static_cast<long long>(local_particles());
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_LONG_LONG, MPI_SUM, impl_->comm);
  return n;
}

template <int Dim>
double DecomposedMpm<Dim>::total_mass() const {
  SwarmFields f(impl_->swarm);
  double m = 0.0;
  for (PetscInt k = 0; k < f.n; ++k) m += f.mass[k];
  MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_SUM, impl_->comm);
  return m;
}

template <int Dim>
Vec<Dim> DecomposedMpm<Dim>::total_momentum() const {
  SwarmFields f(impl_->swarm);
  Vec<Dim> p = Vec<Dim>::Zero();
  for (PetscInt k = 0; k < f.n; ++k) p += f.mass[k] * Eigen::Map<const Vec<Dim>>(f.velocity + Dim * k);
  MPI_Allreduce(MPI_IN_PLACE, p.data(), Dim, MPI_DOUBLE, MPI_SUM, impl_->comm);
  return p;
}

template <int Dim>
double DecomposedMpm<Dim>::total_momentum_scale() const {
  SwarmFields f(impl_->swarm);
  double s = 0.0;
  for (PetscInt k = 0; k < f.n; ++k) {
    const double* v = f.velocity + Dim * k;
    s += f.mass[k] * (Dim == 2 ? std::hypot(v[0], v[1]) : std::hypot(v[0], v[1], v[Dim - 1]));
  }
  MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, impl_->comm);
  return s;
}

template <int Dim>
double DecomposedMpm<Dim>::local_speed_max(const std::vector<std::uint8_t>& counted) const {
  SwarmFields f(impl_->swarm);
  double v2 = 0.0;
  for (PetscInt k = 0; k < f.n; ++k) {
    const auto m = static_cast<std::size_t>(f.material[k]);
    if (m >= counted.size() || !counted[m]) continue;
    double s = 0.0;
    for (int d = 0; d < Dim; ++d) s += f.velocity[Dim * k + d] * f.velocity[Dim * k + d];
    v2 = std::max(v2, s);
  }
  return std::sqrt(v2);
}

template <int Dim>
std::vector<typename DecomposedMpm<Dim>::Particle> DecomposedMpm<Dim>::gather() const {
  constexpr int D = Dim, DD = Dim * Dim;
  // Doubles per particle: mass, volume, x, v, l_p, σ, σ_zz, material, ε̄p, e, plastic work, the scalars.
  constexpr int at_x = 2, at_v = at_x + D, at_l = at_v + D, at_s = at_l + D, at_zz = at_s + DD, at_mat = at_zz + 1;
  constexpr int at_state = at_mat + 1, at_scalars = at_state + 3;  // 17 in 2D, 25 in 3D
  const int ns = impl_->scalars;
  const int per = at_scalars + ns;
  const std::vector<double> sc = ns > 0 ? impl_->scalar_values() : std::vector<double>{};
  SwarmFields f(impl_->swarm);
  std::vector<long long> ids(static_cast<std::size_t>(f.n));
  std::vector<double> vals(static_cast<std::size_t>(f.n) * per);
  for (PetscInt k = 0; k < f.n; ++k) {
    ids[static_cast<std::size_t>(k)] = f.id[k];
    double* v = vals.data() + per * k;
    v[0] = f.mass[k], v[1] = f.volume[k];
    for (int d = 0; d < D; ++d)
      v[at_x + d] = f.x[D * k + d], v[at_v + d] = f.velocity[D * k + d], v[at_l + d] = f.half_size[D * k + d];
    for (int c = 0; c < DD; ++c) v[at_s + c] = f.stress[DD * k + c];
    v[at_zz] = f.stress_zz[k];
    v[at_mat] = static_cast<double>(f.material[k]);
    v[at_state] = f.plastic_strain[k], v[at_state + 1] = f.internal_energy[k], v[at_state + 2] = f.plastic_work[k];
    for (int c = 0; c < ns; ++c) v[at_scalars + c] = sc[static_cast<std::size_t>(k * ns + c)];
  }
  const int ranks = impl_->size;
  std::vector<int> counts(static_cast<std::size_t>(ranks)), displs(static_cast<std::size_t>(ranks));
  int n = static_cast<int>(f.n);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, impl_->comm);
  int total = 0;
  for (int r = 0; r < ranks; ++r) displs[static_cast<std::size_t>(r)] = total, total += counts[static_cast<std::size_t>(r)];
  std::vector<long long> all_ids(static_cast<std::size_t>(total));
  MPI_Allgatherv(ids.data(), n, MPI_LONG_LONG, all_ids.data(), counts.data(), displs.data(), MPI_LONG_LONG, impl_->comm);
  for (int r = 0; r < ranks; ++r) counts[static_cast<std::size_t>(r)] *= per, displs[static_cast<std::size_t>(r)] *= per;
  std::vector<double> all(static_cast<std::size_t>(total) * per);
  MPI_Allgatherv(vals.data(), n * per, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, impl_->comm);
  std::vector<Particle> out(static_cast<std::size_t>(total));
  for (std::size_t k = 0; k < out.size(); ++k) {
    const double* v = all.data() + per * k;
    Particle& p = out[k];
    p.id = all_ids[k];
    p.mass = v[0], p.volume = v[1];
    p.position = Eigen::Map<const Vec<Dim>>(v + at_x);
    p.velocity = Eigen::Map<const Vec<Dim>>(v + at_v);
    p.half_size = Eigen::Map<const Vec<Dim>>(v + at_l);
    p.stress = Eigen::Map<const Mat<Dim>>(v + at_s);
    p.stress_zz = v[at_zz];
    p.material = static_cast<int>(v[at_mat]);
    p.plastic_strain = v[at_state], p.internal_energy = v[at_state + 1], p.plastic_work = v[at_state + 2];
    p.scalars.assign(v + at_scalars, v + at_scalars + ns);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  return out;
}

template <int Dim>
double DecomposedMpm<Dim>::Impl::initial_wave_speed(int material, double J, double energy) const {
  const Material& m = materials[static_cast<std::size_t>(material)];
  if (m.is_rigid()) return -std::numeric_limits<double>::infinity();  // stable_time_step counts them
  return particle_wave_speed(m, opt.analysis, J, energy);
}

// Simulation::stable_time_step over the ranks: the largest c_p + |v_p| of every rank (MPI_MAX), so
// every rank takes the same step, the smallest of the ranks' own limits.
template <int Dim>
double DecomposedMpm<Dim>::stable_time_step(double cfl, double max_time_step) const {
  const Impl& s = *impl_;
  double cmax = 0.0;
  {
    SwarmFields f(s.swarm);
    for (PetscInt k = 0; k < f.n; ++k)
      cmax = std::max(cmax, f.wave_speed[k] + Eigen::Map<const Vec<Dim>>(f.velocity + Dim * k).norm());
  }
  MPI_Allreduce(MPI_IN_PLACE, &cmax, 1, MPI_DOUBLE, MPI_MAX, s.comm);
  cmax = with_rigid_speeds(cmax, s.materials, s.time);
  // Penalty contact: the springs' limit and the stiffer penalty's wave factor (as the serial step).
  const double dt_penalty = s.penalty_time_step(cmax);
  // The damping's explicit limit while it acts (as the serial step).
  const double dt_damping = damping_active(s.opt.damping_rate, s.opt.damping_until, s.time)
                                ? damping_time_step_limit(s.opt.damping_rate)
                                : std::numeric_limits<double>::infinity();
  const double dt = cfl_time_step(cfl, s.grid.min_cell_size(), cmax, max_time_step);
  if (cmax <= 0.0) return std::min(dt, dt_damping);
  return std::min({dt, dt_penalty, dt_damping});
}

template <int Dim>
double DecomposedMpm<Dim>::total_plastic_work() const {
  SwarmFields f(impl_->swarm);
  double w = 0.0;
  for (PetscInt k = 0; k < f.n; ++k) w += f.plastic_work[k];
  MPI_Allreduce(MPI_IN_PLACE, &w, 1, MPI_DOUBLE, MPI_SUM, impl_->comm);
  return w;
}

// Every member defined in this file, for both dimensions (the other files instantiate theirs).
template class DecomposedMpm<2>;
template class DecomposedMpm<3>;

}  // namespace frictherm::mechanics
