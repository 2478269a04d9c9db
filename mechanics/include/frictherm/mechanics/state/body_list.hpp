#pragma once
// The bodies of a Simulation<Dim> and the fine lattice add_body fills them on (simulation_setup.cpp).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace frictherm::mechanics {

struct BodyInfo {
  std::string name;
  std::size_t particle_count = 0;
};

/// Every body added, and which points of the fill lattice (taken_ppc points per cell per direction)
/// an earlier body already took.
struct BodyList {
  std::vector<BodyInfo> info;
  std::vector<std::uint8_t> taken;  // fine lattice points already filled by a body
  int taken_ppc = 0;
};

}  // namespace frictherm::mechanics
