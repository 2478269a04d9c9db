// Transfers for coupled physics on the decomposed grid (frictherm/mechanics/distributed.hpp): the
// particles' current stencils in the local node numbering, per-particle scalars carried by the swarm,
// and the two node exchanges of the step (local → owners summed, owners → ghosts) for caller values.
// No physics here: the coupling module builds its heat conduction on them.
#include "distributed/decomposed_state.hpp"

#include <stdexcept>

namespace frictherm::mechanics {

using detail::petsc_check;

template <int Dim>
MPI_Comm DecomposedMpm<Dim>::communicator() const {
  return impl_->comm;
}

template <int Dim>
int DecomposedMpm<Dim>::particle_scalar_index(const std::string& name) const {
  const auto& names = impl_->opt.particle_scalars;
  for (std::size_t c = 0; c < names.size(); ++c)
    if (names[c] == name) return static_cast<int>(c);
  throw std::invalid_argument("decomposed mechanics: no particle scalar '" + name +
                              "' (expected one of DecomposedOptions::particle_scalars)");
}

template <int Dim>
std::vector<double> DecomposedMpm<Dim>::Impl::scalar_values() const {
  PetscInt n = 0;
  petsc_check(DMSwarmGetLocalSize(swarm, &n), "DMSwarmGetLocalSize");
  std::vector<double> out(static_cast<std::size_t>(n) * static_cast<std::size_t>(scalars));
  if (scalars == 0) return out;
  double* v = nullptr;
  petsc_check(DMSwarmGetField(swarm, swarm_field::scalars, nullptr, nullptr, reinterpret_cast<void**>(&v)),
              "DMSwarmGetField");
  std::copy(v, v + out.size(), out.begin());
  DMSwarmRestoreField(swarm, swarm_field::scalars, nullptr, nullptr, reinterpret_cast<void**>(&v));
  return out;
}

template <int Dim>
std::vector<double> DecomposedMpm<Dim>::particle_scalar(int index) const {
  const Impl& s = *impl_;
  if (index < 0 || index >= s.scalars) throw std::out_of_range("decomposed mechanics: particle scalar index");
  const std::vector<double> all = s.scalar_values();
  const std::size_t n = all.size() / static_cast<std::size_t>(s.scalars);
  std::vector<double> out(n);
  for (std::size_t k = 0; k < n; ++k) out[k] = all[k * static_cast<std::size_t>(s.scalars) + static_cast<std::size_t>(index)];
  return out;
}

template <int Dim>
void DecomposedMpm<Dim>::set_particle_scalar(int index, const std::vector<double>& values) {
  Impl& s = *impl_;
  if (index < 0 || index >= s.scalars) throw std::out_of_range("decomposed mechanics: particle scalar index");
  if (values.size() != local_particles())
    throw std::invalid_argument("decomposed mechanics: set_particle_scalar got " + std::to_string(values.size()) +
                                " values for " + std::to_string(local_particles()) + " local particles");
  double* v = nullptr;
  petsc_check(DMSwarmGetField(s.swarm, swarm_field::scalars, nullptr, nullptr, reinterpret_cast<void**>(&v)),
              "DMSwarmGetField");
  for (std::size_t k = 0; k < values.size(); ++k)
    v[k * static_cast<std::size_t>(s.scalars) + static_cast<std::size_t>(index)] = values[k];
  DMSwarmRestoreField(s.swarm, swarm_field::scalars, nullptr, nullptr, reinterpret_cast<void**>(&v));
}

template <int Dim>
DecomposedLocalParticles DecomposedMpm<Dim>::local_particle_data(bool kinematics) const {
  SwarmFields f(impl_->swarm);
  DecomposedLocalParticles out;
  const auto n = static_cast<std::size_t>(f.n);
  out.id.assign(f.id, f.id + n);
  out.mass.assign(f.mass, f.mass + n);
  out.volume.assign(f.volume, f.volume + n);
  out.material.assign(f.material, f.material + n);
  out.plastic_work.assign(f.plastic_work, f.plastic_work + n);
  if (kinematics) {
    out.position.assign(f.x, f.x + Dim * n);
    out.velocity.assign(f.velocity, f.velocity + Dim * n);
    out.half_size.assign(f.half_size, f.half_size + Dim * n);
    out.initial_position.assign(f.x0, f.x0 + Dim * n);
    out.stress.assign(f.stress, f.stress + Dim * Dim * n);
    out.stress_zz.assign(f.stress_zz, f.stress_zz + n);
  }
  return out;
}

// S_ip and G_ip of this rank's particles at x (Dim values per particle, swarm order) with their
// half-widths, in the local numbering (current_stencils at the current positions, stencils_at).
template <int Dim>
void DecomposedMpm<Dim>::Impl::stencils_at(const double* x, Stencils& c) const {
  dispatch_shape(opt.shape, [&](auto kernel) {
    using Kernel = decltype(kernel);
    SwarmFields f(swarm);
    const auto n = static_cast<std::size_t>(f.n);
    c.first.assign(1, 0);
    c.node.clear();
    c.S.clear();
    c.G.clear();
    const NodeIndexer<Dim> ix = local_indexer();
    Stencil<Dim, Kernel> st;
    for (std::size_t k = 0; k < n; ++k) {
      st.evaluate(grid, Eigen::Map<const Vec<Dim>>((x ? x : f.x) + Dim * k), Eigen::Map<const Vec<Dim>>(f.half_size + Dim * k));
      if (!in_box(st))
        throw std::logic_error("decomposed mechanics: particle " + std::to_string(f.id[k]) +
                               " reaches nodes outside its rank's ghosted box (not migrated?)");
      st.for_each(ix, [&](int i, double S, const Vec<Dim>& G) {
        c.node.push_back(i);
        c.S.push_back(S);
        c.G.push_back(G);
      });
      c.first.push_back(static_cast<int>(c.node.size()));
    }
  });
}

template <int Dim>
const typename DecomposedMpm<Dim>::Stencils& DecomposedMpm<Dim>::current_stencils() {
  Impl& s = *impl_;
  if (s.current_valid) return s.current;
  s.stencils_at(nullptr, s.current);
  s.current_valid = true;
  return s.current;
}

template <int Dim>
typename DecomposedMpm<Dim>::Stencils DecomposedMpm<Dim>::stencils_at(const std::vector<double>& x) const {
  if (x.size() != Dim * local_particles())
    throw std::invalid_argument("decomposed mechanics: stencils_at takes Dim positions per local particle");
  Stencils c;
  impl_->stencils_at(x.data(), c);
  return c;
}

template <int Dim>
int DecomposedMpm<Dim>::local_node_count() const {
  return static_cast<int>(impl_->local_count());
}
template <int Dim>
const std::vector<int>& DecomposedMpm<Dim>::owned_local_nodes() const {
  return impl_->owned_local_int;
}

template <int Dim>
const Grid<Dim>& DecomposedMpm<Dim>::grid() const {
  return impl_->grid;
}
template <int Dim>
std::array<int, 2 * Dim> DecomposedMpm<Dim>::ghosted_nodes() const {
  std::array<int, 2 * Dim> r{};
  for (std::size_t d = 0; d < static_cast<std::size_t>(Dim); ++d) {
    r[2 * d] = static_cast<int>(impl_->box_start[d]);
    r[2 * d + 1] = static_cast<int>(impl_->box_start[d] + impl_->box_size[d]);
  }
  return r;
}

namespace {
void check_components(int components, int max) {
  if (components < 1 || components > max)
    throw std::invalid_argument("decomposed mechanics: " + std::to_string(components) +
                                " components per node (expected 1 to " + std::to_string(max) + ")");
}
}  // namespace

// The step's grid vectors carry dof = 1 + 2·Dim values per node; a transfer of fewer components pads with 0.
template <int Dim>
void DecomposedMpm<Dim>::sum_to_owned(const std::vector<double>& local, int components, std::vector<double>& owned) {
  Impl& s = *impl_;
  check_components(components, max_transfer_components);
  const auto nl = static_cast<std::size_t>(s.local_count()), no = static_cast<std::size_t>(s.owned_count());
  const auto c = static_cast<std::size_t>(components);
  if (local.size() != nl * c)
    throw std::invalid_argument("decomposed mechanics: sum_to_owned got " + std::to_string(local.size()) +
                                " values (expected local nodes × components = " + std::to_string(nl * c) + ")");
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(s.local, &a), "VecGetArray");
  for (std::size_t l = 0; l < nl; ++l)
    for (std::size_t d = 0; d < static_cast<std::size_t>(Impl::dof); ++d) a[Impl::dof * l + d] = d < c ? local[l * c + d] : 0.0;
  petsc_check(VecRestoreArray(s.local, &a), "VecRestoreArray");
  petsc_check(VecSet(s.global, 0.0), "VecSet");
  petsc_check(DMLocalToGlobal(s.da, s.local, ADD_VALUES, s.global), "DMLocalToGlobal");
  const PetscScalar* g = nullptr;
  petsc_check(VecGetArrayRead(s.global, &g), "VecGetArrayRead");
  owned.resize(no * c);
  for (std::size_t q = 0; q < no; ++q)
    for (std::size_t d = 0; d < c; ++d) owned[q * c + d] = g[Impl::dof * q + d];
  petsc_check(VecRestoreArrayRead(s.global, &g), "VecRestoreArrayRead");
}

template <int Dim>
void DecomposedMpm<Dim>::owned_to_local(const std::vector<double>& owned, int components, std::vector<double>& local) {
  Impl& s = *impl_;
  check_components(components, max_transfer_components);
  const auto nl = static_cast<std::size_t>(s.local_count()), no = static_cast<std::size_t>(s.owned_count());
  const auto c = static_cast<std::size_t>(components);
  if (owned.size() != no * c)
    throw std::invalid_argument("decomposed mechanics: owned_to_local got " + std::to_string(owned.size()) +
                                " values (expected owned nodes × components = " + std::to_string(no * c) + ")");
  PetscScalar* g = nullptr;
  petsc_check(VecGetArray(s.global, &g), "VecGetArray");
  for (std::size_t q = 0; q < no; ++q)
    for (std::size_t d = 0; d < static_cast<std::size_t>(Impl::dof); ++d) g[Impl::dof * q + d] = d < c ? owned[q * c + d] : 0.0;
  petsc_check(VecRestoreArray(s.global, &g), "VecRestoreArray");
  petsc_check(DMGlobalToLocal(s.da, s.global, INSERT_VALUES, s.local), "DMGlobalToLocal");
  const PetscScalar* a = nullptr;
  petsc_check(VecGetArrayRead(s.local, &a), "VecGetArrayRead");
  local.resize(nl * c);
  for (std::size_t l = 0; l < nl; ++l)
    for (std::size_t d = 0; d < c; ++d) local[l * c + d] = a[Impl::dof * l + d];
  petsc_check(VecRestoreArrayRead(s.local, &a), "VecRestoreArrayRead");
}

#define FRICTHERM_INSTANTIATE_TRANSFER(D)                                                              \
  template MPI_Comm DecomposedMpm<D>::communicator() const;                                            \
  template int DecomposedMpm<D>::particle_scalar_index(const std::string&) const;                      \
  template std::vector<double> DecomposedMpm<D>::Impl::scalar_values() const;                          \
  template std::vector<double> DecomposedMpm<D>::particle_scalar(int) const;                           \
  template void DecomposedMpm<D>::set_particle_scalar(int, const std::vector<double>&);                \
  template DecomposedLocalParticles DecomposedMpm<D>::local_particle_data(bool) const;                     \
  template const DecomposedMpm<D>::Stencils& DecomposedMpm<D>::current_stencils();                     \
  template DecomposedMpm<D>::Stencils DecomposedMpm<D>::stencils_at(const std::vector<double>&) const; \
  template int DecomposedMpm<D>::local_node_count() const;                                             \
  template const std::vector<int>& DecomposedMpm<D>::owned_local_nodes() const;                        \
  template const Grid<D>& DecomposedMpm<D>::grid() const;                                               \
  template std::array<int, 2 * D> DecomposedMpm<D>::ghosted_nodes() const;                              \
  template void DecomposedMpm<D>::sum_to_owned(const std::vector<double>&, int, std::vector<double>&); \
  template void DecomposedMpm<D>::owned_to_local(const std::vector<double>&, int, std::vector<double>&);
FRICTHERM_INSTANTIATE_TRANSFER(2)
FRICTHERM_INSTANTIATE_TRANSFER(3)
#undef FRICTHERM_INSTANTIATE_TRANSFER

}  // namespace frictherm::mechanics
