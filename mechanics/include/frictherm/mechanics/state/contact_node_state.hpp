#pragma once
// The multi-material contact nodes of a step (Simulation<Dim>; contact_nodes.cpp, contact_extents.cpp,
// simulation_contact.cpp): which fields have mass at each contact node, the extent separation's
// normals and extents, the per-thread work of a pass and the lagged normal traction.
#include <frictherm/mechanics/state/contact_books.hpp>  // ContactStats
#include <frictherm/mechanics/types.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frictherm::mechanics {

/// Contact nodes found by find_contact_nodes and the scratch of the passes that resolve them.
template <int Dim>
struct ContactNodeState {
  struct Entry {  // one field with mass at a multi-material node
    int node, slot, field;
  };
  // One thread's share of find_contact_nodes (a range of grid nodes), per field: its slots
  // [slot_begin, slot_end), the end of those with mass in `occupied`, the entries and nodes of the
  // contact nodes that first have mass in that field, and where they go in entries/groups.
  struct Listing {
    std::vector<int> occupied;
    std::vector<std::size_t> slot_begin, slot_end, field_end, entries, groups, entry_base, group_base;
  };
  struct ThreadWork {  // per-thread contact stats and pair books of one pass
    ContactStats stats;
    // Material pair k = min·nm + max: the pass's work, zero outside `touched` (the pairs it added
    // to, marked in `marked`), so a pass clears and sums only those, not all nm² pairs of a PBX.
    // Only the first thread's are summed into: the threads list their node groups' entries, and the
    // pass adds the lists in thread order, which is group order (resolve_contact).
    std::vector<double> pair_first, pair_second;
    std::vector<std::uint8_t> marked;
    std::vector<std::size_t> touched;
    struct PairEntry {
      std::size_t k;
      double w1, w2;
    };
    std::vector<PairEntry> entries;
    std::vector<double> rigid_work;  // Δp·v_rigid of each change a rigid partner made, in group order
    std::vector<double> normal_work;  // each node group's normal_stop_work (contact_pair.hpp), in group order
    void add(std::size_t k, double w1, double w2) {
      if (!marked[k]) marked[k] = 1, touched.push_back(k);
      pair_first[k] += w1;
      pair_second[k] += w2;
    }
  };

  std::vector<Entry> entries;           // grouped by node; within a node in material order
  std::vector<std::size_t> groups;      // start of each node's entries, then the end
  std::vector<Listing> listing;         // per thread
  std::vector<std::uint16_t> node_field_count;  // per grid node: fields with mass (find_contact_nodes)
  std::vector<int> node_entry_cursor;           // per grid node: next entry of its run, −1: none
  // Extent separation, per contact entry: the normal from its material to its partners, and the
  // largest extents of its own particle domains along it and of its partners' along its reverse, then
  // the same along each signed axis (contact_extent.hpp kExtentDirections values per entry).
  std::vector<Vec<Dim>> entry_normal;
  std::vector<double> entry_extent_own, entry_extent_other;
  std::vector<std::vector<double>> extent_thread;  // per-thread maxima (threads 1..n-1), own then other
  std::vector<ThreadWork> thread_work;             // per thread, of one pass
  // Per slot, the momentum change of this step's extrapolated contact pass (the energy books' start
  // of step: contact_pair.hpp normal_stop_work, energy_books.hpp condition_stop_work).
  std::vector<Vec<Dim>> extrapolated_change;
  // Normal-stress regularisation (ContactOptions::regularized): per grid node the lagged normal
  // traction σ̃ (Pa) of its two-material pair and the step that last updated it (a node that was not
  // in contact on the previous step starts again from σ).
  std::vector<double> lagged_normal_traction, lagged_normal_step;
  // The contact terms' scatter (simulation_step.cpp, issue 35): the share of the particles whose
  // stencil reached a contact node's slot on the last step, and whether map_to_grid scattered the
  // terms of every particle this step (when that share was over one half), so contact_at_extrapolated
  // does not scatter them again.
  double reach_share = 0.0;
  bool terms_scattered = false;
};

}  // namespace frictherm::mechanics
