// Decomposed 2D MPM (frictherm/mechanics/distributed.hpp): the DMDA of the grid's nodes, the DMSwarm
// of the particles, ownership by nearest node, migration, reductions and the gather by global id.
#include "distributed/decomposed_state.hpp"

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
int stencil_reach(ShapeKind kind) {
  if (kind == ShapeKind::extended_bspline)
    throw std::invalid_argument("decomposed mechanics: shape 'extended_bspline' is not supported (expected linear, "
                                "ugimp or quadratic_bspline)");
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

DecomposedMpm2D::Impl::~Impl() {
  PetscSFDestroy(&entry_sf);
  PetscSFDestroy(&node_sf);
  if (field_unit != MPI_DATATYPE_NULL) MPI_Type_free(&field_unit);
  VecDestroy(&local);
  VecDestroy(&global);
  DMDestroy(&swarm);
  DMDestroy(&da);
}

int DecomposedMpm2D::Impl::owner_of(const double* x) const {
  int p[2];
  for (int d = 0; d < 2; ++d) {
    const double s = (x[d] - grid.lo()[d]) * grid.inverse_cell_size()[d];
    const PetscInt node =
        std::clamp<PetscInt>(static_cast<PetscInt>(std::floor(s + 0.5)) + Grid<2>::ghost, 0, starts[d].back() - 1);
    p[d] = static_cast<int>(std::upper_bound(starts[d].begin(), starts[d].end(), node) - starts[d].begin()) - 1;
  }
  return p[0] + static_cast<int>(procs[0]) * p[1];  // DMDA ranks: x fastest
}

DecomposedMpm2D::DecomposedMpm2D(MPI_Comm comm, const Grid<2>& grid, const Material& material,
                                 const DecomposedOptions& options)
    : DecomposedMpm2D(comm, grid, std::vector<Material>{material}, options) {}

DecomposedMpm2D::DecomposedMpm2D(MPI_Comm comm, const Grid<2>& grid, const std::vector<Material>& materials,
                                 const DecomposedOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  if (materials.empty()) throw std::invalid_argument("decomposed mechanics: no material given");
  for (const Material& material : materials)
    if (material.kind != MaterialKind::linear_elastic)
      throw std::invalid_argument("decomposed mechanics: material '" + material.name + "' has kind '" +
                                  to_string(material.kind) + "' (expected linear_elastic)");
  for (const FixedFace& face : options.fixed_faces)
    if (face.axis < 0 || face.axis >= 2)
      throw std::invalid_argument("decomposed mechanics: fixed face axis " + std::to_string(face.axis) +
                                  " (expected 0 or 1)");
  s.width = stencil_reach(options.shape);
  s.comm = comm;
  MPI_Comm_rank(comm, &s.rank);
  MPI_Comm_size(comm, &s.size);
  s.grid = grid;
  s.materials = materials;
  s.opt = options;
  s.setup_contact();  // checks the contact settings before any collective PETSc call
  s.fields = options.contact ? static_cast<int>(materials.size()) : 1;
  s.per_field = options.contact ? node_dof::with_contact : node_dof::without_contact;
  const IVec<2>& nodes = grid.nodes_per_dim();
  petsc_check(DMDACreate2d(comm, DM_BOUNDARY_NONE, DM_BOUNDARY_NONE, DMDA_STENCIL_BOX, nodes[0], nodes[1],
                           PETSC_DECIDE, PETSC_DECIDE, s.dof, s.width, nullptr, nullptr, &s.da),
              "DMDACreate2d");
  petsc_check(DMSetUp(s.da), "DMSetUp(DMDA)");
  const Vec<2> first = grid.lo() - grid.cell_size(), last = grid.hi() + grid.cell_size();  // ghost layer
  petsc_check(DMDASetUniformCoordinates(s.da, first[0], last[0], first[1], last[1], 0.0, 0.0),
              "DMDASetUniformCoordinates");
  petsc_check(DMDAGetCorners(s.da, &s.xs, &s.ys, nullptr, &s.xm, &s.ym, nullptr), "DMDAGetCorners");
  petsc_check(DMDAGetGhostCorners(s.da, &s.gxs, &s.gys, nullptr, &s.gxm, &s.gym, nullptr), "DMDAGetGhostCorners");
  petsc_check(DMDAGetInfo(s.da, nullptr, nullptr, nullptr, nullptr, &s.procs[0], &s.procs[1], nullptr, nullptr,
                          nullptr, nullptr, nullptr, nullptr, nullptr),
              "DMDAGetInfo");
  const PetscInt* counts[2] = {nullptr, nullptr};
  petsc_check(DMDAGetOwnershipRanges(s.da, &counts[0], &counts[1], nullptr), "DMDAGetOwnershipRanges");
  for (int d = 0; d < 2; ++d) {
    s.starts[d].assign(1, 0);
    for (PetscInt p = 0; p < s.procs[d]; ++p) s.starts[d].push_back(s.starts[d].back() + counts[d][p]);
  }
  petsc_check(DMCreateLocalVector(s.da, &s.local), "DMCreateLocalVector");
  petsc_check(DMCreateGlobalVector(s.da, &s.global), "DMCreateGlobalVector");

  // The swarm: PIC type over the DMDA (DMSwarmSetType(PIC) registers DMSwarmPIC_coor, 2 per point).
  petsc_check(DMCreate(comm, &s.swarm), "DMCreate(DMSwarm)");
  petsc_check(DMSetType(s.swarm, DMSWARM), "DMSetType(DMSWARM)");
  petsc_check(DMSetDimension(s.swarm, 2), "DMSetDimension");
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
  reg(swarm_field::velocity, 2, PETSC_DOUBLE);
  reg(swarm_field::half_size, 2, PETSC_DOUBLE);
  reg(swarm_field::stress, 4, PETSC_DOUBLE);
  reg(swarm_field::stress_zz, 1, PETSC_DOUBLE);
  reg(swarm_field::deformation, 4, PETSC_DOUBLE);
  reg(swarm_field::material, 1, PETSC_INT);
  reg(swarm_field::initial_position, 2, PETSC_DOUBLE);
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
  s.traffic.ghost_nodes = static_cast<long>(s.gxm * s.gym - s.xm * s.ym);
  s.traffic.values_per_node = s.dof;
  s.traffic.field_entry_bytes = s.per_field * static_cast<int>(sizeof(double));
  s.setup_fixed_faces();
  s.setup_sparse_exchange();
  int bytes = 0;
  for (const char* name : {DMSwarmPICField_coor, DMSwarmField_pid, DMSwarmField_rank, DMSwarmPICField_cellid,
                           swarm_field::id, swarm_field::mass, swarm_field::volume, swarm_field::volume0,
                           swarm_field::velocity, swarm_field::half_size, swarm_field::stress,
                           swarm_field::stress_zz, swarm_field::deformation, swarm_field::material,
                           swarm_field::initial_position}) {
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

DecomposedMpm2D::~DecomposedMpm2D() = default;

void DecomposedMpm2D::add_particles(const std::vector<DecomposedParticle>& particles) {
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
      const DecomposedParticle& p = particles[q];
      const std::size_t k = static_cast<std::size_t>(before) + q;
      f.id[k] = static_cast<long>(p.id);
      f.mass[k] = p.mass;
      f.volume[k] = f.volume0[k] = p.volume;
      for (int d = 0; d < 2; ++d) {
        f.x[2 * k + d] = f.x0[2 * k + d] = p.position[d];
        f.velocity[2 * k + d] = p.velocity[d];
        f.half_size[2 * k + d] = p.half_size[d];
      }
      Eigen::Map<Mat<2>>(f.stress + 4 * k) = p.stress;
      f.stress_zz[k] = p.stress_zz;
      f.material[k] = static_cast<PetscInt>(p.material);
      Eigen::Map<Mat<2>>(f.F + 4 * k) = Mat<2>::Identity();
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
void DecomposedMpm2D::Impl::migrate(double /*dt*/) {
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
      dest[k] = owner_of(x + 2 * k);
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

int DecomposedMpm2D::stencil_width() const { return impl_->width; }
std::array<int, 2> DecomposedMpm2D::processes() const {
  return {static_cast<int>(impl_->procs[0]), static_cast<int>(impl_->procs[1])};
}
std::array<int, 4> DecomposedMpm2D::owned_nodes() const {
  const Impl& s = *impl_;
  return {static_cast<int>(s.xs), static_cast<int>(s.xs + s.xm), static_cast<int>(s.ys), static_cast<int>(s.ys + s.ym)};
}
std::size_t DecomposedMpm2D::local_particles() const {
  PetscInt n = 0;
  petsc_check(DMSwarmGetLocalSize(impl_->swarm, &n), "DMSwarmGetLocalSize");
  return static_cast<std::size_t>(n);
}
const DecomposedTraffic& DecomposedMpm2D::traffic() const { return impl_->traffic; }
int DecomposedMpm2D::velocity_fields() const { return impl_->fields; }

// Fixed faces as Simulation::fix_face: nodes at lattice index ≤ 0 (lower) or ≥ cells (upper) along
// the axis, i.e. DMDA index ≤ 1 or ≥ cells + 1 (DMDA index = lattice + Grid<2>::ghost).
void DecomposedMpm2D::Impl::setup_fixed_faces() {
  fixed_mask.assign(static_cast<std::size_t>(xm * ym), 0);
  for (const FixedFace& face : opt.fixed_faces) {  // axes checked by the constructor
    const PetscInt last = grid.cells()[face.axis] + Grid<2>::ghost;
    for (PetscInt j = ys; j < ys + ym; ++j)
      for (PetscInt i = xs; i < xs + xm; ++i) {
        const PetscInt l = face.axis == 0 ? i : j;
        if (face.upper ? l < last : l > Grid<2>::ghost) continue;
        for (int d = 0; d < 2; ++d)
          if (face.components[static_cast<std::size_t>(d)])
            fixed_mask[static_cast<std::size_t>((j - ys) * xm + (i - xs))] |= static_cast<std::uint8_t>(1u << d);
      }
  }
}

long long DecomposedMpm2D::global_particles() const {
  long long n = static_cast<long long>(local_particles());
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_LONG_LONG, MPI_SUM, impl_->comm);
  return n;
}

double DecomposedMpm2D::total_mass() const {
  SwarmFields f(impl_->swarm);
  double m = 0.0;
  for (PetscInt k = 0; k < f.n; ++k) m += f.mass[k];
  MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_SUM, impl_->comm);
  return m;
}

Vec<2> DecomposedMpm2D::total_momentum() const {
  SwarmFields f(impl_->swarm);
  double p[2] = {0.0, 0.0};
  for (PetscInt k = 0; k < f.n; ++k)
    for (int d = 0; d < 2; ++d) p[d] += f.mass[k] * f.velocity[2 * k + d];
  MPI_Allreduce(MPI_IN_PLACE, p, 2, MPI_DOUBLE, MPI_SUM, impl_->comm);
  return Vec<2>(p[0], p[1]);
}

double DecomposedMpm2D::total_momentum_scale() const {
  SwarmFields f(impl_->swarm);
  double s = 0.0;
  for (PetscInt k = 0; k < f.n; ++k) s += f.mass[k] * std::hypot(f.velocity[2 * k], f.velocity[2 * k + 1]);
  MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, impl_->comm);
  return s;
}

std::vector<DecomposedParticle> DecomposedMpm2D::gather() const {
  const int ns = impl_->scalars;
  const int per = 14 + ns;  // doubles per particle below
  const std::vector<double> sc = ns > 0 ? impl_->scalar_values() : std::vector<double>{};
  SwarmFields f(impl_->swarm);
  std::vector<long long> ids(static_cast<std::size_t>(f.n));
  std::vector<double> vals(static_cast<std::size_t>(f.n) * per);
  for (PetscInt k = 0; k < f.n; ++k) {
    ids[static_cast<std::size_t>(k)] = f.id[k];
    double* v = vals.data() + per * k;
    v[0] = f.mass[k], v[1] = f.volume[k], v[2] = f.x[2 * k], v[3] = f.x[2 * k + 1];
    v[4] = f.velocity[2 * k], v[5] = f.velocity[2 * k + 1], v[6] = f.half_size[2 * k], v[7] = f.half_size[2 * k + 1];
    for (int c = 0; c < 4; ++c) v[8 + c] = f.stress[4 * k + c];
    v[12] = f.stress_zz[k];
    v[13] = static_cast<double>(f.material[k]);
    for (int c = 0; c < ns; ++c) v[14 + c] = sc[static_cast<std::size_t>(k * ns + c)];
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
  std::vector<DecomposedParticle> out(static_cast<std::size_t>(total));
  for (std::size_t k = 0; k < out.size(); ++k) {
    const double* v = all.data() + per * k;
    DecomposedParticle& p = out[k];
    p.id = all_ids[k];
    p.mass = v[0], p.volume = v[1];
    p.position = Vec<2>(v[2], v[3]);
    p.velocity = Vec<2>(v[4], v[5]);
    p.half_size = Vec<2>(v[6], v[7]);
    p.stress = Eigen::Map<const Mat<2>>(v + 8);
    p.stress_zz = v[12];
    p.material = static_cast<int>(v[13]);
    p.scalars.assign(v + 14, v + 14 + ns);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  return out;
}

}  // namespace frictherm::mechanics
