#pragma once
// Boundary conditions and loads of a simulation, described at set-up and resolved to nodes or
// particles when the simulation is finalized.
#include <frictherm/mechanics/time_function.hpp>
#include <frictherm/mechanics/types.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace frictherm::mechanics {

/// Nodes on a face of the grid (and the ghost nodes beyond it) with some velocity components fixed to 0.
struct FixedFace {
  int axis = 0;        // 0 = x, 1 = y, 2 = z
  bool upper = false;  // false: the face at lo[axis]; true: the face at hi[axis]
  std::array<bool, 3> components{{true, true, true}};
};

/// A force (N) on the particle of `body` nearest to `point`, or shared equally by every particle of
/// `body` inside [box_lo, box_hi] when use_box is set; scaled by `scale(t)`.
template <int Dim>
struct PointLoad {
  int body = -1;  // -1: any body
  Vec<Dim> point = Vec<Dim>::Zero();
  bool use_box = false;
  Vec<Dim> box_lo = Vec<Dim>::Zero(), box_hi = Vec<Dim>::Zero();
  Vec<Dim> force = Vec<Dim>::Zero();
  TimeFunction scale = TimeFunction::constant(1.0);
};

/// A traction (Pa) on the face of `body` normal to `axis` (its outer particle layer on the `upper`
/// or lower side); each particle of the layer receives traction times its face area; scaled by `scale(t)`.
template <int Dim>
struct EdgeTraction {
  int body = 0;
  int axis = 0;
  bool upper = true;
  Vec<Dim> traction = Vec<Dim>::Zero();
  TimeFunction scale = TimeFunction::constant(1.0);
};

/// A point load or a traction resolved to one particle (Simulation::particle_loads, the decomposed
/// run's DecomposedMpm::Options::loads): the force (N) at scale 1 on the particle with index
/// `particle` in the finalized Simulation (the decomposed run's particle id), scaled by `scale(t)`;
/// `source` is the load it comes from: i for the i-th point load, (point loads) + j for the j-th traction.
template <int Dim>
struct ParticleLoad {
  std::int64_t particle = 0;
  int source = 0;
  Vec<Dim> force = Vec<Dim>::Zero();
  TimeFunction scale = TimeFunction::constant(1.0);
};

}  // namespace frictherm::mechanics
