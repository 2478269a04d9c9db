#pragma once
// The scene sections `thermal` and `coupling` (docs/scenes.md, docs/coupling.md):
//
//   "thermal":  {"integrator": "cvode_bdf", "rtol": 1e-6, "atol": 1e-3,
//                "materials": {"hmx": {"heat_capacity": 1500, "conductivity": 0.45}},
//                "fixed_temperature": [{"face": "x_min", "temperature": 300}],
//                "reaction": {"kinetics": "hmx_rogers1975", "materials": ["hmx"]}}
//   "coupling": {"window": {"policy": "adaptive", "max_temperature_rise": 0.5},
//                "heating_order": "second",
//                "continuation": {"duration": 1e-3, "intervals": 100},
//                "hotspots": {"mode": "rise", "threshold": 100},
//                "plastic_heating": true}
//
// Without a `thermal` section nothing thermal is computed; `coupling` needs `thermal`.
#include <frictherm/coupling/coupler.hpp>
#include <frictherm/coupling/json_reader.hpp>
#include <frictherm/mechanics/contact.hpp>
#include <frictherm/mechanics/material.hpp>

#include <string>
#include <vector>

namespace frictherm::coupling {

/// Frictional heating order (Nairn et al. 2018 eqs. 27 and 34/36): the order of the nodal work the
/// runner takes from Simulation::frictional_work.
using HeatingOrder = mechanics::HeatingOrder;

struct ThermalSceneSpec {
  bool enabled = false;        // the scene has a `thermal` section
  CouplerOptions coupler;      // properties, integrator, window policy, hot spots, fixed faces
  HeatingOrder heating_order = HeatingOrder::second;
  double continuation_duration = 0.0;  // s of thermal-only integration after the mechanics ends
  long continuation_intervals = 100;   // series rows (windows) over the continuation
  bool stop_when_decided = false;      // end the continuation once every hot spot has a fate
  bool reuse_distance_given = false;   // coupling.reuse_distance set by the scene (not its default)
  /// thermal.preconditioner: the PETSc preconditioner of a decomposed run's Krylov solve ("jacobi",
  /// "bjacobi", "hypre"; thermal::DistributedOptions). The serial run does not read it.
  std::string preconditioner = "jacobi";
};

/// Reads `thermal` and `coupling` from the scene root (both optional). `materials` are the scene's
/// materials (ids = positions), `thickness` the 2D thickness, `min_cell_size` the grid's smallest cell
/// edge (0: not known; the keys measured in cells are then checked when the run starts). Throws
/// SceneError naming the key path.
ThermalSceneSpec parse_thermal_sections(const JsonReader& root, int dimension,
                                        const std::vector<mechanics::Material>& materials, double thickness,
                                        double min_cell_size = 0.0);

const char* to_string(WindowPolicy::Kind kind);

}  // namespace frictherm::coupling
