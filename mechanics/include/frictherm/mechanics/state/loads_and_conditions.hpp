#pragma once
// The boundary conditions and loads of a Simulation<Dim> (simulation_setup.cpp, simulation_fields.cpp):
// as given, and resolved to grid-node masks and particle forces.
#include <frictherm/mechanics/loads.hpp>
#include <frictherm/mechanics/time_function.hpp>
#include <frictherm/mechanics/types.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frictherm::mechanics {

/// Fixed faces, rigid-driven nodes, point loads and edge tractions.
template <int Dim>
struct LoadsAndConditions {
  // Resolved loads: particle index, force at scale 1, and which TimeFunction scales it.
  struct ResolvedLoad {
    std::size_t particle;
    Vec<Dim> force;
    const TimeFunction* scale;
  };
  std::vector<std::uint8_t> fixed_mask;  // per grid node, bit d set: velocity component d fixed to 0
  std::vector<std::uint8_t> rigid_mask;  // per grid node, bit d set: velocity component d driven by a rigid material
  std::vector<Vec<Dim>> rigid_velocity;  // per grid node: the driving rigid material's velocity
  std::vector<FixedFace> faces;
  std::vector<PointLoad<Dim>> point_loads;
  std::vector<EdgeTraction<Dim>> tractions;
  std::vector<ResolvedLoad> resolved_loads;  // the point loads and tractions on particles (resolve_loads)
};

}  // namespace frictherm::mechanics
