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
//   fields_to_owners       each rank's entries at multi-material ghost nodes (the slots of its fields
//                          there with a contribution) get places at the owner by a fetch-and-add of
//                          their count per node over node_sf and the owner's per-node base broadcast
//                          back; entry_sf (leaves: these entries, roots: the owner's received
//                          entries) carries per_field values, the material and the sending rank;
//                          the owner sums its own slots and the received entries per material, in
//                          material order and then rank order (independent of arrival), into the
//                          groups mt_* that the grid and contact phases work on
//   fields_to_ghosts       the groups' values (v, a after contact) into the owner's own slots and,
//                          over the same entry_sf, back into the slots of the ranks that sent them
//
// The fields' storage is per-field boxes (field_storage.cpp): the owner need not store a slot for a
// material that only other ranks bring to its node; the group holds it. "Reaches" is stencil
// membership (the particles' stencils, whatever the weight), so a node flagged single-material is
// reached by one material only on every rank and its DMDA total is that material's field, value for
// value as the serial per-material field. Nothing here is sent when no two materials meet at a
// shared node.
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
  MPI_Type_contiguous(unit_size(), MPI_DOUBLE, &field_unit);
  MPI_Type_commit(&field_unit);
  const std::size_t n = static_cast<std::size_t>(local_nodes);
  field_lo.assign(n, fields), field_hi.assign(n, -1), multi.assign(n, 0);
  owned_flag.assign(n, 0);
  for (const PetscInt l : owned_local) owned_flag[static_cast<std::size_t>(l)] = 1;
  ghost_of_local.assign(n, -1);
  for (std::size_t g = 0; g < ghost_local.size(); ++g)
    ghost_of_local[static_cast<std::size_t>(ghost_local[g])] = static_cast<PetscInt>(g);
  leaf_count.assign(n, 0), leaf_offset.assign(n, 0), root_count.assign(n, 0), entry_base.assign(n, 0);
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

// Exchange: this rank's per-material sums at multi-material ghost nodes (one entry per slot with a
// contribution) to the owners, which build the complete per-material groups of their multi nodes
// (the star forest is rebuilt each step: the entries change as the bodies move).
template <int Dim>
void DecomposedMpm<Dim>::Impl::fields_to_owners(double /*dt*/) {
  if (fields == 1) return;
  const std::size_t unit = static_cast<std::size_t>(unit_size());
  // Leaves: the slots at ghost multi nodes with a contribution, each the jth of its node here.
  for (const PetscInt l : ghost_local) {
    leaf_count[static_cast<std::size_t>(l)] = 0;
    if (multi[static_cast<std::size_t>(l)]) ++traffic.multi_ghost_nodes;
  }
  send_slot.clear(), send_field.clear(), send_jth.clear();
  for (std::size_t f = 0; f < boxes.size(); ++f)
    for (std::size_t sl = boxes[f].first; sl < boxes[f].first + boxes[f].count; ++sl) {
      const std::size_t u = static_cast<std::size_t>(slot_node[sl]);
      if (owned_flag[u] || !multi[u] || all_zero(slot_values(sl))) continue;
      send_slot.push_back(sl);
      send_field.push_back(static_cast<int>(f));
      send_jth.push_back(leaf_count[u]++);
    }
  traffic.field_entries_sent += static_cast<long>(send_slot.size());
  // Places at the owners: a fetch-and-add of the counts per node, then each owned node's base back.
  for (const PetscInt l : owned_local) root_count[static_cast<std::size_t>(l)] = 0;
  petsc_check(PetscSFFetchAndOpBegin(node_sf, MPIU_INT, root_count.data(), leaf_count.data(), leaf_offset.data(),
                                     MPI_SUM),
              "PetscSFFetchAndOpBegin");
  petsc_check(PetscSFFetchAndOpEnd(node_sf, MPIU_INT, root_count.data(), leaf_count.data(), leaf_offset.data(),
                                   MPI_SUM),
              "PetscSFFetchAndOpEnd");
  PetscInt received = 0;
  for (const PetscInt l : owned_local) {
    entry_base[static_cast<std::size_t>(l)] = received;
    received += root_count[static_cast<std::size_t>(l)];
  }
  petsc_check(PetscSFBcastBegin(node_sf, MPIU_INT, entry_base.data(), entry_base.data(), MPI_REPLACE),
              "PetscSFBcastBegin");
  petsc_check(PetscSFBcastEnd(node_sf, MPIU_INT, entry_base.data(), entry_base.data(), MPI_REPLACE), "PetscSFBcastEnd");
  entry_remote.resize(send_slot.size());
  send_buf.resize(send_slot.size() * unit);
  for (std::size_t i = 0; i < send_slot.size(); ++i) {
    const std::size_t sl = send_slot[i];
    const std::size_t u = static_cast<std::size_t>(slot_node[sl]);
    PetscSFNode& r = entry_remote[i];
    r.rank = ghost_remote[static_cast<std::size_t>(ghost_of_local[u])].rank;
    r.index = entry_base[u] + leaf_offset[u] + send_jth[i];
    double* b = send_buf.data() + i * unit;
    std::copy(slot_values(sl), slot_values(sl) + per_field, b);
    b[per_field] = static_cast<double>(send_field[i]);
    b[per_field + 1] = static_cast<double>(rank);
  }
  petsc_check(PetscSFDestroy(&entry_sf), "PetscSFDestroy");
  petsc_check(PetscSFCreate(comm, &entry_sf), "PetscSFCreate");
  petsc_check(PetscSFSetType(entry_sf, PETSCSFBASIC), "PetscSFSetType");
  petsc_check(PetscSFSetGraph(entry_sf, received, static_cast<PetscInt>(send_slot.size()), nullptr, PETSC_COPY_VALUES,
                              entry_remote.data(), PETSC_COPY_VALUES),
              "PetscSFSetGraph");
  petsc_check(PetscSFSetUp(entry_sf), "PetscSFSetUp");
  recv_buf.assign(static_cast<std::size_t>(received) * unit, 0.0);
  petsc_check(PetscSFReduceBegin(entry_sf, field_unit, send_buf.data(), recv_buf.data(), MPI_REPLACE),
              "PetscSFReduceBegin");
  petsc_check(PetscSFReduceEnd(entry_sf, field_unit, send_buf.data(), recv_buf.data(), MPI_REPLACE), "PetscSFReduceEnd");
  fields_to_mt();
}

// The owner's groups: per owned multi node (in owned order), its own slots with a contribution and
// the entries received for it, ordered by (material, rank) and summed per material in that order.
template <int Dim>
void DecomposedMpm<Dim>::Impl::fields_to_mt() {
  const std::size_t unit = static_cast<std::size_t>(unit_size());
  struct Item {
    PetscInt node;      // local node
    int field, from;    // material, contributing rank
    std::size_t where;  // own slot, or received entry
    bool own;
  };
  thread_local std::vector<Item> items;
  items.clear();
  for (std::size_t f = 0; f < boxes.size(); ++f)
    for (std::size_t sl = boxes[f].first; sl < boxes[f].first + boxes[f].count; ++sl) {
      const std::size_t u = static_cast<std::size_t>(slot_node[sl]);
      if (!owned_flag[u] || !multi[u] || all_zero(slot_values(sl))) continue;
      items.push_back({slot_node[sl], static_cast<int>(f), rank, sl, true});
    }
  const std::size_t received = recv_buf.size() / unit;
  for (const PetscInt l : owned_local) {
    const std::size_t u = static_cast<std::size_t>(l);
    for (PetscInt r = entry_base[u]; r < entry_base[u] + root_count[u]; ++r) {
      const double* b = recv_buf.data() + static_cast<std::size_t>(r) * unit;
      items.push_back({l, static_cast<int>(b[per_field]), static_cast<int>(b[per_field + 1]),
                       static_cast<std::size_t>(r), false});
    }
  }
  // Owned order of the nodes (owned_local increases with l), then material, then rank.
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    return a.node != b.node ? a.node < b.node : a.field != b.field ? a.field < b.field : a.from < b.from;
  });
  mt_q.clear(), mt_l.clear(), mt_first.clear(), mt_field.clear(), mt_values.clear(), mt_own.clear(), mt_order.clear();
  mt_recv_entry.assign(received, 0);
  const PetscInt bx = box_size[0], by = box_size[1];
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Item& it = items[i];
    const bool new_node = i == 0 || it.node != items[i - 1].node;
    if (new_node) {  // a new group: its owned index q (x fastest over the owned block) from the local node
      const PetscInt ii = it.node % bx + box_start[0], jj = (it.node / bx) % by + box_start[1];
      const PetscInt kk = it.node / (bx * by) + box_start[2];
      mt_q.push_back(((kk - owned_start[2]) * owned_size[1] + (jj - owned_start[1])) * owned_size[0] +
                     (ii - owned_start[0]));
      if (owned_local[static_cast<std::size_t>(mt_q.back())] != it.node)
        throw std::logic_error("decomposed mechanics: a multi-material node's owned index does not match its local node");
      mt_l.push_back(it.node);
      mt_first.push_back(mt_field.size());
    }
    if (new_node || it.field != items[i - 1].field) {
      mt_field.push_back(it.field);
      mt_values.resize(mt_values.size() + static_cast<std::size_t>(per_field), 0.0);
    }
    const std::size_t e = mt_field.size() - 1;
    const double* v = it.own ? slot_values(it.where) : recv_buf.data() + it.where * unit;
    double* m = mt_at(e);
    for (int c = 0; c < per_field; ++c) m[c] += v[c];
    mt_order.push_back({e, it.where, it.own});
    if (it.own)
      mt_own.push_back({it.where, e});
    else
      mt_recv_entry[it.where] = e;
  }
  mt_first.push_back(mt_field.size());
}

// Exchange: the groups' values (v, a after contact, and the rest of the entry) into this rank's own
// slots at its multi nodes and, over entry_sf, back to the slots that sent them.
template <int Dim>
void DecomposedMpm<Dim>::Impl::fields_to_ghosts(double /*dt*/) {
  if (fields == 1) return;
  const std::size_t unit = static_cast<std::size_t>(unit_size());
  for (const auto& [sl, e] : mt_own) std::copy(mt_at(e), mt_at(e) + per_field, slot_values(sl));
  for (std::size_t r = 0; r < mt_recv_entry.size(); ++r)
    std::copy(mt_at(mt_recv_entry[r]), mt_at(mt_recv_entry[r]) + per_field, recv_buf.data() + r * unit);
  petsc_check(PetscSFBcastBegin(entry_sf, field_unit, recv_buf.data(), send_buf.data(), MPI_REPLACE),
              "PetscSFBcastBegin");
  petsc_check(PetscSFBcastEnd(entry_sf, field_unit, recv_buf.data(), send_buf.data(), MPI_REPLACE), "PetscSFBcastEnd");
  for (std::size_t i = 0; i < send_slot.size(); ++i)
    std::copy(send_buf.data() + i * unit, send_buf.data() + i * unit + static_cast<std::size_t>(per_field),
              slot_values(send_slot[i]));
}

#define FRICTHERM_INSTANTIATE_SPARSE(D)                              \
  template void DecomposedMpm<D>::Impl::setup_sparse_exchange();      \
  template void DecomposedMpm<D>::Impl::exchange_field_ranges(double); \
  template void DecomposedMpm<D>::Impl::fields_to_owners(double);     \
  template void DecomposedMpm<D>::Impl::fields_to_mt();                \
  template void DecomposedMpm<D>::Impl::fields_to_ghosts(double);
FRICTHERM_INSTANTIATE_SPARSE(2)
FRICTHERM_INSTANTIATE_SPARSE(3)
#undef FRICTHERM_INSTANTIATE_SPARSE

}  // namespace frictherm::mechanics
