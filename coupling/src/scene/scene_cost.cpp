// Cost estimate of a scene before allocation (scene_cost.hpp).
//
// Memory model, fitted to the peak resident size of `frictherm run` (1 thread, 3 steps, /usr/bin/time)
// on this code: 2D 4.0e6 and 1.6e7 grid nodes with a few particles: 439 and 1699 MB (~106 B/node);
// 2D 6.4e5 and 2.56e6 particles on small grids: 257 and 894 MB (~350-395 B/particle); 3D 3.4e6
// nodes: 531 MB (~154 B/node); 3D 1.38e7 particles: 6.8 GB (~490 B/particle). The constants below
// round these up. Extra threads keep their own nodal scatter buffers (mass, momentum, force); a
// thermal section adds its nodal system (an allowance, not fitted).
#include <frictherm/coupling/scene.hpp>
#include <frictherm/coupling/scene_cost.hpp>
#include <frictherm/mechanics/time_step/cfl_time_step.hpp>
#include <frictherm/mechanics/thread_partition.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>

namespace frictherm::coupling {

namespace {

constexpr double kBaseBytes = 40e6;
// A grid above kMaxEmptyGridNodes nodes with more than kMaxNodesPerParticle nodes per particle is
// refused as mostly empty, unless run.max_memory is given (docs/scenes.md, "Cost limits").
constexpr double kMaxEmptyGridNodes = 1e7;
constexpr double kMaxNodesPerParticle = 100.0;
// 2D bodies' outlines are sampled at contact.boundary_spacing (penalty contact's boundary points):
// at most this many points, each with its position, normal and bookkeeping.
constexpr double kMaxBoundaryPoints = 1e7;
constexpr double kBytesPerBoundaryPoint = 64.0;
constexpr double kMinBoundarySpacingPerCell = 0.01;
double bytes_per_particle(int dim) { return dim == 2 ? 420.0 : 520.0; }
double bytes_per_node(int dim) { return dim == 2 ? 115.0 : 165.0; }
double thermal_bytes_per_node(int dim) { return dim == 2 ? 300.0 : 700.0; }
// Contact keeps dense materials x materials tables (Simulation: ContactSetup::pair_index 4 B,
// ContactBooks::pair_work_first and pair_work_second 8 B each; each contact thread's pair books
// 8 + 8 + 1 B): 50,000 materials asked for 50 GB and ended validate with std::bad_alloc (issue 34;
// 20,000 took 7.9 GB and 18 s).
constexpr double kPairBytes = 20.0, kPairBytesPerThread = 17.0;
double pair_table_bytes(const Scene& s, int threads) {
  if (!s.contact.enabled) return 0.0;
  const double n = static_cast<double>(s.materials.size());
  return n * n * (kPairBytes + threads * kPairBytesPerThread);
}

std::string bytes_text(double b) {
  if (b < 1e5) return format_number(b) + " bytes";  // run.max_memory: 1 is a byte, not "0 MB"
  if (b >= 1e9) return format_number(std::round(b / 1e8) / 10.0) + " GB";
  return format_number(std::round(b / 1e5) / 10.0) + " MB";
}

}  // namespace

double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double value = 0.0;
  std::string unit;
  while (in >> key >> value >> unit)
    if (key == "MemAvailable:") return value * 1024.0;
  return 0.0;
}

SceneCost estimate_scene_cost(const Scene& s) {
  SceneCost c;
  const int dim = s.dimension;
  // Particles: every body's bounding box filled at particles_per_cell per direction (an upper bound;
  // exact for boxes aligned with the cells).
  for (const BodySpec& b : s.bodies) {
    double n = 1.0;
    for (int d = 0; d < dim; ++d) {
      const double cells = std::max(0.0, (b.shape.box_hi[d] - b.shape.box_lo[d]) / s.cell_size[d]);
      n *= (std::ceil(cells) + 1.0) * b.particles_per_cell;
    }
    c.particles += n;
  }
  c.grid_nodes = 1.0;
  for (int d = 0; d < dim; ++d) c.grid_nodes *= static_cast<double>(s.cells[d]) + 1.0;
  // Boundary points (2D: every body's outline, as Simulation::add_body samples it): an outline is
  // counted as twice its bounding box's perimeter (an annulus has two loops), one point per spacing.
  if (dim == 2) {
    const double spacing = s.contact.options.boundary_point_spacing(std::min(s.cell_size[0], s.cell_size[1]));
    for (const BodySpec& b : s.bodies)
      c.boundary_points +=
          4.0 * ((b.shape.box_hi[0] - b.shape.box_lo[0]) + (b.shape.box_hi[1] - b.shape.box_lo[1])) / spacing + 2.0;
  }
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const int wanted = s.threads > 0 ? s.threads : static_cast<int>(hw);
  // (a bomb's particle count can exceed any integer; 1e15 particles already ask for the most threads)
  c.threads = mechanics::threads_for_particles(static_cast<std::size_t>(std::min(c.particles, 1e15)), wanted);
  c.memory_bytes = kBaseBytes + c.particles * bytes_per_particle(dim) + c.grid_nodes * bytes_per_node(dim) +
                   (c.threads - 1) * c.grid_nodes * 8.0 * (1 + 2 * dim) +
                   (s.thermal.enabled ? c.grid_nodes * thermal_bytes_per_node(dim) : 0.0) +
                   c.boundary_points * kBytesPerBoundaryPoint + pair_table_bytes(s, c.threads);
  if (s.max_memory > 0.0) {
    c.memory_limit = s.max_memory;
    c.memory_limit_source = "run.max_memory";
  } else {
    const double avail = available_memory_bytes();
    c.memory_limit = avail > 0.0 ? kDefaultMemoryFraction * avail : 8.0 * 1024 * 1024 * 1024;
    c.memory_limit_source = avail > 0.0 ? "75% of the machine's available memory" : "8 GiB (available memory unknown)";
  }

  // First time step, as Simulation::stable_time_step at t = 0: cfl h_min / (c + |v|), bounded by
  // solver.max_time_step and damping.
  double fastest_speed = 0.0, fastest_wave = 0.0;
  std::string speed_key, wave_key;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    double v2 = 0.0;
    for (int d = 0; d < dim; ++d) v2 += s.bodies[i].velocity[d] * s.bodies[i].velocity[d];
    if (!(std::sqrt(v2) <= fastest_speed)) {
      fastest_speed = std::sqrt(v2);
      speed_key = "bodies[" + std::to_string(i) + "].velocity";
    }
  }
  for (const mechanics::Material& m : s.materials) {
    double w = 0.0;
    if (m.is_rigid()) {
      double v2 = 0.0;
      for (const auto& f : m.rigid_velocity) v2 += f(0.0) * f(0.0);
      w = std::sqrt(v2);
    } else {
      w = mechanics::particle_wave_speed(m, s.options.analysis, /*J=*/1.0, /*e=*/0.0);
    }
    if (!(w <= fastest_wave)) {
      fastest_wave = w;
      wave_key = "materials." + m.name;
    }
  }
  c.wave_speed = fastest_wave + fastest_speed;
  double h = std::numeric_limits<double>::infinity();
  for (int d = 0; d < dim; ++d) h = std::min(h, s.cell_size[d]);
  c.time_step_key = fastest_speed > fastest_wave ? speed_key : wave_key;
  if (std::isnan(c.wave_speed)) return c.time_step = c.wave_speed, c;  // refused by check_scene_cost
  c.time_step = mechanics::cfl_time_step(s.options.cfl, h, c.wave_speed, std::numeric_limits<double>::infinity());
  if (!(s.options.max_time_step >= c.time_step)) {
    c.time_step = s.options.max_time_step;
    c.time_step_key = "solver.max_time_step";
  }
  if (s.options.damping_rate > 0.0 && mechanics::damping_time_step_limit(s.options.damping_rate) < c.time_step) {
    c.time_step = mechanics::damping_time_step_limit(s.options.damping_rate);
    c.time_step_key = "solver.damping.rate";
  }

  c.snapshots = std::ceil(s.end_time / s.output.snapshot_interval - 1e-9) + 1.0;
  c.steps = std::max(std::ceil(s.end_time / c.time_step), c.snapshots - 1.0);
  if (s.max_steps > 0) c.steps = std::min(c.steps, static_cast<double>(s.max_steps));
  c.output_bytes = std::min(c.snapshots, c.steps + 1.0) * c.particles * 8.0 *
                   static_cast<double>(3 * dim + dim * dim + 6);
  return c;
}

void check_scene_cost(const Scene& s, const SceneCost& c) {
  if (!(c.time_step > 0.0))  // 0 (an infinite wave speed or velocity) or NaN
    throw SceneError(c.time_step_key + ": the first time step would be " + format_number(c.time_step) +
                     " s (cfl x cell size / " + format_number(c.wave_speed) +
                     " m/s); expected a positive, finite time step (check densities, moduli and velocities)");
  if (c.snapshots > kMaxSnapshotCount)
    throw SceneError(std::string("output (snapshot_interval or snapshot_count)") + ": the run would write " + format_number(c.snapshots) + " snapshots (end_time " +
                     format_number(s.end_time) + " s / snapshot_interval " + format_number(s.output.snapshot_interval) +
                     " s); expected at most " + format_number(kMaxSnapshotCount));
  if (s.max_steps <= 0 && !(c.steps <= kMaxStepCount))
    throw SceneError("run.end_time: the run would take about " + format_number(c.steps) + " steps of " +
                     format_number(c.time_step) + " s (the first time step, set by " + c.time_step_key + ") to reach " +
                     format_number(s.end_time) + " s; expected at most " + format_number(kMaxStepCount) +
                     " steps: shorten run.end_time, or set run.max_steps to stop earlier");
  const double min_cell = *std::min_element(s.cell_size.begin(), s.cell_size.begin() + s.dimension);
  const double spacing = s.contact.options.boundary_spacing;
  if (spacing > 0.0 && spacing < kMinBoundarySpacingPerCell * min_cell * (1.0 - 1e-12))  // (1/100 itself accepted)
    throw SceneError("contact.boundary_spacing: expected 0 (half the cell size) or a spacing of at least " +
                     format_number(kMinBoundarySpacingPerCell * min_cell) + " m (1/100 of the cell size " +
                     format_number(min_cell) + " m: finer outlines add contact points faster than they add " +
                     "accuracy, and each costs every step), got " + format_number(spacing) + " m");
  if (!(c.boundary_points <= kMaxBoundaryPoints))
    throw SceneError("contact.boundary_spacing: the bodies' outlines would be sampled at about " +
                     format_number(c.boundary_points) + " boundary points (spacing " +
                     format_number(s.contact.options.boundary_spacing) + " m); expected at most " +
                     format_number(kMaxBoundaryPoints) + " (a spacing near half the cell size; 0 chooses it)");
  // A mostly empty dense grid (the mechanics grid is dense: every node costs memory and time each
  // step) is refused unless run.max_memory is given explicitly.
  if (s.max_memory <= 0.0 && c.grid_nodes > kMaxEmptyGridNodes && c.grid_nodes > kMaxNodesPerParticle * c.particles)
    throw SceneError("grid: " + format_number(c.grid_nodes) + " grid nodes for at most " + format_number(c.particles) +
                     " particles (about " + bytes_text(c.grid_nodes * bytes_per_node(s.dimension)) +
                     " of grid arrays, all visited every step); expected a grid around the bodies (at most " +
                     format_number(kMaxNodesPerParticle) + " nodes per particle above " + format_number(kMaxEmptyGridNodes) +
                     " nodes), or set run.max_memory (bytes) to accept it");
  if (!(c.memory_bytes <= c.memory_limit)) {
    // Blame the largest part: the materials' contact pair tables, the particles (the body with most of
    // them) or the grid.
    std::string key = "grid";
    const double particle_bytes = c.particles * bytes_per_particle(s.dimension);
    const double pair_bytes = pair_table_bytes(s, c.threads);
    if (pair_bytes > 0.5 * c.memory_bytes)
      throw SceneError("materials: " + std::to_string(s.materials.size()) + " materials in contact need about " +
                       bytes_text(pair_bytes) + " of materials x materials pair tables (of " + bytes_text(c.memory_bytes) +
                       " in all, " + std::to_string(c.threads) + (c.threads == 1 ? " thread" : " threads") + "); the limit is " + bytes_text(c.memory_limit) +
                       " (" + c.memory_limit_source + "); expected fewer materials (grains of one kind can share a " +
                       "material when friction between them is not needed), or a larger run.max_memory (bytes)");
    if (particle_bytes > c.grid_nodes * bytes_per_node(s.dimension)) {
      std::size_t worst = 0;
      double most = -1.0;
      for (std::size_t i = 0; i < s.bodies.size(); ++i) {
        double n = 1.0;
        for (int d = 0; d < s.dimension; ++d)
          n *= (std::ceil(std::max(0.0, (s.bodies[i].shape.box_hi[d] - s.bodies[i].shape.box_lo[d]) / s.cell_size[d])) + 1.0) *
               s.bodies[i].particles_per_cell;
        if (n > most) most = n, worst = i;
      }
      key = "bodies[" + std::to_string(worst) + "]";
    }
    throw SceneError(key + ": the scene needs about " + bytes_text(c.memory_bytes) + " of memory (" +
                     format_number(c.particles) + " particles, " + format_number(c.grid_nodes) + " grid nodes, " +
                     std::to_string(c.threads) + " threads); the limit is " + bytes_text(c.memory_limit) + " (" +
                     c.memory_limit_source + "); expected fewer particles or grid cells, or a larger run.max_memory (bytes)");
  }
}

}  // namespace frictherm::coupling
