// The phases the MUSL and USF lists add to USL's (phase_lists.cpp; frictherm/mechanics/distributed.hpp):
// MUSL's remap of the momenta from the updated particles, the velocities from momenta (MUSL and USF),
// and USF's forces from the updated stress with their exchange to the owners. As the serial
// remap_momentum, velocity_from_momentum and add_internal_forces (mechanics/src/simulation_step.cpp,
// simulation_fields.cpp), on this rank's particles and owned nodes.
#include "distributed/decomposed_state.hpp"

#include <algorithm>

namespace frictherm::mechanics {

using detail::petsc_check;

// MUSL phase, local: the slots' momenta rebuilt from the updated particle velocities,
// p_i = Σ S_ip m_p v_p^{n+1} over the start-of-step stencils of the deformable particles (the masses
// and forces of particle_to_grid stay in the slots), as the serial remap_momentum.
template <int Dim>
template <class Kernel>
void DecomposedMpm<Dim>::Impl::remap_momentum(double /*dt*/) {
  constexpr int momentum = Dof::momentum;
  // Several fields: fields_to_ghosts wrote the groups' complete values into the slots at multi-material
  // nodes; this rank's own sums of particle_to_grid come back, so that the exchange sums them again.
  if (fields > 1) field_values = p2g_values;
  const std::size_t slots = slot_node.size();
  for (std::size_t sl = 0; sl < slots; ++sl)
    for (int d = 0; d < Dim; ++d) slot_values(sl)[momentum + d] = 0.0;
  SwarmFields f(swarm);
  const auto& st = stencils<Kernel>();
  for (PetscInt k = 0; k < f.n; ++k) {
    if (rigid(f.material[k])) continue;
    const NodeIndexer<Dim> ix = boxes[static_cast<std::size_t>(field_of(f.material[k]))].index;
    const Vec<Dim> mv = f.mass[k] * Eigen::Map<const Vec<Dim>>(f.velocity + Dim * k);
    st[static_cast<std::size_t>(k)].for_each(ix, [&](int slot, double S, const Vec<Dim>&) {
      double* node = slot_values(static_cast<std::size_t>(slot));
      for (int d = 0; d < Dim; ++d) node[momentum + d] += S * mv[d];
    });
  }
}

// MUSL phase, local: with several velocity fields this rank's slots as particle_to_grid left them,
// for remap_momentum (fields_to_ghosts overwrites those at multi-material nodes).
template <int Dim>
void DecomposedMpm<Dim>::Impl::keep_grid_values(double /*dt*/) {
  if (fields > 1) p2g_values = field_values;
}

// MUSL and USF phase, owned nodes: the velocity conditions on the remapped (MUSL) or extrapolated
// (USF) momenta (driven components m v_rigid, fixed ones 0), then v_i = p_i/m_i (empty nodes 0), as
// the serial velocity_from_momentum. The velocities take the momenta's place (Dof::velocity); under
// USF the momenta after the conditions are kept for forces_to_owners (the serial USF step goes on
// from them).
template <int Dim>
void DecomposedMpm<Dim>::Impl::velocity_from_momentum(double /*dt*/) {
  constexpr int mass = Dof::mass, momentum = Dof::momentum, velocity = Dof::velocity;
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(global, &a), "VecGetArray");
  kept_momentum.clear();
  for_each_owned_field(a, [&](PetscInt q, double* node, int field) {
    const std::uint8_t fixed = fixed_mask[static_cast<std::size_t>(q)];
    const std::uint8_t driven = has_rigid ? drive_mask[static_cast<std::size_t>(q)] : 0;
    const double m = node[mass];
    if (partner(field)) {  // a rigid partner's field: m v_rigid (the serial apply_velocity_bc)
      const Vec<Dim> v = partner_velocity(field);
      for (int d = 0; d < Dim; ++d) node[momentum + d] = m * v[d];
    } else {
      for (int d = 0; d < Dim; ++d) {
        if (driven & (1u << d)) node[momentum + d] = m * drive_velocity[static_cast<std::size_t>(q)][d];
        if (fixed & (1u << d)) node[momentum + d] = 0.0;
      }
    }
    if (opt.usf) kept_momentum.insert(kept_momentum.end(), node + momentum, node + momentum + Dim);
    for (int d = 0; d < Dim; ++d) node[velocity + d] = m > empty_node_mass ? node[momentum + d] / m : 0.0;
  });
  petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
}

// USF phase, local: the slots' forces from the stress the stress update left,
// f_i = Σ (S_ip m_p g − V_p σ_p G_ip) over the deformable particles' start-of-step stencils (Nairn 2018
// eq. 3), then the loads of this rank's particles (as the serial add_internal_forces, then
// particle loads, loads/particle_loads.cpp). The slots' other values stay (forces_to_owners sends the forces only).
template <int Dim>
template <class Kernel>
void DecomposedMpm<Dim>::Impl::internal_forces(double /*dt*/) {
  constexpr int force = Dof::force;
  const std::size_t slots = slot_node.size();
  for (std::size_t sl = 0; sl < slots; ++sl) std::fill(slot_values(sl) + force, slot_values(sl) + force + Dim, 0.0);
  SwarmFields f(swarm);
  const auto& st = stencils<Kernel>();
  const Vec<Dim> g = opt.gravity;
  for (PetscInt k = 0; k < f.n; ++k) {
    if (rigid(f.material[k])) continue;  // a rigid material's velocity is prescribed: no force
    const NodeIndexer<Dim> ix = boxes[static_cast<std::size_t>(field_of(f.material[k]))].index;
    const Mat<Dim> Vsig = f.volume[k] * Eigen::Map<const Mat<Dim>>(f.stress + Dim * Dim * k);
    const Vec<Dim> mg = f.mass[k] * g;
    st[static_cast<std::size_t>(k)].for_each(ix, [&](int slot, double S, const Vec<Dim>& G) {
      const Vec<Dim> fi = S * mg - Vsig * G;
      double* node = slot_values(static_cast<std::size_t>(slot));
      for (int d = 0; d < Dim; ++d) node[force + d] += fi[d];
    });
  }
  if (!local_loads.empty()) add_loads<Kernel>(f);
}

// USF phase, exchange: the slots' forces summed per node into the owners as sum_to_owners sums them
// (the local vector's other values 0, so the owners' masses are unchanged), and at multi-material
// nodes per field over entry_sf into the groups, in fields_to_mt's order; then the momenta
// velocity_from_momentum kept back in their places (for_each_owned_field's order).
template <int Dim>
void DecomposedMpm<Dim>::Impl::forces_to_owners(double /*dt*/) {
  constexpr int momentum = Dof::momentum, force = Dof::force;
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(local, &a), "VecGetArray");
  std::fill(a, a + dof * local_count(), 0.0);
  for (std::size_t sl = 0; sl < slot_node.size(); ++sl) {
    double* node = a + dof * slot_node[sl];
    const double* v = slot_values(sl);
    for (int d = 0; d < Dim; ++d) node[force + d] += v[force + d];
  }
  petsc_check(VecRestoreArray(local, &a), "VecRestoreArray");
  petsc_check(VecGetArray(global, &a), "VecGetArray");
  for (PetscInt q = 0; q < owned_count(); ++q) std::fill(a + dof * q + force, a + dof * q + force + Dim, 0.0);
  petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
  petsc_check(DMLocalToGlobalBegin(da, local, ADD_VALUES, global), "DMLocalToGlobalBegin");
  petsc_check(DMLocalToGlobalEnd(da, local, ADD_VALUES, global), "DMLocalToGlobalEnd");
  if (fields > 1) {
    const std::size_t unit = static_cast<std::size_t>(unit_size());
    for (std::size_t i = 0; i < send_slot.size(); ++i) {
      double* b = send_buf.data() + i * unit;
      std::copy(slot_values(send_slot[i]), slot_values(send_slot[i]) + per_field, b);
      b[per_field] = static_cast<double>(send_field[i]);
      b[per_field + 1] = static_cast<double>(rank);
    }
    petsc_check(PetscSFReduceBegin(entry_sf, field_unit, send_buf.data(), recv_buf.data(), MPI_REPLACE),
                "PetscSFReduceBegin");
    petsc_check(PetscSFReduceEnd(entry_sf, field_unit, send_buf.data(), recv_buf.data(), MPI_REPLACE),
                "PetscSFReduceEnd");
    for (std::size_t e = 0; e < mt_field.size(); ++e) std::fill(mt_at(e) + force, mt_at(e) + force + Dim, 0.0);
    for (const MtItem& it : mt_order) {
      const double* v = it.own ? slot_values(it.where) : recv_buf.data() + it.where * unit;
      for (int d = 0; d < Dim; ++d) mt_at(it.entry)[force + d] += v[force + d];
    }
  }
  petsc_check(VecGetArray(global, &a), "VecGetArray");
  std::size_t i = 0;
  for_each_owned_field(a, [&](PetscInt, double* node, int) {
    for (int d = 0; d < Dim; ++d) node[momentum + d] = kept_momentum[i++];
  });
  petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
}

#define FRICTHERM_INSTANTIATE_SCHEME_KERNEL(D, K)                                \
  template void DecomposedMpm<D>::Impl::remap_momentum<K>(double);               \
  template void DecomposedMpm<D>::Impl::internal_forces<K>(double);
#define FRICTHERM_INSTANTIATE_SCHEME(D)                                         \
  FRICTHERM_INSTANTIATE_SCHEME_KERNEL(D, LinearKernel)                          \
  FRICTHERM_INSTANTIATE_SCHEME_KERNEL(D, UGIMPKernel)                           \
  FRICTHERM_INSTANTIATE_SCHEME_KERNEL(D, QuadraticBSplineKernel)                \
  FRICTHERM_INSTANTIATE_SCHEME_KERNEL(D, ExtendedBSplineKernel)                 \
  template void DecomposedMpm<D>::Impl::keep_grid_values(double);               \
  template void DecomposedMpm<D>::Impl::velocity_from_momentum(double);         \
  template void DecomposedMpm<D>::Impl::forces_to_owners(double);
FRICTHERM_INSTANTIATE_SCHEME(2)
FRICTHERM_INSTANTIATE_SCHEME(3)
#undef FRICTHERM_INSTANTIATE_SCHEME
#undef FRICTHERM_INSTANTIATE_SCHEME_KERNEL

}  // namespace frictherm::mechanics
