#pragma once
// How a Simulation<Dim>'s materials map onto particles, velocity fields and grid nodes
// (simulation_fields.cpp): per material its particle range, field, node box and rigid motion.
#include <frictherm/mechanics/types.hpp>

#include <cstddef>
#include <vector>

namespace frictherm::mechanics {

/// A rigid material's prescribed motion over one step.
template <int Dim>
struct RigidBodyMotion {
  Vec<Dim> velocity, displacement;  // at t, and over [t, t + dt] (trapezoid)
  void move(Vec<Dim>& particle_velocity, Vec<Dim>& particle_position) const {
    particle_velocity = velocity;
    particle_position += displacement;
  }
};

/// The materials' particle ranges and velocity fields, and the slot → grid node map of the fields.
template <int Dim>
struct FieldLayout {
  std::vector<std::size_t> material_begin, material_end;  // particle ranges after finalize()
  std::vector<int> field_of_material;  // -1: rigid material acting through the rigid mask (no contact, or a boundary)
  std::vector<int> slot_node;
  bool slot_node_valid = false;        // slot_node matches the per-material layout of the fields (layout_fields)
  std::vector<Vec<Dim>> field_velocity;          // rigid fields: prescribed velocity at the step's start
  std::vector<RigidBodyMotion<Dim>> rigid_motion;  // per material, for particle_pass(refresh)
  std::vector<IVec<Dim>> box_lo, box_hi;         // per material: nodes reached by its particles (contact)
};

}  // namespace frictherm::mechanics
