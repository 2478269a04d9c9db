// XPIC(m) and FMPM(k) in the decomposed step (frictherm/mechanics/transfer.hpp; Hammerquist & Nairn
// 2017, Nairn & Hammerquist 2021): the serial filter_grid_velocity (simulation_transfer.cpp) over the
// ranks, with the kernels it shares (transfer/grid_to_particle.hpp). The series
// v* = Σ_{j=0}^{order−1} (I − S⁺S)^j w0 lives at the owners (per owned node, and per field entry at a
// multi-material node); each term j ≥ 1 is
//   vectors_to_ghosts   the term to every rank holding the node: a DMDA of Dim values per node
//                       (DMGlobalToLocal) and, at multi-material nodes, the group entries over the
//                       step's entry forest to the slots that sent them (as fields_to_ghosts)
//   round trip          local: Σ_p S_ip m_p Σ_k S_kp term_k into each slot (filter_round_trip)
//   vectors_to_owners   the sums to the owners (DMLocalToGlobal, ADD_VALUES; per field over the
//                       entry forest, summed in fields_to_mt's order)
//   next term           owners: term − sums/m, zero at velocity conditions (filter_next_term)
// and v* goes to the ghosts at the end for grid_to_particle. w0 is FMPM's v^{n+1} (nodal_velocities)
// or XPIC's v^n, the velocity p/m of the momenta the momentum update starts from (start_velocity).
// A rigid contact partner's field keeps w0, as the serial rigid fields. Each term costs one ghost
// update and one sum to the owners of Dim values per node (and per multi-material entry).
#include "distributed/decomposed_state.hpp"

#include <frictherm/mechanics/transfer/grid_to_particle.hpp>

#include <algorithm>

namespace frictherm::mechanics {

using detail::petsc_check;

// XPIC, owned nodes before the momentum update: v^n = p/m per field (0 at an empty node), as the
// serial save_start_velocity.
template <int Dim>
void DecomposedMpm<Dim>::Impl::start_velocity(double /*dt*/) {
  if (opt.particle_update != ParticleUpdate::xpic) return;
  constexpr int mass = Dof::mass, momentum = Dof::momentum;
  const auto velocity_of = [&](const double* node) {
    const double m = node[mass];
    return m > empty_node_mass ? Vec<Dim>(Eigen::Map<const Vec<Dim>>(node + momentum) / m) : Vec<Dim>(Vec<Dim>::Zero());
  };
  const PetscScalar* a = nullptr;
  petsc_check(VecGetArrayRead(global, &a), "VecGetArrayRead");
  start_owned.resize(static_cast<std::size_t>(owned_count()));
  for (PetscInt q = 0; q < owned_count(); ++q) start_owned[static_cast<std::size_t>(q)] = velocity_of(a + dof * q);
  petsc_check(VecRestoreArrayRead(global, &a), "VecRestoreArrayRead");
  start_mt.resize(mt_field.size());
  for (std::size_t e = 0; e < mt_field.size(); ++e) start_mt[e] = velocity_of(mt_at(e));
}

// Owned values (per owned node; per group entry) to every rank holding the node: filter_local over
// the ghosted box, slot_vector at this rank's slots of multi-material nodes.
template <int Dim>
void DecomposedMpm<Dim>::Impl::vectors_to_ghosts(const std::vector<Vec<Dim>>& owned, const std::vector<Vec<Dim>>& entries) {
  PetscScalar* g = nullptr;
  petsc_check(VecGetArray(filter_global, &g), "VecGetArray");
  for (std::size_t q = 0; q < owned.size(); ++q) Eigen::Map<Vec<Dim>>(g + Dim * q) = owned[q];
  petsc_check(VecRestoreArray(filter_global, &g), "VecRestoreArray");
  petsc_check(DMGlobalToLocalBegin(filter_da, filter_global, INSERT_VALUES, filter_local), "DMGlobalToLocalBegin");
  petsc_check(DMGlobalToLocalEnd(filter_da, filter_global, INSERT_VALUES, filter_local), "DMGlobalToLocalEnd");
  if (fields == 1) return;
  for (const auto& [sl, e] : mt_own) slot_vector[sl] = entries[e];
  vector_recv.resize(mt_recv_entry.size() * Dim);
  vector_send.resize(send_slot.size() * Dim);
  for (std::size_t r = 0; r < mt_recv_entry.size(); ++r)
    Eigen::Map<Vec<Dim>>(vector_recv.data() + r * Dim) = entries[mt_recv_entry[r]];
  petsc_check(PetscSFBcastBegin(entry_sf, vector_unit, vector_recv.data(), vector_send.data(), MPI_REPLACE),
              "PetscSFBcastBegin");
  petsc_check(PetscSFBcastEnd(entry_sf, vector_unit, vector_recv.data(), vector_send.data(), MPI_REPLACE),
              "PetscSFBcastEnd");
  for (std::size_t i = 0; i < send_slot.size(); ++i)
    slot_vector[send_slot[i]] = Eigen::Map<const Vec<Dim>>(vector_send.data() + i * Dim);
}

// slot_sums to the owners: per owned node the sum over its fields' slots and the ranks (as
// sum_to_owners), per group entry its field's sum (in fields_to_mt's order).
template <int Dim>
void DecomposedMpm<Dim>::Impl::vectors_to_owners(std::vector<Vec<Dim>>& owned, std::vector<Vec<Dim>>& entries) {
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(filter_local, &a), "VecGetArray");
  std::fill(a, a + Dim * local_count(), 0.0);
  for (std::size_t sl = 0; sl < slot_node.size(); ++sl) Eigen::Map<Vec<Dim>>(a + Dim * slot_node[sl]) += slot_sums[sl];
  petsc_check(VecRestoreArray(filter_local, &a), "VecRestoreArray");
  petsc_check(VecZeroEntries(filter_global), "VecZeroEntries");
  petsc_check(DMLocalToGlobalBegin(filter_da, filter_local, ADD_VALUES, filter_global), "DMLocalToGlobalBegin");
  petsc_check(DMLocalToGlobalEnd(filter_da, filter_local, ADD_VALUES, filter_global), "DMLocalToGlobalEnd");
  const PetscScalar* g = nullptr;
  petsc_check(VecGetArrayRead(filter_global, &g), "VecGetArrayRead");
  owned.resize(static_cast<std::size_t>(owned_count()));
  for (std::size_t q = 0; q < owned.size(); ++q) owned[q] = Eigen::Map<const Vec<Dim>>(g + Dim * q);
  petsc_check(VecRestoreArrayRead(filter_global, &g), "VecRestoreArrayRead");
  if (fields == 1) return;
  vector_send.resize(send_slot.size() * Dim);
  vector_recv.assign(mt_recv_entry.size() * Dim, 0.0);
  for (std::size_t i = 0; i < send_slot.size(); ++i) Eigen::Map<Vec<Dim>>(vector_send.data() + i * Dim) = slot_sums[send_slot[i]];
  petsc_check(PetscSFReduceBegin(entry_sf, vector_unit, vector_send.data(), vector_recv.data(), MPI_REPLACE),
              "PetscSFReduceBegin");
  petsc_check(PetscSFReduceEnd(entry_sf, vector_unit, vector_send.data(), vector_recv.data(), MPI_REPLACE),
              "PetscSFReduceEnd");
  entries.assign(mt_field.size(), Vec<Dim>::Zero());
  for (const MtItem& it : mt_order)
    entries[it.entry] += it.own ? slot_sums[it.where] : Vec<Dim>(Eigen::Map<const Vec<Dim>>(vector_recv.data() + it.where * Dim));
}

// XPIC/FMPM, before grid_to_particle (after the ghost update of v^{n+1}): v* at the owners, then at
// every rank holding the node (filter_local, slot_vector), as the serial filter_grid_velocity.
template <int Dim>
template <class Kernel>
void DecomposedMpm<Dim>::Impl::velocity_filter(double /*dt*/) {
  if (!filtered()) return;
  constexpr int mass = Dof::mass, velocity = Dof::velocity;
  if (!filter_da) {  // collective: every rank filters the same steps
    petsc_check(DMDACreateCompatibleDMDA(da, Dim, &filter_da), "DMDACreateCompatibleDMDA");
    petsc_check(DMCreateGlobalVector(filter_da, &filter_global), "DMCreateGlobalVector");
    petsc_check(DMCreateLocalVector(filter_da, &filter_local), "DMCreateLocalVector");
    MPI_Type_contiguous(Dim, MPI_DOUBLE, &vector_unit);
    MPI_Type_commit(&vector_unit);
  }
  const bool xpic = opt.particle_update == ParticleUpdate::xpic;
  const std::size_t owned = static_cast<std::size_t>(owned_count()), entries = mt_field.size();
  const PetscScalar* a = nullptr;
  petsc_check(VecGetArrayRead(global, &a), "VecGetArrayRead");
  // w0: XPIC's v^n, FMPM's v^{n+1}; j = 0 of the series.
  term_owned.resize(owned);
  for (std::size_t q = 0; q < owned; ++q) term_owned[q] = xpic ? start_owned[q] : Vec<Dim>(Eigen::Map<const Vec<Dim>>(a + dof * q + velocity));
  term_mt.resize(entries);
  for (std::size_t e = 0; e < entries; ++e) term_mt[e] = xpic ? start_mt[e] : Vec<Dim>(Eigen::Map<const Vec<Dim>>(mt_at(e) + velocity));
  filtered_owned = term_owned, filtered_mt = term_mt;
  slot_vector.assign(slot_node.size(), Vec<Dim>::Zero());  // a slot no particle reached with S or G ≠ 0 reads 0
  slot_sums.resize(slot_node.size());
  SwarmFields f(swarm);
  const auto& st = stencils<Kernel>();
  // The owned node's velocity conditions (fixed faces, rigid drives): the series keeps w0 there.
  const auto conditions = [&](std::size_t q) {
    return static_cast<std::uint8_t>(fixed_mask[q] | (has_rigid ? drive_mask[q] : 0));
  };
  for (int j = 1; j < opt.transfer_order; ++j) {
    vectors_to_ghosts(term_owned, term_mt);
    std::fill(slot_sums.begin(), slot_sums.end(), Vec<Dim>::Zero());
    const PetscScalar* terms = nullptr;
    petsc_check(VecGetArrayRead(filter_local, &terms), "VecGetArrayRead");
    for (PetscInt k = 0; k < f.n; ++k) {
      if (rigid(f.material[k])) continue;  // as the serial round trip: deformable materials only
      const NodeIndexer<Dim> ix = boxes[static_cast<std::size_t>(field_of(f.material[k]))].index;
      filter_round_trip<Dim>(st[static_cast<std::size_t>(k)], ix, f.mass[k],
                             [&](int slot) { return slot_vector_at(terms, static_cast<std::size_t>(slot)); },
                             [&](int slot, const Vec<Dim>& share) { slot_sums[static_cast<std::size_t>(slot)] += share; });
    }
    petsc_check(VecRestoreArrayRead(filter_local, &terms), "VecRestoreArrayRead");
    vectors_to_owners(sums_owned, sums_mt);
    // term ← term − S⁺S term (zero at empty nodes and velocity conditions); v* += term.
    for (std::size_t q = 0; q < owned; ++q) {
      if (multi[static_cast<std::size_t>(owned_local[q])]) continue;
      term_owned[q] = filter_next_term<Dim>(term_owned[q], sums_owned[q], a[dof * q + mass], empty_node_mass, conditions(q));
      filtered_owned[q] += term_owned[q];
    }
    for (std::size_t g = 0; g < mt_q.size(); ++g)
      for (std::size_t e = mt_first[g]; e < mt_first[g + 1]; ++e) {
        term_mt[e] = filter_next_term<Dim>(term_mt[e], sums_mt[e], mt_at(e)[mass], empty_node_mass,
                                           conditions(static_cast<std::size_t>(mt_q[g])));
        filtered_mt[e] += term_mt[e];
      }
  }
  // A rigid contact partner's field keeps w0 (the serial rigid fields).
  for (std::size_t q = 0; q < owned; ++q) {
    const std::size_t l = static_cast<std::size_t>(owned_local[q]);
    if (!multi[l] && fields > 1 && partner(static_cast<int>(field_lo[l])))
      filtered_owned[q] = xpic ? start_owned[q] : Vec<Dim>(Eigen::Map<const Vec<Dim>>(a + dof * q + velocity));
  }
  for (std::size_t e = 0; e < entries; ++e)
    if (partner(mt_field[e])) filtered_mt[e] = xpic ? start_mt[e] : Vec<Dim>(Eigen::Map<const Vec<Dim>>(mt_at(e) + velocity));
  petsc_check(VecRestoreArrayRead(global, &a), "VecRestoreArrayRead");
  vectors_to_ghosts(filtered_owned, filtered_mt);  // v* where the particles read it
}

#define FRICTHERM_INSTANTIATE_FILTER(D)                                                               \
  template void DecomposedMpm<D>::Impl::start_velocity(double);                                        \
  template void DecomposedMpm<D>::Impl::vectors_to_ghosts(const std::vector<Vec<D>>&, const std::vector<Vec<D>>&); \
  template void DecomposedMpm<D>::Impl::vectors_to_owners(std::vector<Vec<D>>&, std::vector<Vec<D>>&); \
  template void DecomposedMpm<D>::Impl::velocity_filter<LinearKernel>(double);                         \
  template void DecomposedMpm<D>::Impl::velocity_filter<UGIMPKernel>(double);                          \
  template void DecomposedMpm<D>::Impl::velocity_filter<QuadraticBSplineKernel>(double);               \
  template void DecomposedMpm<D>::Impl::velocity_filter<ExtendedBSplineKernel>(double);
FRICTHERM_INSTANTIATE_FILTER(2)
FRICTHERM_INSTANTIATE_FILTER(3)
#undef FRICTHERM_INSTANTIATE_FILTER

}  // namespace frictherm::mechanics
