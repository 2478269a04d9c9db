// The step's list of contact nodes (Nairn, Bardenhagen & Smith 2018 §2.2: a node where two or more
// materials have mass): (node, slot, field) entries grouped by node, shared between the threads by
// ranges of grid nodes. The list is the same for every thread count.
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/thread_partition.hpp>
#include <frictherm/mechanics/parallel_region.hpp>

#include <omp.h>

#include <algorithm>
#include <climits>

namespace frictherm::mechanics {

// Entries come grouped by node, the groups in order of first appearance over the slots with mass
// (fields in material order, a field's slots in node order), within a group in field order. Each
// thread takes a range of grid nodes, so the counts and cursors it writes are its own:
//   1. per field, the slots of its nodes (a field's slots are in node order: a binary search);
//      their counts and cursors reset, the fields with mass at each node counted;
//   2. per field, the nodes with two or more fields that first have mass in that field, and their
//      entries: the blocks (field f, thread t), laid out f-major then t, are node order within f;
//   3. after a barrier, the blocks' offsets, then each node's run filled in field order.
// Counting sort, O(slots) with no comparison sort.
template <int Dim>
void Simulation<Dim>::find_contact_nodes() {
  if (!contact_setup_.any_multimaterial) {  // every present pair uses penalty contact
    contact_nodes_.entries.clear();
    contact_nodes_.groups.assign(1, 0);
    return;
  }
  const std::size_t nf = fields_.size();
  int span_lo = INT_MAX, span_hi = INT_MIN;  // the grid nodes some field covers: [span_lo, span_hi)
  for (const VelocityField<Dim>& F : fields_)
    if (F.count > 0) {
      span_lo = std::min(span_lo, layout_.slot_node[F.first]);
      span_hi = std::max(span_hi, layout_.slot_node[F.first + F.count - 1] + 1);
    }
  if (span_lo >= span_hi) {
    contact_nodes_.entries.clear();
    contact_nodes_.groups.assign(1, 0);
    return;
  }
  // Below a few thousand slots the fork and the barriers cost more than the work they share.
  const int threads = nodes_.mass.size() >= 8192 ? threads_.count : 1;
  if (contact_nodes_.listing.size() < static_cast<std::size_t>(threads))
    contact_nodes_.listing.resize(static_cast<std::size_t>(threads));
  const double mmin = empty_node_mass_;
  const bool reset_whole_range = nodes_.mass.size() >= static_cast<std::size_t>(span_hi - span_lo);

  parallel_region(threads, [&] {
    const int t = omp_get_thread_num(), T = omp_get_num_threads();
    ContactNodeListing& w = contact_nodes_.listing[static_cast<std::size_t>(t)];
    const EvenShare share(span_lo, span_hi, t, T);
    const int node_lo = static_cast<int>(share.lo), node_hi = static_cast<int>(share.hi);
    w.slot_begin.resize(nf), w.slot_end.resize(nf), w.field_end.resize(nf);
    w.entries.assign(nf, 0), w.groups.assign(nf, 0), w.entry_base.resize(nf), w.group_base.resize(nf);
    for (std::size_t f = 0; f < nf; ++f) {
      const int* b = layout_.slot_node.data() + fields_[f].first;
      const int* e = b + fields_[f].count;
      w.slot_begin[f] = static_cast<std::size_t>(std::lower_bound(b, e, node_lo) - layout_.slot_node.data());
      w.slot_end[f] = static_cast<std::size_t>(std::lower_bound(b, e, node_hi) - layout_.slot_node.data());
    }
    // 1. Reset this range's counts and cursors (over the range or slot by slot, whichever is shorter).
    if (reset_whole_range) {
      std::fill(contact_nodes_.node_field_count.begin() + node_lo, contact_nodes_.node_field_count.begin() + node_hi, 0);
      std::fill(contact_nodes_.node_entry_cursor.begin() + node_lo, contact_nodes_.node_entry_cursor.begin() + node_hi, -1);
    } else {
      for (std::size_t f = 0; f < nf; ++f)
        for (std::size_t s = w.slot_begin[f]; s < w.slot_end[f]; ++s) {
          const auto node = static_cast<std::size_t>(layout_.slot_node[s]);
          contact_nodes_.node_field_count[node] = 0;
          contact_nodes_.node_entry_cursor[node] = -1;
        }
    }
    w.occupied.clear();
    for (std::size_t f = 0; f < nf; ++f) {
      for (std::size_t s = w.slot_begin[f]; s < w.slot_end[f]; ++s)
        if (nodes_.mass[s] > mmin) {
          ++contact_nodes_.node_field_count[static_cast<std::size_t>(layout_.slot_node[s])];
          w.occupied.push_back(static_cast<int>(s));
        }
      w.field_end[f] = w.occupied.size();
    }
    // 2. Each contact node at its first field: its place in the block (encoded −2 − offset until the
    //    block's offset is known).
    for (std::size_t f = 0, o = 0; f < nf; ++f)
      for (; o < w.field_end[f]; ++o) {
        const auto node = static_cast<std::size_t>(layout_.slot_node[static_cast<std::size_t>(w.occupied[o])]);
        if (contact_nodes_.node_field_count[node] >= 2 && contact_nodes_.node_entry_cursor[node] == -1) {
          contact_nodes_.node_entry_cursor[node] = -2 - static_cast<int>(w.entries[f]);
          w.entries[f] += contact_nodes_.node_field_count[node];
          ++w.groups[f];
        }
      }
#pragma omp barrier
#pragma omp single
    {
      std::size_t entries = 0, groups = 0;
      for (std::size_t f = 0; f < nf; ++f)
        for (int u = 0; u < T; ++u) {
          ContactNodeListing& x = contact_nodes_.listing[static_cast<std::size_t>(u)];
          x.entry_base[f] = entries, x.group_base[f] = groups;
          entries += x.entries[f], groups += x.groups[f];
        }
      contact_nodes_.entries.resize(entries);
      contact_nodes_.groups.resize(groups + 1);
      contact_nodes_.groups[groups] = entries;  // the end of the last node's run
    }  // (implicit barrier)
    // 3. The runs, in field order within each node; a node's group starts where its run does.
    for (std::size_t f = 0, o = 0; f < nf; ++f) {
      std::size_t group = w.group_base[f];
      for (; o < w.field_end[f]; ++o) {
        const int s = w.occupied[o];
        const int node = layout_.slot_node[static_cast<std::size_t>(s)];
        if (contact_nodes_.node_field_count[static_cast<std::size_t>(node)] < 2) continue;
        int& cursor = contact_nodes_.node_entry_cursor[static_cast<std::size_t>(node)];
        if (cursor <= -2) {
          cursor = static_cast<int>(w.entry_base[f]) + (-2 - cursor);
          contact_nodes_.groups[group++] = static_cast<std::size_t>(cursor);
        }
        contact_nodes_.entries[static_cast<std::size_t>(cursor++)] = {node, s, static_cast<int>(f)};
      }
    }
  });
}

template void Simulation<2>::find_contact_nodes();
template void Simulation<3>::find_contact_nodes();

}  // namespace frictherm::mechanics
