#pragma once
// What a scene will cost, estimated from the parsed scene before anything large is allocated
// (issue 15): particles, grid nodes, peak memory, the first time step, steps and snapshots.
// parse_scene refuses a scene beyond the limits (SceneError naming the key path and the numbers);
// `frictherm validate` prints the estimate (docs/scenes.md, "Cost limits").
#include <string>

namespace frictherm::coupling {

struct Scene;

/// Limits on a scene's cost. Memory: run.max_memory (bytes), default kDefaultMemoryFraction of the
/// machine's MemAvailable (/proc/meminfo; 8 GiB when that cannot be read).
constexpr double kDefaultMemoryFraction = 0.75;
constexpr double kMaxStepCount = 1e9;        // without run.max_steps; with it, max_steps bounds the run
constexpr double kMaxSnapshotCount = 1e5;    // snapshots (each one also ends a step)

struct SceneCost {
  double particles = 0.0;      // upper bound: each body's bounding box filled at particles_per_cell
  double grid_nodes = 0.0;     // the dense background grid, (cells + 1)^dim
  double boundary_points = 0.0;  // 2D: the bodies' outlines sampled at contact.boundary_spacing (an upper bound)
  int threads = 1;             // threads the estimate assumes (per-thread nodal scatter buffers)
  double memory_bytes = 0.0;   // estimated peak resident memory
  double memory_limit = 0.0;   // bytes
  std::string memory_limit_source;  // "run.max_memory" or "75% of MemAvailable"
  double time_step = 0.0;      // first stable time step (s; infinite when nothing moves or waves)
  double wave_speed = 0.0;     // fastest signal at t = 0 (m/s): wave speed plus speed
  std::string time_step_key;   // the key path that sets time_step (e.g. materials.steel, bodies[1].velocity)
  double steps = 0.0;          // to end_time (or run.max_steps), at least one per snapshot
  double snapshots = 0.0;
  double output_bytes = 0.0;   // snapshot data in the HDF5 file
};

/// The machine's MemAvailable in bytes (/proc/meminfo), or 0 when unknown.
double available_memory_bytes();

/// The estimate; allocates nothing in proportion to the scene.
SceneCost estimate_scene_cost(const Scene& scene);

/// Throws SceneError (key path first) when the cost is beyond a limit or the first time step is not
/// positive and finite.
void check_scene_cost(const Scene& scene, const SceneCost& cost);

}  // namespace frictherm::coupling
