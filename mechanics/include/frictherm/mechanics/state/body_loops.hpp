#pragma once
// The boundary loops of the bodies of a Simulation<Dim> (penalty contact; simulation_setup.cpp,
// simulation_penalty.cpp): where the boundary material points are sampled.
#include <frictherm/mechanics/types.hpp>

#include <vector>

namespace frictherm::mechanics {

/// Per body: its boundary loops (from its region, or set_body_boundary), the spacing they were
/// sampled with (−1: given by the user), its material (−1: several), particle half-size and velocity.
template <int Dim>
struct BodyLoops {
  std::vector<std::vector<std::vector<Vec<2>>>> loops;
  std::vector<double> spacing;
  std::vector<int> material;
  std::vector<Vec<Dim>> half_size, velocity;
};

}  // namespace frictherm::mechanics
