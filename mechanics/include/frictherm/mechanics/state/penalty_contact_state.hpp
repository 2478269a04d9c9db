#pragma once
// Penalty contact of a Simulation<Dim> (Kakouris 2024; simulation_penalty.cpp): the boundary material
// points, the contact with its pairs and slip histories, and the per-field data the step refreshes.
#include <frictherm/mechanics/boundary_points.hpp>
#include <frictherm/mechanics/penalty_contact.hpp>

#include <optional>
#include <vector>

namespace frictherm::mechanics {

/// A material pair in penalty contact: master and slave materials, index into penalty_contact()'s pairs.
struct PenaltyPairInfo {
  int master_material = -1, slave_material = -1;
};

/// The boundary points and penalty pairs set up by finalize(), and the step's field boxes.
template <int Dim>
struct PenaltyContactState {
  BoundaryPoints<Dim> boundary;                 // boundary material points of the bodies in penalty pairs
  std::optional<PenaltyContact<Dim>> contact;   // none without penalty pairs
  std::vector<PenaltyPairInfo> pairs;           // pair k of contact
  std::vector<FieldNodes<Dim>> fields;          // the fields' node boxes, refreshed each step
  std::vector<double> reference_mass;           // per field: its mean particle mass (sliver test)
  // A boundary point leaves out a node of its field holding less than 0.25 S m_p (a sliver of the
  // body beside its edge, see simulation_penalty.cpp).
  static constexpr double sliver = 0.25;
};

}  // namespace frictherm::mechanics
