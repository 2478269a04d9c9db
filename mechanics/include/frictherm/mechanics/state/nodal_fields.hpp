#pragma once
// The nodal fields of a Simulation<Dim> and the velocity fields whose slots they hold.
#include <frictherm/mechanics/shape_functions.hpp>  // NodeIndexer
#include <frictherm/mechanics/types.hpp>

#include <cstddef>
#include <vector>

namespace frictherm::mechanics {

/// Nodal fields, one entry per slot: a grid node of one velocity field (without contact the single
/// field covers the whole grid and slot = node index).
template <int Dim>
struct NodalFields {
  std::vector<double> mass;
  std::vector<Vec<Dim>> momentum;
  std::vector<Vec<Dim>> force;
  std::vector<Vec<Dim>> velocity;      // v_i^{n+1} after the momentum update
  std::vector<Vec<Dim>> acceleration;  // (p^{n+1} - p^n) / (m dt), boundary conditions applied
  // Contact only (empty otherwise): Σ S m x (or Σ S m (x − x0)), Ω = Σ S V, g = Σ G V (eqs. 4–6, 9).
  std::vector<Vec<Dim>> mass_position;
  std::vector<double> domain;
  std::vector<Vec<Dim>> domain_gradient;
  void resize(std::size_t n, bool with_contact = false);
  /// To n slots without clearing the ones kept (a layout change of the step: the step's scatter
  /// clears every slot of a field before adding to it and nodal_velocities sets every velocity and
  /// acceleration, so no slot is read before it is written).
  void resize_slots(std::size_t n, bool with_contact);
};

/// One velocity field: the nodes of a box of the grid, stored in slots first .. first + count − 1.
template <int Dim>
struct VelocityField {
  int material = -1;          // -1: the shared field of all deformable materials (no contact)
  bool rigid = false;
  IVec<Dim> lo{};             // first node of the box (lattice counted from the first ghost node)
  IVec<Dim> extent{};         // nodes per direction
  std::size_t first = 0, count = 0;
  NodeIndexer<Dim> index;     // lattice -> slot
};

}  // namespace frictherm::mechanics
