// The units and names of everything a run file holds (output_quantities.hpp). Energies are in J: in
// 2D the particle masses and volumes already carry the scene's thickness (docs/output.md).
#include <frictherm/coupling/output_quantities.hpp>

#include <map>

namespace frictherm::coupling {
namespace {

struct Entry {
  const char* units;
  const char* long_name;
};

// Series columns, table columns, snapshot fields and /meta keys by exact name. "area" is replaced by
// m^2 in 2D and m^3 in 3D (hot-spot sizes: area over the thickness in 2D, volume in 3D).
const std::map<std::string, Entry>& catalogue() {
  static const std::map<std::string, Entry> c{
      // series: mechanics (runner_output.cpp) and the energy balance (docs/output.md)
      {"time", {"s", "time"}},
      {"step", {"1", "mechanics step"}},
      {"dt", {"s", "time step"}},
      {"kinetic_energy", {"J", "kinetic energy"}},
      {"strain_energy", {"J", "stored (strain) energy"}},
      {"total_energy", {"J", "kinetic plus stored energy"}},
      {"external_work", {"J", "work of loads and gravity"}},
      {"momentum_x", {"kg m/s", "linear momentum x"}},
      {"momentum_y", {"kg m/s", "linear momentum y"}},
      {"momentum_z", {"kg m/s", "linear momentum z"}},
      {"rigid_work", {"J", "work of rigid materials"}},
      {"damping_work", {"J", "work removed by damping"}},
      {"plastic_dissipation", {"J", "plastic work"}},
      {"energy_lost", {"J", "mechanical energy lost"}},
      {"numerical_dissipation", {"J", "numerical dissipation"}},
      {"contact_normal_work", {"J", "energy removed by the normal contact impulses"}},
      {"boundary_stop_work", {"J", "energy removed by the velocity conditions' stops"}},
      {"stored_energy_lead", {"J", "stored energy's half-step lead over the kinetic energy (taken off in energy_lost)"}},
      {"mean_temperature", {"K", "mean temperature"}},
      {"mean_displacement_x", {"m", "mean displacement x"}},
      {"mean_displacement_y", {"m", "mean displacement y"}},
      {"mean_displacement_z", {"m", "mean displacement z"}},
      {"mean_velocity_x", {"m/s", "mean velocity x"}},
      {"mean_velocity_y", {"m/s", "mean velocity y"}},
      {"mean_velocity_z", {"m/s", "mean velocity z"}},
      // contact
      {"friction_work_first", {"J", "frictional work (first order)"}},
      {"friction_work_second", {"J", "frictional work (second order)"}},
      {"contact_nodes", {"1", "nodes in contact"}},
      {"sliding_nodes", {"1", "nodes sliding"}},
      {"contact_heat_rate", {"W", "frictional heating rate"}},
      {"penalty_energy", {"J", "penalty spring energy"}},
      {"penalty_force", {"N", "penalty normal force"}},
      {"penalty_contacts", {"1", "active penalty contacts"}},
      {"penalty_min_gap", {"m", "deepest penalty gap"}},
      {"penalty_contact_length", {"m", "penetrated master segment length"}},
      // heat (runner_thermal.cpp)
      {"heat_delivered", {"J", "heat delivered to the particles"}},
      {"thermal_energy_change", {"J", "thermal energy change of the particles"}},
      {"max_temperature", {"K", "maximum particle temperature"}},
      {"hotspot_count", {"1", "hot spots"}},
      {"hottest_hotspot_temperature", {"K", "peak temperature of the hottest hot spot"}},
      {"hottest_hotspot_size", {"area", "size of the hottest hot spot"}},
      {"hottest_hotspot_diameter", {"m", "equivalent diameter of the hottest hot spot"}},
      {"thermal_windows", {"1", "coupling windows"}},
      {"plastic_work", {"J", "plastic work handed to the heat"}},
      {"plastic_heat", {"J", "plastic heat"}},
      {"reaction_heat", {"J", "reaction heat released"}},
      {"max_reaction_progress", {"1", "maximum reaction progress"}},
      {"max_interface_temperature", {"K", "maximum interface temperature"}},
      {"max_node_interface_temperature", {"K", "maximum interface temperature of a single node"}},
      {"max_interface_reaction_progress", {"1", "maximum reaction progress at the interface temperature"}},
      // /hotspots and /hotspot_fates
      {"id", {"1", "id"}},
      {"particle_count", {"1", "particles"}},
      {"peak_temperature", {"K", "peak temperature"}},
      {"size", {"area", "hot spot size"}},
      {"equivalent_diameter", {"m", "equivalent diameter"}},
      {"centroid_x", {"m", "centroid x"}},
      {"centroid_y", {"m", "centroid y"}},
      {"centroid_z", {"m", "centroid z"}},
      {"birth_time", {"s", "birth time"}},
      {"duration", {"s", "duration"}},
      {"excess_energy", {"J", "excess thermal energy"}},
      {"material_mask", {"1", "materials present (bit m: material id m)"}},
      {"fate", {"1", "hot spot fate"}},
      {"start_time", {"s", "start of the continuation"}},
      {"initial_peak_temperature", {"K", "peak temperature at the start"}},
      {"final_peak_temperature", {"K", "peak temperature at the end"}},
      {"max_peak_temperature", {"K", "highest peak temperature"}},
      {"decision_time", {"s", "time the fate was decided"}},
      {"runaway_time", {"s", "runaway time"}},
      {"time_to_runaway", {"s", "time to runaway"}},
      // an ensemble's /members (ensemble.cpp); its /hotspots use the names above
      {"seed", {"1", "seed"}},
      {"status", {"1", "member status (0 completed, 1 stopped at max_steps, 2 failed)"}},
      {"simulated_time", {"s", "simulated time"}},
      {"hotspots", {"1", "hot spots"}},
      {"runaway", {"1", "runaway hot spots"}},
      {"dying", {"1", "dying hot spots"}},
      // snapshot fields (docs/output.md)
      {"position", {"m", "position"}},
      {"velocity", {"m/s", "velocity"}},
      {"displacement", {"m", "displacement"}},
      {"initial_position", {"m", "initial position"}},
      {"stress", {"Pa", "Cauchy stress"}},
      {"stress_zz", {"Pa", "out-of-plane stress"}},
      {"mass", {"kg", "particle mass"}},
      {"volume", {"m^3", "particle volume"}},
      {"temperature", {"K", "temperature"}},
      {"material", {"1", "material id"}},
      {"body", {"1", "body id"}},
      {"reaction_progress", {"1", "reaction progress"}},
      {"interface_temperature", {"K", "interface temperature"}},
      {"interface_reaction_progress", {"1", "reaction progress at the interface temperature"}},
      // /nodes: the thermal grid's nodes (runner_thermal.cpp; position and temperature as above)
      {"heat_capacity", {"J/K", "nodal heat capacity"}},
      {"lattice", {"1", "grid node coordinates (position = grid lo + lattice * cell size)"}},
      {"polyvertex", {"1", "XDMF polyvertex connectivity"}},
      {"connectivity", {"1", "XDMF polyvertex connectivity"}},
      // /meta numbers
      {"cell_size", {"m", "smallest cell size"}},
      {"cfl", {"1", "CFL factor"}},
      {"dimension", {"1", "dimension"}},
      {"end_time", {"s", "end time"}},
      {"final_time", {"s", "final time"}},
      {"thickness", {"m", "thickness"}},
      {"threads", {"1", "threads"}},
      {"steps", {"1", "steps"}},
      {"wall_time", {"s", "wall-clock time"}},
      {"ranks", {"1", "ranks"}},
      {"snapshots", {"1", "snapshots"}},
      {"checkpoint_write_time", {"s", "wall-clock time writing checkpoints"}},
      {"checkpoints_written", {"1", "checkpoints written"}},
      {"resumed_at_step", {"1", "step resumed at"}},
      {"resumed_from_ranks", {"1", "ranks of the run resumed"}},
      {"hotspots_seen", {"1", "hot spots seen"}},
      {"grid_lo", {"m", "grid lower corner"}},
      {"grid_hi", {"m", "grid upper corner"}},
      {"grid_cells", {"1", "grid cells per axis"}},
      {"grid_cell_size", {"m", "grid cell size per axis"}},
      {"work_received", {"J", "work received by the heat"}},
      {"plastic_work_received", {"J", "plastic work received by the heat"}},
      {"plastic_heat_received", {"J", "plastic heat received"}},
      {"plastic_heat_delivered", {"J", "plastic heat delivered"}},
      {"reaction_heat_released", {"J", "reaction heat released"}},
      {"particle_reaction_heat", {"J", "reaction heat of the particles"}},
      {"heat_relocated", {"J", "heat relocated"}},
      {"heat_pending", {"J", "heat pending"}},
      {"nodal_energy_change", {"J", "thermal energy change of the nodes"}},
      {"particle_energy_change", {"J", "thermal energy change of the particles"}},
      {"max_assembly_residual", {"J", "largest assembly residual"}},
      {"max_capacity_residual", {"1", "largest relative heat capacity residual"}},
      {"thermal_wall_time", {"s", "wall-clock time of the heat"}},
      {"thermal_min_window", {"s", "shortest coupling window"}},
      {"thermal_max_window", {"s", "longest coupling window"}},
      {"thermal_atol", {"K", "thermal integrator absolute tolerance"}},
      {"thermal_rtol", {"1", "thermal integrator relative tolerance"}},
      {"reaction_activation_temperature", {"K", "reaction activation temperature"}},
      {"reaction_heat_of_reaction", {"J/kg", "heat of reaction"}},
      {"reaction_prefactor", {"1/s", "reaction prefactor"}},
  };
  return c;
}

bool ends_with(const std::string& s, const char* tail) {
  const std::string t(tail);
  return s.size() >= t.size() && s.compare(s.size() - t.size(), t.size(), t) == 0;
}

std::string spaced(std::string s) {
  for (char& ch : s)
    if (ch == '_') ch = ' ';
  return s;
}

// Names the catalogue does not list one by one: families of /meta keys and any remaining text-free
// name whose ending says what it is.
std::optional<OutputQuantity> by_pattern(const std::string& name) {
  if (name.rfind("time_", 0) == 0) return OutputQuantity{"s", "wall-clock time in " + spaced(name.substr(5)), {}};
  if (name.rfind("traffic_", 0) == 0)  // per rank and step (decomposed_setup.cpp)
    return OutputQuantity{name.find("bytes") != std::string::npos ? "byte" : "1", spaced(name), {}};
  for (const char* count : {"_count", "_nodes", "_windows", "_iters", "_failures", "_substeps", "_gathers",
                            "_refreshes", "_reinits", "_intervals", "_evals", "_steps"})
    if (ends_with(name, count)) return OutputQuantity{"1", spaced(name), {}};
  if (ends_with(name, "_temperature")) return OutputQuantity{"K", spaced(name), {}};
  if (ends_with(name, "_time")) return OutputQuantity{"s", spaced(name), {}};
  if (ends_with(name, "_energy") || ends_with(name, "_work") || ends_with(name, "_heat"))
    return OutputQuantity{"J", spaced(name), {}};
  return std::nullopt;
}

}  // namespace

std::optional<OutputQuantity> output_quantity(const std::string& name, int dim) {
  const auto dot = name.find('.');
  const std::string base = name.substr(0, dot);
  std::optional<OutputQuantity> q;
  std::string base_key = base;
  if (base.rfind("polyvertex_", 0) == 0) base_key = "polyvertex";
  const auto& c = catalogue();
  if (const auto it = c.find(base_key); it != c.end()) {
    q = OutputQuantity{it->second.units, it->second.long_name, {}};
  } else {
    q = by_pattern(base);
  }
  if (!q) return std::nullopt;
  if (q->units == "area") q->units = dim == 3 ? "m^3" : "m^2";
  if (base == "fate") q->flags = {{0, "undecided"}, {1, "dying"}, {2, "runaway"}};  // HotSpotFate
  if (dot != std::string::npos) {  // a body (mean_temperature.block) or a material pair (base.block)
    const std::string part = name.substr(dot + 1);
    const std::size_t second = part.find('.');
    q->long_name += second == std::string::npos ? " of " + part
                                                : " between " + part.substr(0, second) + " and " + part.substr(second + 1);
  }
  return q;
}

}  // namespace frictherm::coupling
