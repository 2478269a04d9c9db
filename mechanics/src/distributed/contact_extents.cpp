// Extent separation in the decomposed step (contact.separation "extent"; docs/contact.md, "Contact
// detection"): the serial measure_contact_extents (contact_extents.cpp) with its kernels
// (contact_extent.hpp) and the exchanges it needs. A contact node's gap is measured from the domains
// of every particle that gives it a weight, and these lie on every rank holding the node, so after
// find_contact_nodes:
//
//   1. owners: each contact group's side normals (side_normals, from the complete per-material sums)
//      listed per node as (field, n̂) items;
//   2. exchange: the lists to the ranks that sent entries to the node (entry_sf, owner → leaves: a
//      rank whose particles weigh on a multi-material ghost node sent at least one entry there);
//   3. every rank: its particles' extents along the items of the nodes they weigh on
//      (add_particle_extent), maxima per item;
//   4. exchange: the leaves' maxima to the owners (entry_sf, leaves → owner), whose maxima of them
//      are the serial maxima over all particles (a maximum does not depend on the order), kept per
//      mt entry for gather_sides (extent_gap) in both contact passes.
//
// Timed with find_contact_nodes. A list has at most K items, K the largest number of sides with a
// normal at a contact node over all ranks (one MPI_Allreduce), so a unit of the exchanges is K items.
#include "distributed/decomposed_state.hpp"

#include "contact_extent.hpp"

#include <mpi.h>

#include <algorithm>

namespace frictherm::mechanics {

using detail::petsc_check;

template <int Dim>
void DecomposedMpm<Dim>::Impl::free_extent_units() {
  if (extent_list_unit != MPI_DATATYPE_NULL) MPI_Type_free(&extent_list_unit);
  if (extent_max_unit != MPI_DATATYPE_NULL) MPI_Type_free(&extent_max_unit);
  extent_unit_items = 0;
}

template <int Dim>
template <class Kernel>
void DecomposedMpm<Dim>::Impl::measure_contact_extents(double /*dt*/) {
  using contact_detail::kNoExtent;
  constexpr std::size_t stride = contact_detail::kExtentDirections<Dim>;  // maxima per item (and per mt entry)
  if (!opt.contact || fields == 1 || opt.contact_options.separation != SeparationMethod::extent) return;
  const std::size_t entries_here = mt_field.size();
  mt_normal.assign(entries_here, Vec<Dim>::Zero());
  mt_extent_own.clear();  // no gap while the normals are gathered (as the serial compute_contact_normals)
  // 1. The owners' lists: per contact node its sides' normals, in material order.
  thread_local std::vector<ContactSide<Dim>> sides;
  thread_local std::vector<int> mats;
  thread_local std::vector<std::size_t> entries;
  const auto pair = [this](int a, int b) -> const ContactPairSettings& { return pair_of(a, b); };
  for (const PetscInt l : extent_nodes) extent_start[static_cast<std::size_t>(l)] = -1;
  extent_start.resize(static_cast<std::size_t>(local_count()), -1);
  extent_count.resize(static_cast<std::size_t>(local_count()), 0);
  extent_nodes.clear();
  extent_field.clear(), extent_normal.clear(), extent_own.clear(), extent_other.clear(), extent_entry.clear();
  const auto add_item = [&](int field, const Vec<Dim>& n, std::size_t e) {
    extent_field.push_back(field), extent_normal.push_back(n), extent_entry.push_back(e);
    extent_own.insert(extent_own.end(), stride, kNoExtent), extent_other.insert(extent_other.end(), stride, kNoExtent);
  };
  entry_group.assign(entries_here, 0);
  for (std::size_t g = 0; g + 1 < mt_first.size(); ++g)
    for (std::size_t e = mt_first[g]; e < mt_first[g + 1]; ++e) entry_group[e] = g;
  int most = 0;
  for (const auto& [q, g] : contact_nodes) {
    gather_sides(g, 1.0, sides, mats, entries);
    contact_detail::side_normals(sides, mats, pair, [&](std::size_t a, const Vec<Dim>& n) { mt_normal[entries[a]] = n; });
    const std::size_t l = static_cast<std::size_t>(mt_l[g]);
    const std::size_t first = extent_field.size();
    for (std::size_t e = mt_first[g]; e < mt_first[g + 1]; ++e)
      if (mt_normal[e].squaredNorm() > 0.0) add_item(mt_field[e], mt_normal[e], e);
    if (extent_field.size() == first) continue;
    extent_start[l] = static_cast<PetscInt>(first);
    extent_count[l] = static_cast<PetscInt>(extent_field.size() - first);
    extent_nodes.push_back(static_cast<PetscInt>(l));
    most = std::max(most, static_cast<int>(extent_count[l]));
  }
  const std::size_t owned_items = extent_field.size();
  MPI_Allreduce(MPI_IN_PLACE, &most, 1, MPI_INT, MPI_MAX, comm);
  mt_extent_own.assign(stride * entries_here, kNoExtent);
  mt_extent_other.assign(stride * entries_here, kNoExtent);
  if (most == 0) return;  // no contact node with a normal on any rank
  if (most != extent_unit_items) {  // (the star forests that used the old units are destroyed)
    free_extent_units();
    MPI_Type_contiguous(most * (1 + Dim), MPI_DOUBLE, &extent_list_unit);
    MPI_Type_commit(&extent_list_unit);
    MPI_Type_contiguous(most * 2 * static_cast<int>(stride), MPI_DOUBLE, &extent_max_unit);
    MPI_Type_commit(&extent_max_unit);
    extent_unit_items = most;
  }
  const std::size_t K = static_cast<std::size_t>(most), list_unit = K * (1 + Dim), max_unit = 2 * stride * K;
  // 2. The lists to the leaves: each received entry's root holds its node's list (field −1: no item).
  const std::size_t roots = mt_recv_entry.size(), leaves = send_slot.size();
  extent_root.assign(roots * list_unit, -1.0);
  for (std::size_t r = 0; r < roots; ++r) {
    const std::size_t l = static_cast<std::size_t>(mt_l[entry_group[mt_recv_entry[r]]]);
    if (extent_start[l] < 0) continue;
    double* b = extent_root.data() + r * list_unit;
    for (PetscInt j = 0; j < extent_count[l]; ++j) {
      const std::size_t i = static_cast<std::size_t>(extent_start[l] + j);
      double* item = b + static_cast<std::size_t>(j) * (1 + Dim);
      item[0] = static_cast<double>(extent_field[i]);
      for (int d = 0; d < Dim; ++d) item[1 + d] = extent_normal[i][d];
    }
  }
  extent_leaf.assign(leaves * list_unit, -1.0);
  petsc_check(PetscSFBcastBegin(entry_sf, extent_list_unit, extent_root.data(), extent_leaf.data(), MPI_REPLACE),
              "PetscSFBcastBegin");
  petsc_check(PetscSFBcastEnd(entry_sf, extent_list_unit, extent_root.data(), extent_leaf.data(), MPI_REPLACE),
              "PetscSFBcastEnd");
  // Ghost nodes' lists from the first leaf at each (every leaf at a node received the same list).
  for (std::size_t i = 0; i < leaves; ++i) {
    if (send_jth[i] != 0) continue;
    const std::size_t l = static_cast<std::size_t>(slot_node[send_slot[i]]);
    const double* b = extent_leaf.data() + i * list_unit;
    const std::size_t first = extent_field.size();
    for (std::size_t j = 0; j < K && b[j * (1 + Dim)] >= 0.0; ++j) {
      const double* item = b + j * (1 + Dim);
      add_item(static_cast<int>(item[0]), Eigen::Map<const Vec<Dim>>(item + 1), 0);
    }
    if (extent_field.size() == first) continue;
    extent_start[l] = static_cast<PetscInt>(first);
    extent_count[l] = static_cast<PetscInt>(extent_field.size() - first);
    extent_nodes.push_back(static_cast<PetscInt>(l));
  }
  // 3. This rank's particles (a rigid wall has no field), over the nodes they weigh on (S > 0).
  {
    SwarmFields f(swarm);
    const auto& st = stencils<Kernel>();
    const NodeIndexer<Dim> local_ix = local_indexer();
    for (PetscInt k = 0; k < f.n; ++k) {
      if (rigid_wall(f.material[k])) continue;
      const int field = field_of(f.material[k]);
      const Vec<Dim> x = Eigen::Map<const Vec<Dim>>(f.x + Dim * k), hs = Eigen::Map<const Vec<Dim>>(f.half_size + Dim * k);
      st[static_cast<std::size_t>(k)].for_each(local_ix, [&](int l, double S, const Vec<Dim>&) {
        if (!(S > 0.0)) return;
        const PetscInt start = extent_start[static_cast<std::size_t>(l)];
        if (start < 0) return;
        const std::size_t i = static_cast<std::size_t>(start);
        const int* item_field = extent_field.data() + i;
        contact_detail::add_particle_extent<Dim>(x, hs, field, static_cast<int>(extent_count[static_cast<std::size_t>(l)]),
                                                 [item_field](int j) { return item_field[j]; }, extent_normal.data() + i,
                                                 extent_own.data() + stride * i, extent_other.data() + stride * i);
      });
    }
  }
  // 4. The leaves' maxima to the owners (one leaf per node carries the node's; the others none).
  extent_leaf.assign(leaves * max_unit, kNoExtent);
  for (std::size_t i = 0; i < leaves; ++i) {
    if (send_jth[i] != 0) continue;
    const std::size_t l = static_cast<std::size_t>(slot_node[send_slot[i]]);
    double* b = extent_leaf.data() + i * max_unit;
    for (PetscInt j = 0; extent_start[l] >= 0 && j < extent_count[l]; ++j) {
      const std::size_t it = static_cast<std::size_t>(extent_start[l] + j), jj = static_cast<std::size_t>(j);
      for (std::size_t e = 0; e < stride; ++e) b[2 * stride * jj + e] = extent_own[stride * it + e], b[2 * stride * jj + stride + e] = extent_other[stride * it + e];
    }
  }
  extent_root.assign(roots * max_unit, kNoExtent);
  petsc_check(PetscSFReduceBegin(entry_sf, extent_max_unit, extent_leaf.data(), extent_root.data(), MPI_REPLACE),
              "PetscSFReduceBegin");
  petsc_check(PetscSFReduceEnd(entry_sf, extent_max_unit, extent_leaf.data(), extent_root.data(), MPI_REPLACE),
              "PetscSFReduceEnd");
  for (std::size_t r = 0; r < roots; ++r) {
    const std::size_t l = static_cast<std::size_t>(mt_l[entry_group[mt_recv_entry[r]]]);
    const double* b = extent_root.data() + r * max_unit;
    for (PetscInt j = 0; extent_start[l] >= 0 && j < extent_count[l]; ++j) {
      const std::size_t it = static_cast<std::size_t>(extent_start[l] + j), jj = static_cast<std::size_t>(j);
      for (std::size_t e = 0; e < stride; ++e) {
        extent_own[stride * it + e] = std::max(extent_own[stride * it + e], b[2 * stride * jj + e]);
        extent_other[stride * it + e] = std::max(extent_other[stride * it + e], b[2 * stride * jj + stride + e]);
      }
    }
  }
  for (std::size_t i = 0; i < owned_items; ++i) {
    for (std::size_t e = 0; e < stride; ++e) {
      mt_extent_own[stride * extent_entry[i] + e] = extent_own[stride * i + e];
      mt_extent_other[stride * extent_entry[i] + e] = extent_other[stride * i + e];
    }
  }
}

#define FRICTHERM_INSTANTIATE_EXTENTS(D)                                                            \
  template void DecomposedMpm<D>::Impl::free_extent_units();                                         \
  template void DecomposedMpm<D>::Impl::measure_contact_extents<LinearKernel>(double);               \
  template void DecomposedMpm<D>::Impl::measure_contact_extents<UGIMPKernel>(double);                \
  template void DecomposedMpm<D>::Impl::measure_contact_extents<QuadraticBSplineKernel>(double);     \
  template void DecomposedMpm<D>::Impl::measure_contact_extents<ExtendedBSplineKernel>(double);
FRICTHERM_INSTANTIATE_EXTENTS(2)
FRICTHERM_INSTANTIATE_EXTENTS(3)
#undef FRICTHERM_INSTANTIATE_EXTENTS

}  // namespace frictherm::mechanics
