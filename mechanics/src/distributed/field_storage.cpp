// Per-field storage of the decomposed step (frictherm/mechanics/distributed.hpp): each velocity
// field covers the box of local nodes its local particles' stencils reach, stored contiguously, as
// the serial Simulation::layout_fields lays out each material's field. A PBX grain's field is a few
// dozen nodes wherever the grain lies, so a rank stores Σ_f |box_f| slots (bounded by its particles'
// stencils for compact bodies) instead of fields × ghosted box.
#include "distributed/decomposed_state.hpp"

namespace frictherm::mechanics {

// Boxes from box_lo / box_hi (DMDA indices, filled by particle_to_grid), slot = first +
// Σ (node_d − lo_d) stride_d; slot_node maps each slot to its local node; the values are zeroed.
template <int Dim>
void DecomposedMpm<Dim>::Impl::layout_fields() {
  boxes.resize(static_cast<std::size_t>(fields));
  std::size_t total = 0;
  for (std::size_t f = 0; f < boxes.size(); ++f) {
    FieldBox& B = boxes[f];
    B.first = total;
    B.count = 0;
    if (box_lo[f][0] > box_hi[f][0]) {  // no local particle of this field
      B.extent = IVec<Dim>{};
      B.index = NodeIndexer<Dim>{};
      continue;
    }
    for (int d = 0; d < Dim; ++d) {
      B.lo[d] = box_lo[f][d];
      B.extent[d] = box_hi[f][d] - box_lo[f][d] + 1;
    }
    B.index = box_indexer<Dim>(B.lo, B.extent, total, B.count);
    total += B.count;
  }
  slot_node.resize(total);
  for (const FieldBox& B : boxes) {
    for (std::size_t s = 0; s < B.count; ++s) {
      std::size_t r = s;
      PetscInt ijk[3] = {0, 0, 0};
      for (int d = 0; d < Dim; ++d) {
        ijk[d] = B.lo[d] + static_cast<PetscInt>(r % static_cast<std::size_t>(B.extent[d]));
        r /= static_cast<std::size_t>(B.extent[d]);
      }
      slot_node[B.first + s] = local_node(ijk[0], ijk[1], ijk[2]);
    }
  }
  field_values.assign(total * static_cast<std::size_t>(per_field), 0.0);
  peak_slots = std::max(peak_slots, static_cast<long>(total));
}

template <int Dim>
long DecomposedMpm<Dim>::field_slots() const {
  return static_cast<long>(impl_->slot_node.size());
}
template <int Dim>
long DecomposedMpm<Dim>::peak_field_slots() const {
  return impl_->peak_slots;
}

#define FRICTHERM_INSTANTIATE_STORAGE(D)                     \
  template void DecomposedMpm<D>::Impl::layout_fields();     \
  template long DecomposedMpm<D>::field_slots() const;       \
  template long DecomposedMpm<D>::peak_field_slots() const;
FRICTHERM_INSTANTIATE_STORAGE(2)
FRICTHERM_INSTANTIATE_STORAGE(3)
#undef FRICTHERM_INSTANTIATE_STORAGE

}  // namespace frictherm::mechanics
