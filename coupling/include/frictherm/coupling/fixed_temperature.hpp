#pragma once
// Fixed-temperature faces of the thermal grid (scene key thermal.fixed_temperature): which thermal
// unknowns they hold, written once for the serial Coupler (coupler.cpp: Dirichlet nodes of the
// assembled problem and of the matrix-free sub-steps) and the decomposed DecomposedHeat
// (decomposed_heat.cpp: the owned unknowns of each rank).
#include <cstddef>
#include <vector>

namespace frictherm::coupling {

/// A grid face held at a fixed temperature: every thermal unknown on it is a Dirichlet node.
struct FixedTemperatureFace {
  int axis = 0;
  bool upper = false;
  double temperature = 293.15;  // K
};

/// The nodes the faces hold among `count` nodes: node u lies on a face when its lattice index along
/// the face's axis (`lattice_along(u, axis)`, 0 at the grid's lower bound) is 0 for a lower face or
/// cells[axis] for an upper one. Calls emit(u, T) face by face in the faces' order, nodes in order
/// within a face: a node on two faces (an edge or a corner) is emitted for each, and the later face's
/// temperature holds where the caller overwrites in this order (Problem::set_dirichlet, the sub-steps'
/// reset, a per-node table).
template <class Cells, class LatticeAlong, class Emit>
void for_each_fixed_node(const std::vector<FixedTemperatureFace>& faces, const Cells& cells, std::size_t count,
                         LatticeAlong&& lattice_along, Emit&& emit) {
  for (const FixedTemperatureFace& f : faces) {
    const int face_index = f.upper ? static_cast<int>(cells[static_cast<std::size_t>(f.axis)]) : 0;
    for (std::size_t u = 0; u < count; ++u)
      if (lattice_along(u, f.axis) == face_index) emit(u, f.temperature);
  }
}

}  // namespace frictherm::coupling
