// The thermal side of a run: coupler calls, series columns, /hotspots, metadata, continuation.
#include "run/runner_thermal.hpp"

#include "run/node_output.hpp"
#include "run/run_signals.hpp"

#include <frictherm/mechanics/errors.hpp>

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <iterator>
#include <limits>
#include <stdexcept>

namespace frictherm::coupling::detail {

namespace {

const char* const kSeriesColumns[] = {"heat_delivered",         "thermal_energy_change",     "max_temperature",
                                      "hotspot_count",          "hottest_hotspot_temperature", "hottest_hotspot_size",
                                      "hottest_hotspot_diameter", "thermal_windows"};


}  // namespace

template <int Dim>
ThermalRun<Dim>::ThermalRun(const Scene& scene, mechanics::Simulation<Dim>& sim)
    : spec_(scene.thermal), coupler_(sim.grid(), sim.options().shape, scene.thermal.coupler) {
  // The coupler reads the MPM step's stencils instead of evaluating its own (sim outlives this run).
  coupler_.set_stencil_source([&sim] { return sim.current_stencils(); });
  try {
    coupler_.start(sim.particles(), sim.time());
  } catch (const std::invalid_argument& e) {
    throw SceneError::at_key("thermal.materials", e.what());
  }
}

template <int Dim>
void ThermalRun<Dim>::declare_output(H5Output& out, std::vector<std::string>& names) {
  for (const char* c : kSeriesColumns) names.emplace_back(c);
  const CouplerOptions& o = coupler_.options();
  if (o.plastic.enabled) names.insert(names.end(), {"plastic_work", "plastic_heat"});
  if (o.reaction.enabled) names.insert(names.end(), {"reaction_heat", "max_reaction_progress"});
  if (o.interface_temperature.enabled) names.emplace_back("max_interface_temperature");
  if (o.interface_temperature.enabled && o.interface_temperature.patch_length > 0.0)
    names.emplace_back("max_node_interface_temperature");
  if (o.interface_temperature.enabled && o.reaction.enabled) names.emplace_back("max_interface_reaction_progress");
  out.declare_table("hotspots", hotspot_table_columns(Dim));
  if (spec_.continuation_duration > 0.0)
    out.declare_table("hotspot_fates", hotspot_fate_columns());
}

template <int Dim>
void ThermalRun<Dim>::extend_series_row(std::vector<double>& row, H5Output& out,
                                        const mechanics::Simulation<Dim>& sim, double time) {
  const EnergyBooks& b = coupler_.books();
  const HotSpotTracker& hs = coupler_.hotspots();
  const HotSpot* hot = hs.hottest();
  // No hot spot: the hottest_hotspot_* columns are NaN (undefined), not 0 (issue 14 item 6).
  const double kNoHotSpot = std::numeric_limits<double>::quiet_NaN();
  const long windows = b.windows + b.continuation_intervals;
  // thermal_energy_change: Σ_p m_p C_v,p (T_p − T_p(0)), which equals heat_delivered (design §4).
  row.insert(row.end(), {b.heat_delivered, coupler_.particle_energy_change(sim.particles()), hs.max_temperature(),
                         static_cast<double>(hs.hot_spots().size()), hot ? hot->peak_temperature : kNoHotSpot,
                         hot ? hot->size : kNoHotSpot, hot ? hot->equivalent_diameter : kNoHotSpot,
                         static_cast<double>(windows)});
  const CouplerOptions& o = coupler_.options();
  if (o.plastic.enabled) row.insert(row.end(), {b.plastic_work_received, b.plastic_heat_received});
  if (o.reaction.enabled) {
    const std::vector<double>& lam = coupler_.reaction_progress();
    row.insert(row.end(), {b.reaction_heat_released, lam.empty() ? 0.0 : *std::max_element(lam.begin(), lam.end())});
  }
  if (o.interface_temperature.enabled) {  // NaN until some node has received frictional heat
    const double t_int = coupler_.interface_temperature().max_temperature();
    row.push_back(std::isfinite(t_int) ? t_int : std::numeric_limits<double>::quiet_NaN());
    if (o.interface_temperature.patch_length > 0.0) {
      const double t_node = coupler_.interface_temperature().max_node_temperature();
      row.push_back(std::isfinite(t_node) ? t_node : std::numeric_limits<double>::quiet_NaN());
    }
  }
  if (o.interface_temperature.enabled && o.reaction.enabled) row.push_back(coupler_.interface_reaction().max_progress());
  if (windows == hotspot_windows_written_) return;
  hotspot_windows_written_ = windows;
  for (const HotSpot& h : hs.hot_spots()) out.append_table_row("hotspots", hotspot_table_row(h, time, Dim));
}

template <int Dim>
template <class F>
void ThermalRun<Dim>::guarded(const mechanics::Simulation<Dim>& sim, double time, F&& f) {
  try {
    f();
  } catch (const thermal::SolverError& e) {
    throw mechanics::SimulationError(std::string("thermal solver failed: ") + e.what(), sim.step_count(), time, -1);
  } catch (const thermal::StabilityError& e) {
    throw mechanics::SimulationError(std::string("thermal integration unstable: ") + e.what(), sim.step_count(),
                                     time, -1);
  }
}

template <int Dim>
void ThermalRun<Dim>::after_step(mechanics::Simulation<Dim>& sim, const std::vector<double>& nodal_work,
                                 bool must_close) {
  guarded(sim, sim.time(), [&] {
    const bool closed = coupler_.after_step(sim.particles(), nodal_work, sim.time());
    if (must_close && !closed) coupler_.close_window(sim.particles(), sim.time());
  });
}

template <int Dim>
void ThermalRun<Dim>::continuation(H5Output& out, mechanics::Simulation<Dim>& sim,
                                   const std::vector<std::string>& fields, SeriesMemory& memory) {
  if (!(spec_.continuation_duration > 0.0)) return;
  guarded(sim, sim.time(), [&] { coupler_.close_window(sim.particles(), sim.time()); });
  const double t0 = sim.time();
  const long n = spec_.continuation_intervals;
  double t = t0;
  for (long k = 1; k <= n; ++k) {
    t = t0 + spec_.continuation_duration * static_cast<double>(k) / static_cast<double>(n);
    guarded(sim, t, [&] { coupler_.continue_thermal(sim.particles(), t); });
    std::vector<double> row = series_row<Dim>(sim, memory, spec_.heating_order);
    row[0] = t;  // the mechanics columns stay at their final values
    extend_series_row(row, out, sim, t);
    out.append_series(row);
    const HotSpotFates& f = coupler_.fates();
    if (spec_.stop_when_decided && !f.records().empty() && f.all_decided()) break;
    if (interrupt_signal() != 0) break;  // SIGINT/SIGTERM: end with this interval's state (run_signals.hpp)
  }
  coupler_.finish_continuation();
  for (const HotSpotFateRecord& r : coupler_.fates().records()) out.append_table_row("hotspot_fates", hotspot_fate_row(r));
  out.begin_snapshot(sim.step_count(), t);
  detail::write_fields<Dim>(out, sim, fields);
  write_fields(out);
  out.end_snapshot();
}

template <int Dim>
void ThermalRun<Dim>::write_fields(H5Output& out) const {
  const std::vector<double>& lam = coupler_.reaction_progress();
  if (coupler_.options().reaction.enabled && !lam.empty())
    out.snapshot_field("reaction_progress", lam.data(), lam.size(), 1);
  const std::vector<double>& t_int = coupler_.interface_temperature().particle_temperature();
  if (coupler_.options().interface_temperature.enabled && !t_int.empty())
    out.snapshot_field("interface_temperature", t_int.data(), t_int.size(), 1);
  const std::vector<double>& lam_int = coupler_.interface_reaction().progress();
  if (coupler_.interface_reaction().started() && !lam_int.empty())
    out.snapshot_field("interface_reaction_progress", lam_int.data(), lam_int.size(), 1);
  write_nodes(out);
}

// The thermal grid's state at the snapshot (/nodes, RUN.xdmf "thermal_nodes"): the nodes that are
// unknowns of the last system, where they are, their temperature T_i and heat capacity M_i (eq. 38).
template <int Dim>
void ThermalRun<Dim>::write_nodes(H5Output& out) const {
  const NodalThermalSystem* system = coupler_.system();
  const Eigen::VectorXd& t = coupler_.nodal_temperature();
  if (system == nullptr || system->size() == 0 || static_cast<std::size_t>(t.size()) != system->size()) return;
  write_node_fields<Dim>(out, coupler_.grid(), system->grid_node, t.data(), system->mass.data());
}

template <int Dim>
void ThermalRun<Dim>::write_metadata(H5Output& out, const mechanics::Simulation<Dim>& sim) const {
  write_thermal_metadata(out, ThermalMetadata{coupler_.options(), spec_.heating_order, coupler_.books(),
                                              coupler_.integrator_stats(),
                                              coupler_.particle_reaction_heat(sim.particles()),
                                              coupler_.pending_heat(),
                                              coupler_.particle_energy_change(sim.particles()),
                                              static_cast<std::int64_t>(coupler_.hotspots().ids_issued())});
}

void write_thermal_metadata(H5Output& out, const ThermalMetadata& m) {
  const CouplerOptions& o = m.options;
  const EnergyBooks& b = m.books;
  const thermal::IntegratorStats& st = m.stats;
  out.write_metadata("thermal_integrator", o.integrator);
  out.write_metadata("thermal_rtol", o.integrator_options.rtol);
  out.write_metadata("thermal_atol", o.integrator_options.atol);
  out.write_metadata("thermal_window_policy", to_string(o.window.kind));
  out.write_metadata("heating_order", to_string(m.heating_order));
  const std::pair<const char*, std::int64_t> counts[] = {
      {"thermal_steps", static_cast<std::int64_t>(st.steps)},
      {"thermal_rhs_evals", static_cast<std::int64_t>(st.rhs_evals)},
      {"thermal_jac_evals", static_cast<std::int64_t>(st.jac_evals)},
      {"thermal_nonlinear_iters", static_cast<std::int64_t>(st.nonlinear_iters)},
      {"thermal_linear_iters", static_cast<std::int64_t>(st.linear_iters)},
      {"thermal_error_test_failures", static_cast<std::int64_t>(st.error_test_failures)},
      {"thermal_convergence_failures", static_cast<std::int64_t>(st.convergence_failures)},
      {"thermal_reinits", static_cast<std::int64_t>(st.reinits)},
      {"thermal_windows", static_cast<std::int64_t>(b.windows)},
      {"thermal_matrix_free_windows", static_cast<std::int64_t>(b.matrix_free_windows)},
      {"thermal_matrix_free_substeps", static_cast<std::int64_t>(b.matrix_free_substeps)},
      {"thermal_matrix_free_gathers", static_cast<std::int64_t>(b.matrix_free_gathers)},
      {"thermal_matrix_free_refreshes", static_cast<std::int64_t>(b.matrix_free_refreshes)},
      {"thermal_continuation_intervals", static_cast<std::int64_t>(b.continuation_intervals)},
      {"hotspots_seen", m.hotspots_seen},
  };
  for (const auto& [key, value] : counts) out.write_metadata(key, value);
  const std::pair<const char*, double> values[] = {
      {"thermal_wall_time", st.wall_seconds},
      {"thermal_min_window", b.windows > 0 ? b.min_window : 0.0},
      {"thermal_max_window", b.max_window},
      {"work_received", b.work_received},
      {"heat_delivered", b.heat_delivered},
      {"plastic_work_received", b.plastic_work_received},
      {"plastic_heat_received", b.plastic_heat_received},
      {"plastic_heat_delivered", b.plastic_heat_delivered},
      {"reaction_heat_released", b.reaction_heat_released},
      {"particle_reaction_heat", m.particle_reaction_heat},
      {"heat_relocated", b.heat_relocated},
      {"heat_pending", m.pending_heat},
      {"nodal_energy_change", b.nodal_energy_change},
      {"particle_energy_change", m.particle_energy_change},
      {"max_assembly_residual", b.max_assembly_residual},
  };
  for (const auto& [key, value] : values) out.write_metadata(key, value);
  out.write_metadata("plastic_heating", o.plastic.enabled ? "on" : "off");
  if (o.reaction.enabled) {
    out.write_metadata("reaction_kinetics", o.reaction.kinetics_name);
    out.write_metadata("reaction_prefactor", o.reaction.kinetics.prefactor);
    out.write_metadata("reaction_activation_temperature", o.reaction.kinetics.activation_temperature);
    out.write_metadata("reaction_heat_of_reaction", o.reaction.kinetics.specific_heat_of_reaction);
  }
}

template class ThermalRun<2>;
template class ThermalRun<3>;

}  // namespace frictherm::coupling::detail
