// The checks of a checkpoint's arrays before any state is restored (checkpoint_checks.hpp).
#include "run/checkpoint_checks.hpp"

#include "output/h5_util.hpp"

#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace frictherm::coupling::ckpt {

namespace {

using h5detail::check;
using h5detail::check_id;
using h5detail::Handle;

// Items (first dimension) of dataset `name`, or -1 when the checkpoint has none of that name.
long items(hid_t f, const std::string& path, const std::string& name) {
  if (H5Lexists(f, name.substr(0, name.find('/')).c_str(), H5P_DEFAULT) <= 0) return -1;
  if (name.find('/') != std::string::npos && H5Lexists(f, name.c_str(), H5P_DEFAULT) <= 0) return -1;
  const Handle d{check_id(H5Dopen2(f, name.c_str(), H5P_DEFAULT), path, "cannot open '/" + name + "'"), H5Dclose};
  const Handle space{check_id(H5Dget_space(d.get()), path, "dataspace of '/" + name + "'"), H5Sclose};
  hsize_t dims[2] = {0, 0};
  if (H5Sget_simple_extent_ndims(space.get()) < 1) return 0;
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  return static_cast<long>(dims[0]);
}

// Every value of the double dataset `name` (when present) is finite; else the first item that is not.
void require_finite(hid_t f, const std::string& path, const std::string& name) {
  if (items(f, path, name) <= 0) return;
  const Handle d{check_id(H5Dopen2(f, name.c_str(), H5P_DEFAULT), path, "cannot open '/" + name + "'"), H5Dclose};
  const Handle type{check_id(H5Dget_type(d.get()), path, "type of '/" + name + "'"), H5Tclose};
  if (H5Tget_class(type.get()) != H5T_FLOAT) return;
  const Handle space{check_id(H5Dget_space(d.get()), path, "dataspace of '/" + name + "'"), H5Sclose};
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  std::vector<double> v(static_cast<std::size_t>(n));
  check(H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path, "cannot read '/" + name + "'");
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw std::runtime_error("checkpoint '" + path + "': /" + name + " holds a non-finite value (" +
                               std::to_string(v[i]) + " at value " + std::to_string(i) + "); the checkpoint is damaged");
}

// Every value of the integer dataset `name` (when present), converted to long.
std::vector<long> longs(hid_t f, const std::string& path, const std::string& name) {
  const long n = items(f, path, name);
  if (n <= 0) return {};
  const Handle d{check_id(H5Dopen2(f, name.c_str(), H5P_DEFAULT), path, "cannot open '/" + name + "'"), H5Dclose};
  const Handle space{check_id(H5Dget_space(d.get()), path, "dataspace of '/" + name + "'"), H5Sclose};
  std::vector<long> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.get())));
  check(H5Dread(d.get(), H5T_NATIVE_LONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path, "cannot read '/" + name + "'");
  return v;
}

// Every value of the double dataset `name` (when present; its type was checked by the caller or is
// checked by the Reader after).
std::vector<double> doubles(hid_t f, const std::string& path, const std::string& name) {
  if (items(f, path, name) <= 0) return {};
  const Handle d{check_id(H5Dopen2(f, name.c_str(), H5P_DEFAULT), path, "cannot open '/" + name + "'"), H5Dclose};
  const Handle space{check_id(H5Dget_space(d.get()), path, "dataspace of '/" + name + "'"), H5Sclose};
  std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.get())));
  check(H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), path, "cannot read '/" + name + "'");
  return v;
}

[[noreturn]] void damaged(const std::string& path, const std::string& name, const std::string& what) {
  throw std::runtime_error("checkpoint '" + path + "': /" + name + " " + what +
                           "; the checkpoint is damaged or belongs to another scene");
}

// `name` (when present) holds `expected` items (or none, when `may_be_empty`).
void require(hid_t f, const std::string& path, const std::string& name, long expected, bool may_be_empty,
             const std::string& what) {
  const long n = items(f, path, name);
  if (n < 0 || n == expected || (may_be_empty && n == 0)) return;
  damaged(path, name, "holds " + std::to_string(n) + " items, expected " + std::to_string(expected) + " (" + what + ")");
}

// Every value of `name` (when present) in [lo, hi).
void in_range(hid_t f, const std::string& path, const std::string& name, long lo, long hi, const char* what) {
  const std::vector<long> v = longs(f, path, name);
  for (std::size_t i = 0; i < v.size(); ++i)
    if (v[i] < lo || v[i] >= hi)
      damaged(path, name, "holds " + std::to_string(v[i]) + " at item " + std::to_string(i) + ", expected " +
                              std::to_string(lo) + " to " + std::to_string(hi - 1) + " (" + what + ")");
}

// Points of `name` (when present) inside the grid's box [lo, hi] widened by `margin` cells per side
// (Grid::contains: a particle or boundary point outside has no stencil, the step refuses it as "left
// the grid"): a finite but absurd value, e.g. a flipped exponent, had crashed the thermal assembly of
// the restore (fuzz_checkpoint).
void inside_grid(hid_t f, const std::string& path, const std::string& name, const std::vector<double>& lo_box,
                 const std::vector<double>& hi_box, const std::vector<double>& cell, double margin) {
  const std::size_t dim = lo_box.size();
  const std::vector<double> x = doubles(f, path, name);
  for (std::size_t i = 0; dim > 0 && i + dim <= x.size(); i += dim)
    for (std::size_t d = 0; d < dim; ++d) {
      const double lo = lo_box[d] - margin * cell[d], hi = hi_box[d] + margin * cell[d];
      if (!(x[i + d] >= lo && x[i + d] <= hi))
        damaged(path, name, "holds a point outside the grid (" + std::to_string(x[i + d]) + " m in direction " +
                                std::to_string(d) + " at item " + std::to_string(i / dim) + ", expected " +
                                std::to_string(lo) + " to " + std::to_string(hi) + " m)");
    }
}

// Half sizes of `name` within [0, max_half] (the stencil of a particle inside finds all its nodes
// only then; max_half is h/2 or the largest the scene built).
void half_sizes(hid_t f, const std::string& path, const std::string& name, const std::vector<double>& max_half) {
  const std::size_t dim = max_half.size();
  const std::vector<double> l = doubles(f, path, name);
  for (std::size_t i = 0; dim > 0 && i + dim <= l.size(); i += dim)
    for (std::size_t d = 0; d < dim; ++d)
      if (!(l[i + d] >= 0.0 && l[i + d] <= max_half[d] * (1.0 + 1e-12)))
        damaged(path, name, "holds " + std::to_string(l[i + d]) + " m at item " + std::to_string(i / dim) +
                                ", expected 0 to " + std::to_string(max_half[d]) + " m (half the cell size)");
}

// -inf in the wave speeds `speeds` (never a CFL speed) only for particles of rigid materials.
void rigid_wave_speeds(hid_t f, const std::string& path, const std::string& speeds, const std::string& materials,
                       const std::vector<bool>& rigid) {
  const long P = items(f, path, materials);
  if (P <= 0 || items(f, path, speeds) != P) return;
  const std::vector<long> material = longs(f, path, materials);
  const std::vector<double> c = doubles(f, path, speeds);
  const long M = static_cast<long>(rigid.size());
  for (std::size_t i = 0; i < c.size() && i < material.size(); ++i)
    if (c[i] == -std::numeric_limits<double>::infinity() && material[i] >= 0 && material[i] < M &&
        !rigid[static_cast<std::size_t>(material[i])])
      damaged(path, speeds, "holds -inf (a rigid particle's) at particle " + std::to_string(i) + " of a deformable material");
}

// Counters: never negative.
void counts(hid_t f, const std::string& path, std::initializer_list<const char*> names) {
  for (const char* a : names) in_range(f, path, a, 0, std::numeric_limits<long>::max(), "a count");
}

}  // namespace

// The arrays' sizes against the simulation built from the scene, the index arrays' values against
// what they index, the counters' signs and the values the next step reads for finiteness, before
// any state is restored (issue 34: truncated, padded or NaN arrays had been accepted). Arrays a run
// fills with its first step may be empty only in a checkpoint of step 0. The Reader then checks every
// dataset's shape and type and every double's finiteness as it restores it.
void check_arrays(hid_t f, const std::string& path, const SceneSizes& z) {
  const long P = z.particles, G = z.nodes, M = z.materials, B = z.boundary_points;
  const auto step_values = longs(f, path, "mechanics/step");
  const long step = step_values.size() == 1 ? step_values[0] : -1;
  const bool first = step == 0;  // before the first step: the step's arrays are not filled yet
  auto damaged = [&](const std::string& name, const std::string& what) { ckpt::damaged(path, name, what); };
  auto require = [&](const std::string& name, long expected, bool may_be_empty, const char* what) {
    ckpt::require(f, path, name, expected, may_be_empty, what);
  };
  auto in_range = [&](const std::string& name, long lo, long hi, const char* what) {
    ckpt::in_range(f, path, name, lo, hi, what);
  };
  static const char* const kParticleArrays[] = {
      "position", "initial_position", "velocity", "half_size", "mass", "initial_volume", "volume",
      "deformation_gradient", "stress", "stress_zz", "temperature", "plastic_strain", "internal_energy",
      "plastic_work", "material", "body"};
  for (const char* a : kParticleArrays) {
    const std::string name = std::string("mechanics/particles/") + a;
    require(name, P, false, "the scene's particles");
    require_finite(f, path, name);
  }
  // Positions inside the grid (boundary points may lie on its edge: the ghost layer of one cell, as
  // the step allows) and half sizes within the cell.
  inside_grid(f, path, "mechanics/particles/position", z.lo, z.hi, z.cell, 0.0);
  inside_grid(f, path, "mechanics/boundary/position", z.lo, z.hi, z.cell, 1.0);
  half_sizes(f, path, "mechanics/particles/half_size", z.max_half);
  in_range("mechanics/particles/material", 0, M, "the scene's materials");
  in_range("mechanics/particles/body", 0, z.bodies, "the scene's bodies");
  rigid_wave_speeds(f, path, "mechanics/wave_speed", "mechanics/particles/material", z.rigid);
  const std::vector<long> ready = longs(f, path, "mechanics/wave_speed_ready");
  require("mechanics/wave_speed", P, first || (ready.size() == 1 && ready[0] == 0), "the scene's particles");
  for (const char* a : {"mechanics/work_first", "mechanics/work_second", "mechanics/contact/lagged_normal_traction",
                        "mechanics/contact/lagged_normal_step", "pending/work", "system/unknown"})
    require(a, G, first, "the scene's grid nodes");
  for (const char* a : {"mechanics/pair_work_first", "mechanics/pair_work_second"})
    require(a, z.contact ? M * M : 0, first, "material pairs of the scene");
  for (const char* a : {"hotspots/owner", "hotspots/reference"}) require(a, P, first, "the scene's particles");
  // λ_p of every particle when the loading had a reaction (/reaction/enabled), else empty (frictherm
  // continue with a new reaction starts from λ = 0): an emptied progress had restarted the reaction.
  if (const std::vector<long> reacting = longs(f, path, "reaction/enabled"); reacting.size() == 1) {
    if (reacting[0] == 1) require("reaction/particle_progress", P, false, "the scene's particles: /reaction/enabled is 1");
    if (reacting[0] == 0 && items(f, path, "reaction/particle_progress") > 0)
      damaged("reaction/particle_progress", "holds " + std::to_string(items(f, path, "reaction/particle_progress")) +
                                                " items, expected none (/reaction/enabled is 0: the loading had no reaction)");
  }
  require("hotspots/options", 4, false, "mode, threshold, link factor, minimum particles");
  // Penalty contact: the boundary points sampled on the scene's shapes, a slip history per pair.
  for (const char* a : {"mechanics/boundary/position", "mechanics/boundary/velocity"})
    require(a, B, false, "the scene's penalty boundary points");
  const std::vector<long> call = longs(f, path, "mechanics/penalty/stamp");
  for (long k = 0; k < z.penalty_pairs; ++k) {
    const std::string p = "mechanics/penalty/pair" + std::to_string(k) + "/";
    for (const char* a : {"segment", "beta", "length", "traction", "stamp"})
      require(p + a, B, false, "the scene's penalty boundary points");
    require(p + "books", 8, false, "a penalty pair's books");
    in_range(p + "segment", -1, B, "-1 or a boundary segment");
    if (call.size() == 1) in_range(p + "stamp", 0, call[0] + 1, "at most /mechanics/penalty/stamp, the call counter");
  }
  require("mechanics/penalty/stamp", 1, false, "the call counter");
  if (const long r = items(f, path, "mechanics/penalty/records"); r > 0 && r % 17 != 0)
    damaged("mechanics/penalty/records", "holds " + std::to_string(r) + " values, expected 17 per contact record");
  // Hot spots: their particles and materials, the owners' ids.
  in_range("hotspots/current_particles", 0, P, "the scene's particles");
  in_range("hotspots/current_materials", 0, M, "the scene's materials");
  const std::vector<long> next_id = longs(f, path, "hotspots/next_id");
  if (next_id.size() == 1) in_range("hotspots/owner", -1, next_id[0], "-1 or a hot-spot id below /hotspots/next_id");
  // The thermal unknowns: as many temperatures and masses as grid nodes listed, at most G.
  const long unknowns = items(f, path, "system/grid_node");
  if (unknowns > G)
    damaged("system/grid_node", "holds " + std::to_string(unknowns) + " items, expected at most " + std::to_string(G) +
                                    " (the scene's grid nodes)");
  if (unknowns >= 0) {
    require("nodal_temperature", unknowns, false, "the thermal unknowns listed in /system/grid_node");
    require("system/mass", unknowns, false, "the thermal unknowns listed in /system/grid_node");
    in_range("system/grid_node", 0, G, "the scene's grid nodes");
    in_range("system/unknown", -1, unknowns, "-1 or a thermal unknown listed in /system/grid_node");
  }
  // Counters: never negative; the steps of the last row and snapshot (-1: none) not after the step.
  counts(f, path, {"mechanics/step", "mechanics/contact_stats/contact_nodes", "mechanics/contact_stats/multi_nodes",
                   "mechanics/contact_stats/sliding_nodes", "mechanics/contact_stats/guarded",
                   "mechanics/contact_stats/penalty_contacts", "mechanics/contact_stats/penalty_sliding",
                   "hotspots/next_id", "window_steps", "books/windows", "books/continuation_intervals", "books/steps",
                   "integrator/steps", "integrator/rhs_evals", "integrator/jac_evals", "integrator/nonlinear_iters",
                   "integrator/linear_iters", "integrator/error_test_failures", "integrator/convergence_failures",
                   "integrator/reinits"});
  if (step >= 0)
    for (const char* a : {"run/last_series_step", "run/last_snapshot_step"})
      in_range(a, -1, step + 1, "-1 or a step up to /mechanics/step");
  in_range("run/hotspot_windows_written", -1, std::numeric_limits<long>::max(), "-1 or a count of windows");
  // The series' memory of the last row: the cumulative frictional work, total and per contact pair.
  const std::vector<long> has_previous = longs(f, path, "run/series_memory/has_previous");
  require("run/series_memory/work", 1 + z.series_pairs, has_previous.size() == 1 && has_previous[0] == 0,
          "the total and each contact pair's frictional work");
  // The marks describe this state.
  const std::vector<long> mark_step = longs(f, path, "marks/step");
  if (step >= 0 && mark_step.size() == 1 && mark_step[0] != step)
    damaged("marks/step", "holds step " + std::to_string(mark_step[0]) + ", /mechanics/step " + std::to_string(step));
  for (const char* a : {"mechanics/time", "mechanics/last_dt", "mechanics/work_first", "mechanics/work_second",
                        "mechanics/pair_work_first", "mechanics/pair_work_second", "nodal_temperature", "system/mass",
                        "pending/work", "window_start"})
    require_finite(f, path, a);
  if (!first) require_finite(f, path, "mechanics/initial_energy");  // NaN only before the first step
  const std::vector<long> windows = longs(f, path, "books/windows");
  if (windows.size() == 1 && windows[0] > 0) require_finite(f, path, "books/min_window");  // +inf: no window yet
}

// A decomposed run's rank file, with the serial checks above (issue 34: the rank files had their types
// and shapes checked, not their values). Names as DecomposedMpm::checkpoint_state and
// DecomposedHeat::visit_state write them; the Reader then checks every double's finiteness.
void check_rank_file(hid_t f, const std::string& path, const RankSizes& z) {
  const std::size_t dim = z.nodes.size();
  // The owned node range [begin, end) per direction inside the DMDA's nodes; its node count O.
  const std::vector<long> box = longs(f, path, "mechanics/owned_nodes");
  require(f, path, "mechanics/owned_nodes", static_cast<long>(2 * dim), false, "begin and end per direction");
  long owned = box.size() == 2 * dim ? 1 : -1;
  for (std::size_t d = 0; owned > 0 && d < dim; ++d) {
    if (!(box[2 * d] >= 0 && box[2 * d] < box[2 * d + 1] && box[2 * d + 1] <= z.nodes[d]))
      damaged(path, "mechanics/owned_nodes", "holds the range " + std::to_string(box[2 * d]) + " to " +
                                                 std::to_string(box[2 * d + 1]) + " in direction " + std::to_string(d) +
                                                 ", expected 0 <= begin < end <= " + std::to_string(z.nodes[d]) +
                                                 " (the grid's nodes)");
    owned *= box[2 * d + 1] - box[2 * d];
  }
  // Every swarm field: as many items as ids (the Reader checks the components per item).
  const long n = items(f, path, "mechanics/id");
  if (n < 0) damaged(path, "mechanics/id", "is missing");
  for (const auto& [field, components] : z.fields)  // stored flat: n × components values
    require(f, path, "mechanics/" + field, n * components, false,
            std::to_string(components) + " per particle of /mechanics/id");
  require(f, path, "mechanics/material", n, false, "the particles of /mechanics/id");
  in_range(f, path, "mechanics/id", 0, z.particles, "the scene's particle ids");
  in_range(f, path, "mechanics/material", 0, z.materials, "the scene's materials");
  inside_grid(f, path, "mechanics/coor", z.lo, z.hi, z.cell, 0.0);
  half_sizes(f, path, "mechanics/half_size", z.max_half);
  rigid_wave_speeds(f, path, "mechanics/wave_speed", "mechanics/material", z.rigid);
  for (const auto& [field, components] : z.fields)
    if (field != "wave_speed") require_finite(f, path, "mechanics/" + field);  // -inf: a rigid particle's
  for (const char* a : {"mechanics/time", "mechanics/work_first", "mechanics/work_second"}) require_finite(f, path, a);
  // The last step's work per owned node (empty before the first step with contact), 4 contact counters.
  for (const char* a : {"mechanics/work_first", "mechanics/work_second"})
    if (owned > 0) require(f, path, a, owned, true, "the nodes of /mechanics/owned_nodes");
  require(f, path, "mechanics/contact_stats", 4, false, "contact, multi-material, sliding and guarded nodes");
  counts(f, path, {"mechanics/contact_stats"});
  // The regularisation's lagged tractions per owned node (empty when it is off; NaN: no contact yet).
  for (const char* a : {"mechanics/contact/lagged_normal_traction", "mechanics/contact/lagged_normal_step"})
    if (owned > 0) require(f, path, a, owned, true, "the nodes of /mechanics/owned_nodes");
  require_finite(f, path, "mechanics/contact/lagged_normal_step");
  require(f, path, "mechanics/steps_taken", 1, false, "the steps taken");
  require_finite(f, path, "mechanics/steps_taken");
  // This rank's part of the frictional work per material pair (empty before any contact work).
  for (const char* a : {"mechanics/pair_work_first", "mechanics/pair_work_second"}) {
    require(f, path, a, z.materials * z.materials, true, "one per pair of the scene's materials");
    require_finite(f, path, a);
  }
  if (!z.heat) return;
  // The heat: pending work and the last gather per owned node, M_i on the ghosted box.
  for (const char* a : {"window/pending", "gather/M", "gather/T"}) {
    if (owned > 0) require(f, path, a, owned, std::string(a) != "window/pending", "the nodes of /mechanics/owned_nodes");
    require_finite(f, path, a);
  }
  if (z.ghosted_nodes >= 0) require(f, path, "gather/local_M", z.ghosted_nodes, true, "this rank's ghosted nodes");
  require_finite(f, path, "gather/local_M");
  counts(f, path, {"books/windows", "books/substeps", "books/assembled_windows", "books/steps", "books/dropped_nodes",
                   "books/exchanges", "window/steps"});
}

// A decomposed run's global file: the run loop's counters and steps, the series rows a whole number
// of rows, the marks of this state (as check_arrays for the serial run's).
void check_global_file(hid_t f, const std::string& path) {
  counts(f, path, {"run/step", "run/snapshots", "output/series_columns"});
  for (const char* a : {"run/series_memory/time", "run/series_memory/work"}) require_finite(f, path, a);
  const std::vector<long> step = longs(f, path, "run/step");
  if (step.size() == 1) {
    for (const char* a : {"run/last_series_step", "run/last_snapshot_step"})
      in_range(f, path, a, -1, step[0] + 1, "-1 or a step up to /run/step");
    const std::vector<long> mark_step = longs(f, path, "marks/step");
    if (mark_step.size() == 1 && mark_step[0] != step[0])
      damaged(path, "marks/step", "holds step " + std::to_string(mark_step[0]) + ", /run/step " + std::to_string(step[0]));
  }
  const std::vector<long> columns = longs(f, path, "output/series_columns");
  const long rows = items(f, path, "output/series_rows");
  if (columns.size() == 1 && columns[0] > 0 && rows > 0 && rows % columns[0] != 0)
    damaged(path, "output/series_rows", "holds " + std::to_string(rows) + " values, not whole rows of " +
                                            std::to_string(columns[0]) + " columns (/output/series_columns)");
}

}  // namespace frictherm::coupling::ckpt
