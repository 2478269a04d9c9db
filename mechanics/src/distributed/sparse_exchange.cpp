// Per-material fields at shared nodes over PetscSF (issue 16, item 1; docs/distributed.md). With
// contact every material has its own velocity field (Nairn, Bardenhagen & Smith 2018 eqs. 1–6), but
// a node that one material reaches needs no per-material data: its field is the node's total, which
// the DMDA carries (1 + 2·Dim values per node, every ghost node). Only nodes that two or more materials
// reach need the per-material values (m, p, f, Σ S m x, Ω, g) complete at their owner, and these
// travel as (node, material) entries over a star forest built each step:
//
//   exchange_field_ranges  node_sf (leaves: this rank's ghost nodes, roots: the owners' local nodes):
//                          the smallest and largest material reaching each node reduced to the owner
//                          (MPI_MIN, MPI_MAX); multi = they differ; multi broadcast back to the ghosts
//   fields_to_owners       entry_sf (leaves: this rank's (ghost node, material) entries at multi
//                          nodes with a contribution; roots: the same entry at the owner): per_field
//                          doubles each, summed into the owner's values (MPI_SUM)
//   fields_to_ghosts       the same entry_sf, owner → ghosts: the material's v, a after contact
//
// "Reaches" is stencil membership (the particles' stencils, whatever the weight), so a node flagged
// single-material is reached by one material only on every rank and its DMDA total is that
// material's field, value for value as the serial per-material field. Nothing here is sent when no
// two materials meet at a shared node.
#include "distributed/decomposed_state.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

using detail::petsc_check;

// node_sf: every ghost node of this rank (local node l, not owned) → its owner's local node. The
// owner's ghosted box is its owned range widened by the stencil width and clipped to the grid
// (DM_BOUNDARY_NONE), as DMDAGetGhostCorners gives on that rank (checked on this one). Three axes in
// 2D and 3D alike (in 2D the z axis has one node and one process).
template <int Dim>
void DecomposedMpm<Dim>::Impl::setup_sparse_exchange() {
  using Box = std::array<std::array<PetscInt, 2>, 3>;  // per axis: start, size
  auto ghost_box = [&](const std::array<int, 3>& p) {
    Box box;
    for (std::size_t d = 0; d < 3; ++d) {
      const PetscInt w = static_cast<int>(d) < Dim ? width : 0;
      const PetscInt lo = std::max<PetscInt>(starts[d][static_cast<std::size_t>(p[d])] - w, 0);
      const PetscInt hi = std::min<PetscInt>(starts[d][static_cast<std::size_t>(p[d]) + 1] + w, starts[d].back());
      box[d] = {lo, hi - lo};
    }
    return box;
  };
  auto process_of = [&](const std::array<PetscInt, 3>& node) {  // process column / row / layer of a node
    std::array<int, 3> p{};
    for (std::size_t d = 0; d < 3; ++d)
      p[d] = static_cast<int>(std::upper_bound(starts[d].begin(), starts[d].end(), node[d]) - starts[d].begin()) - 1;
    return p;
  };
  const int px = static_cast<int>(procs[0]), py = static_cast<int>(procs[1]);
  const Box mine = ghost_box({rank % px, (rank / px) % py, rank / (px * py)});
  for (std::size_t d = 0; d < 3; ++d)
    if (mine[d][0] != box_start[d] || mine[d][1] != box_size[d])
      throw std::logic_error("decomposed mechanics: the DMDA's ghosted box differs from the one computed for the "
                             "per-material exchange");
  const auto& o = owned_start;
  const auto& on = owned_size;
  const auto& b = box_start;
  const auto& bn = box_size;
  owned_local.clear();
  owned_local.reserve(static_cast<std::size_t>(owned_count()));
  for (PetscInt k = o[2]; k < o[2] + on[2]; ++k)
    for (PetscInt j = o[1]; j < o[1] + on[1]; ++j)
      for (PetscInt i = o[0]; i < o[0] + on[0]; ++i) owned_local.push_back(local_node(i, j, k));
  ghost_local.clear();
  ghost_remote.clear();
  for (PetscInt k = b[2]; k < b[2] + bn[2]; ++k)
    for (PetscInt j = b[1]; j < b[1] + bn[1]; ++j)
      for (PetscInt i = b[0]; i < b[0] + bn[0]; ++i) {
        if (i >= o[0] && i < o[0] + on[0] && j >= o[1] && j < o[1] + on[1] && k >= o[2] && k < o[2] + on[2]) continue;
        const std::array<int, 3> p = process_of({i, j, k});
        const Box box = ghost_box(p);
        ghost_local.push_back(local_node(i, j, k));
        PetscSFNode owner;
        owner.rank = p[0] + px * (p[1] + py * p[2]);
        owner.index = ((k - box[2][0]) * box[1][1] + (j - box[1][0])) * box[0][1] + (i - box[0][0]);
        ghost_remote.push_back(owner);
      }
  const PetscInt local_nodes = local_count();
  petsc_check(PetscSFCreate(comm, &node_sf), "PetscSFCreate");
  petsc_check(PetscSFSetType(node_sf, PETSCSFBASIC), "PetscSFSetType");
  petsc_check(PetscSFSetGraph(node_sf, local_nodes, static_cast<PetscInt>(ghost_local.size()), ghost_local.data(),
                              PETSC_COPY_VALUES, ghost_remote.data(), PETSC_COPY_VALUES),
              "PetscSFSetGraph");
  petsc_check(PetscSFSetUp(node_sf), "PetscSFSetUp");
  MPI_Type_contiguous(per_field, MPI_DOUBLE, &field_unit);
  MPI_Type_commit(&field_unit);
  const std::size_t n = static_cast<std::size_t>(local_nodes);
  field_values.assign(n * static_cast<std::size_t>(fields * per_field), 0.0);
  field_lo.assign(n, fields), field_hi.assign(n, -1), multi.assign(n, 0);
}

// Exchange: the range of materials reaching each node, completed at the owner, and the multi flag
// back to every rank holding the node.
template <int Dim>
void DecomposedMpm<Dim>::Impl::exchange_field_ranges(double /*dt*/) {
  if (fields == 1) return;  // one velocity field: no node holds two
  root_lo = field_lo, root_hi = field_hi;
  petsc_check(PetscSFReduceBegin(node_sf, MPIU_INT, field_lo.data(), root_lo.data(), MPI_MIN), "PetscSFReduceBegin");
  petsc_check(PetscSFReduceBegin(node_sf, MPIU_INT, field_hi.data(), root_hi.data(), MPI_MAX), "PetscSFReduceBegin");
  petsc_check(PetscSFReduceEnd(node_sf, MPIU_INT, field_lo.data(), root_lo.data(), MPI_MIN), "PetscSFReduceEnd");
  petsc_check(PetscSFReduceEnd(node_sf, MPIU_INT, field_hi.data(), root_hi.data(), MPI_MAX), "PetscSFReduceEnd");
  std::fill(multi.begin(), multi.end(), 0);
  for (const PetscInt l : owned_local) {
    const std::size_t u = static_cast<std::size_t>(l);
    field_lo[u] = root_lo[u], field_hi[u] = root_hi[u];
    multi[u] = field_lo[u] < field_hi[u] ? 1 : 0;
  }
  petsc_check(PetscSFBcastBegin(node_sf, MPIU_INT, multi.data(), multi.data(), MPI_REPLACE), "PetscSFBcastBegin");
  petsc_check(PetscSFBcastEnd(node_sf, MPIU_INT, multi.data(), multi.data(), MPI_REPLACE), "PetscSFBcastEnd");
}

// Exchange: this rank's per-material sums at multi-material ghost nodes, one entry per material with
// a non-zero value, summed into the owner's (the star forest is rebuilt: the entries change as the
// bodies move).
template <int Dim>
void DecomposedMpm<Dim>::Impl::fields_to_owners(double /*dt*/) {
  if (fields == 1) return;
  entry_local.clear();
  entry_remote.clear();
  for (std::size_t g = 0; g < ghost_local.size(); ++g) {
    const PetscInt l = ghost_local[g];
    const std::size_t u = static_cast<std::size_t>(l);
    if (!multi[u]) continue;
    ++traffic.multi_ghost_nodes;
    for (PetscInt fl = field_lo[u]; fl <= field_hi[u]; ++fl) {
      const double* v = field_at(l, static_cast<int>(fl));
      if (std::all_of(v, v + per_field, [](double x) { return x == 0.0; })) continue;  // not reached here
      entry_local.push_back(l * fields + fl);
      PetscSFNode owner = ghost_remote[g];
      owner.index = owner.index * fields + fl;
      entry_remote.push_back(owner);
    }
  }
  traffic.field_entries_sent += static_cast<long>(entry_local.size());
  petsc_check(PetscSFDestroy(&entry_sf), "PetscSFDestroy");
  petsc_check(PetscSFCreate(comm, &entry_sf), "PetscSFCreate");
  petsc_check(PetscSFSetType(entry_sf, PETSCSFBASIC), "PetscSFSetType");
  petsc_check(PetscSFSetGraph(entry_sf, local_count() * fields, static_cast<PetscInt>(entry_local.size()),
                              entry_local.data(), PETSC_COPY_VALUES, entry_remote.data(), PETSC_COPY_VALUES),
              "PetscSFSetGraph");
  petsc_check(PetscSFSetUp(entry_sf), "PetscSFSetUp");
  // Leaves (ghost nodes) and roots (owned nodes) are disjoint entries of the same array.
  petsc_check(PetscSFReduceBegin(entry_sf, field_unit, field_values.data(), field_values.data(), MPI_SUM),
              "PetscSFReduceBegin");
  petsc_check(PetscSFReduceEnd(entry_sf, field_unit, field_values.data(), field_values.data(), MPI_SUM),
              "PetscSFReduceEnd");
}

// Exchange: the owners' per-material v, a (and the rest of the entry) back to the ghosts that sent it.
template <int Dim>
void DecomposedMpm<Dim>::Impl::fields_to_ghosts(double /*dt*/) {
  if (fields == 1) return;
  petsc_check(PetscSFBcastBegin(entry_sf, field_unit, field_values.data(), field_values.data(), MPI_REPLACE),
              "PetscSFBcastBegin");
  petsc_check(PetscSFBcastEnd(entry_sf, field_unit, field_values.data(), field_values.data(), MPI_REPLACE),
              "PetscSFBcastEnd");
}

template <int Dim>
long DecomposedMpm<Dim>::field_slots() const {
  return static_cast<long>(impl_->field_values.size()) / impl_->per_field;
}
template <int Dim>
long DecomposedMpm<Dim>::peak_field_slots() const {
  return field_slots();
}

#define FRICTHERM_INSTANTIATE_SPARSE(D)                              \
  template long DecomposedMpm<D>::field_slots() const;                \
  template long DecomposedMpm<D>::peak_field_slots() const;           \
  template void DecomposedMpm<D>::Impl::setup_sparse_exchange();      \
  template void DecomposedMpm<D>::Impl::exchange_field_ranges(double); \
  template void DecomposedMpm<D>::Impl::fields_to_owners(double);     \
  template void DecomposedMpm<D>::Impl::fields_to_ghosts(double);
FRICTHERM_INSTANTIATE_SPARSE(2)
FRICTHERM_INSTANTIATE_SPARSE(3)
#undef FRICTHERM_INSTANTIATE_SPARSE

}  // namespace frictherm::mechanics
