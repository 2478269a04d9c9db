// Extent separation (frictherm's contact detection; docs/contact.md, "Contact detection"): at each
// contact node, the gap between two materials is measured from their particles' domains instead of
// their nodal centres of mass (Nairn, Bardenhagen & Smith 2018 eq. 8). With n̂ the normal from
// material a to its partners (eq. 7, as resolve_contact computes it),
//   gap = min over the partners' particles of (x_p·n̂ − r_p)  −  max over a's particles of (x_p·n̂ + r_p),
// r_p = Σ_d l_{p,d} |n̂_d| the half-extent of particle p's domain (half-sizes l_p) along n̂, over the
// particles that give the node a weight; the same along each coordinate axis (signed towards the
// partners), and the detection takes the largest of these gaps (contact_extent.hpp extent_axis_gap:
// domains an axis separates are apart, whatever the normal). Touching flat surfaces have gap = 0 whatever their offset
// from the grid lines, so a material that reaches a node only as a sliver of its edge row is still
// seen in contact there, where the centre-of-mass test puts it ≈ 1.25 h away.
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/parallel_region.hpp>

#include "contact_extent.hpp"
#include "stencil_access.hpp"

#include <omp.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace frictherm::mechanics {

template <int Dim>
template <class Stencils>
void Simulation<Dim>::measure_contact_extents(const Stencils& st) {
  compute_contact_normals();
  const std::size_t entries = contact_nodes_.entries.size();
  constexpr std::size_t stride = contact_detail::kExtentDirections<Dim>;  // maxima per entry
  constexpr double none = -std::numeric_limits<double>::infinity();
  contact_nodes_.entry_extent_own.assign(stride * entries, none);
  contact_nodes_.entry_extent_other.assign(stride * entries, none);
  if (entries == 0) return;
  if (static_cast<int>(contact_nodes_.extent_thread.size()) < threads_.count - 1) contact_nodes_.extent_thread.resize(static_cast<std::size_t>(threads_.count - 1));
  // Per slot: 1 if its node has two or more fields with mass (the nodes add_particle_extent is
  // called for). A particle whose stencil reaches no such slot with S > 0 adds nothing and is passed
  // over after reading one byte per node (the same calls, in the same order, for the others).
  thread_local std::vector<std::uint8_t> at_contact;  // no allocation once grown
  at_contact.resize(nodes_.mass.size());
  for (std::size_t q = 0; q < at_contact.size(); ++q)
    at_contact[q] = contact_nodes_.node_field_count[static_cast<std::size_t>(layout_.slot_node[q])] >= 2;
  const std::uint8_t* const flag = at_contact.data();
  // The same test as one load per particle (issue 35, speed-s52): the flags dilated by the stencil's
  // box (stencil_access.hpp), read at its first slot, say whether any of its slots is flagged; the
  // S > 0 part of the test is left to the loop below, which skips S = 0 and single-field nodes
  // itself (a particle that passes only through S = 0 slots adds nothing there). EBS walks as before.
  constexpr bool boxed = !std::is_same_v<Stencils, PrecomputedStencils<Dim>>;
  thread_local std::vector<std::uint8_t> reach_flag, reach_tmp;
  if constexpr (boxed) step_detail::dilate_slot_flags_for(st, fields_, at_contact, reach_flag, reach_tmp);
  const std::uint8_t* const reach = reach_flag.data();
  // The extents are maxima, exact in any order: the same numbers on any number of threads. Boxed
  // stencils test one flag per particle and work on those reaching (threads_for_reach); EBS walks all.
  const int threads = boxed ? threads_for_reach(contact_nodes_.reach_share, p_.size(), threads_.count) : threads_.count;
  parallel_region(threads, [&] {
    const int tid = omp_get_thread_num();
    double* own = contact_nodes_.entry_extent_own.data();
    double* other = contact_nodes_.entry_extent_other.data();
    if (tid > 0) {
      std::vector<double>& buf = contact_nodes_.extent_thread[static_cast<std::size_t>(tid - 1)];
      buf.assign(2 * stride * entries, none);
      own = buf.data();
      other = buf.data() + stride * entries;
    }
    for (std::size_t m = 0; m < materials_.size(); ++m) {
      const int f = layout_.field_of_material[m];
      if (f < 0) continue;
      const NodeIndexer<Dim> ix = fields_[static_cast<std::size_t>(f)].index;
#pragma omp for schedule(static) nowait
      for (std::size_t k = layout_.material_begin[m]; k < layout_.material_end[m]; ++k) {
        if constexpr (boxed) {
          if (!reach[step_detail::first_slot(st[k], ix)]) continue;
        } else {
          int reaches = 0;
          st[k].for_each(ix, [&](int slot, double S, const Vec<Dim>&) { reaches |= flag[slot] & (S > 0.0); });
          if (!reaches) continue;
        }
        const Vec<Dim>& x = p_.position[k];
        const Vec<Dim>& l = p_.half_size[k];
        st[k].for_each(ix, [&](int slot, double S, const Vec<Dim>&) {
          if (!(S > 0.0)) return;
          const std::size_t node = static_cast<std::size_t>(layout_.slot_node[static_cast<std::size_t>(slot)]);
          const int c = contact_nodes_.node_field_count[node];
          if (c < 2) return;
          const int begin = contact_nodes_.node_entry_cursor[node] - c;  // the node's run (find_contact_nodes)
          const ContactEntry* run = contact_nodes_.entries.data() + begin;
          contact_detail::add_particle_extent<Dim>(x, l, f, c, [run](int j) { return run[j].field; },
                                                   contact_nodes_.entry_normal.data() + begin, own + stride * begin,
                                                   other + stride * begin);
        });
      }
    }
  });
  for (int t = 0; t + 1 < threads; ++t) {
    const std::vector<double>& buf = contact_nodes_.extent_thread[static_cast<std::size_t>(t)];
    for (std::size_t q = 0; q < stride * entries; ++q) {
      contact_nodes_.entry_extent_own[q] = std::max(contact_nodes_.entry_extent_own[q], buf[q]);
      contact_nodes_.entry_extent_other[q] = std::max(contact_nodes_.entry_extent_other[q], buf[stride * entries + q]);
    }
  }
}

#define FRICTHERM_INSTANTIATE_EXTENTS(D)                                                             \
  template void Simulation<D>::measure_contact_extents(const std::vector<Stencil<D, LinearKernel>>&); \
  template void Simulation<D>::measure_contact_extents(const std::vector<Stencil<D, UGIMPKernel>>&);  \
  template void Simulation<D>::measure_contact_extents(const std::vector<Stencil<D, QuadraticBSplineKernel>>&); \
  template void Simulation<D>::measure_contact_extents(const PrecomputedStencils<D>&);
FRICTHERM_INSTANTIATE_EXTENTS(2)
FRICTHERM_INSTANTIATE_EXTENTS(3)
#undef FRICTHERM_INSTANTIATE_EXTENTS

}  // namespace frictherm::mechanics
