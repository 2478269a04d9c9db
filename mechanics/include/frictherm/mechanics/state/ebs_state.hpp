#pragma once
// The extended B-spline bases of a Simulation<Dim> (Kakouris 2024 §3.3; simulation_ebs.cpp).
#include <frictherm/mechanics/ebs.hpp>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace frictherm::mechanics {

/// extended_bspline: the basis of each velocity field, rebuilt at the start of every step.
template <int Dim>
struct EbsState {
  std::vector<EbsBasis<Dim>> bases;                          // one per velocity field
  std::vector<std::pair<std::size_t, std::size_t>> ranges;   // rebuild scratch: a field's particle ranges
  std::vector<std::uint8_t> kept;                            // nodes never made degenerate (velocity conditions)
};

}  // namespace frictherm::mechanics
