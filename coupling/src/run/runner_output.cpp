// What the run loop writes: snapshot fields, series rows and run metadata.
#include "run/runner_detail.hpp"

#include "run/particle_output.hpp"

#include <frictherm/coupling/instruction_set.hpp>
#include <frictherm/coupling/microstructure.hpp>

#include <omp.h>

#include <algorithm>
#include <ctime>
#include <limits>
#include <sstream>

namespace frictherm::coupling::detail {

std::vector<std::string> series_names(int dim) {
  std::vector<std::string> n{"time",          "step",          "dt",        "kinetic_energy",
                             "strain_energy", "total_energy",  "external_work"};
  const char* axes[3] = {"momentum_x", "momentum_y", "momentum_z"};
  for (int d = 0; d < dim; ++d) n.emplace_back(axes[d]);
  // The energy balance (mechanics::EnergyBalance, docs/output.md "Energy balance").
  for (const char* c : {"rigid_work", "damping_work", "plastic_dissipation", "energy_lost", "numerical_dissipation",
                        "contact_normal_work", "boundary_stop_work", "stored_energy_lead"})
    n.emplace_back(c);
  return n;
}

void append_contact_series_names(std::vector<std::string>& names, const std::vector<std::string>& bodies,
                                 const std::vector<mechanics::Material>& mats,
                                 const std::vector<std::pair<int, int>>& pairs, int dim) {
  for (const char* order : {"first", "second"}) {
    names.push_back(std::string("friction_work_") + order);
    for (const auto& [a, b] : pairs)
      names.push_back(std::string("friction_work_") + order + "." + mats[static_cast<std::size_t>(a)].name + "." +
                      mats[static_cast<std::size_t>(b)].name);
  }
  names.emplace_back("contact_nodes");
  names.emplace_back("sliding_nodes");
  const char* axes[3] = {"x", "y", "z"};
  for (const auto& body : bodies)
    for (int d = 0; d < dim; ++d) names.push_back(std::string("mean_velocity_") + axes[d] + "." + body);
  names.emplace_back("contact_heat_rate");
  for (const auto& [a, b] : pairs)
    names.push_back("contact_heat_rate." + mats[static_cast<std::size_t>(a)].name + "." +
                    mats[static_cast<std::size_t>(b)].name);
}

template <int Dim>
void append_contact_series_names(std::vector<std::string>& names, const mechanics::Simulation<Dim>& sim) {
  if (!sim.contact_enabled()) return;
  std::vector<std::string> bodies;
  for (const auto& body : sim.bodies()) bodies.push_back(body.name);
  append_contact_series_names(names, bodies, sim.materials(), sim.contact_pairs(), Dim);
  // Penalty contact (docs/penalty_contact.md): the springs' energy, and per pair (master.slave) the
  // normal force, active contacts, deepest gap and the summed length of the penetrated master segments.
  if (!sim.penalty_contact()) return;
  append_penalty_series_names(names, sim.penalty_pairs(), sim.materials());
}

void append_penalty_series_names(std::vector<std::string>& names, const std::vector<mechanics::PenaltyPairInfo>& pairs,
                                 const std::vector<mechanics::Material>& mats) {
  names.emplace_back("penalty_energy");
  for (const auto& pp : pairs) {
    const std::string pair =
        mats[static_cast<std::size_t>(pp.master_material)].name + "." + mats[static_cast<std::size_t>(pp.slave_material)].name;
    for (const char* what : {"penalty_force.", "penalty_contacts.", "penalty_min_gap.", "penalty_contact_length."})
      names.push_back(what + pair);
  }
}

void append_body_series_names(std::vector<std::string>& names, const std::vector<std::string>& bodies, int dim) {
  const char* axes[3] = {"x", "y", "z"};
  for (const auto& body : bodies) {
    names.push_back("mean_temperature." + body);
    for (int d = 0; d < dim; ++d) names.push_back(std::string("mean_displacement_") + axes[d] + "." + body);
  }
}

template <int Dim>
void append_body_series_names(std::vector<std::string>& names, const mechanics::Simulation<Dim>& sim) {
  std::vector<std::string> bodies;
  for (const auto& body : sim.bodies()) bodies.push_back(body.name);
  append_body_series_names(names, bodies, Dim);
}

namespace {

// Mass-weighted sums over each body's particles (particle_output.hpp).
template <int Dim>
BodySums<Dim> body_sums(const mechanics::Simulation<Dim>& sim) {
  const auto& p = sim.particles();
  BodySums<Dim> sums(sim.bodies().size());
  for (std::size_t k = 0; k < p.size(); ++k)
    sums.add(static_cast<std::size_t>(p.body[k]), p.mass[k], p.temperature[k], p.position[k], p.initial_position[k],
             p.velocity[k]);
  return sums;
}

}  // namespace

void append_heat_rates(std::vector<double>& row, std::vector<double> work, double time, SeriesMemory& memory) {
  const double dt = time - memory.time;
  for (std::size_t j = 0; j < work.size(); ++j)
    row.push_back(memory.has_previous && dt > 0.0 ? (work[j] - memory.work[j]) / dt : 0.0);
  memory.time = time;
  memory.has_previous = true;
  memory.work = std::move(work);
}

template <int Dim>
std::vector<double> series_row(const mechanics::Simulation<Dim>& sim, SeriesMemory& memory,
                               mechanics::HeatingOrder order) {
  const double ke = sim.kinetic_energy(), se = sim.strain_energy();
  std::vector<double> row{sim.time(), static_cast<double>(sim.step_count()), sim.last_time_step(), ke, se,
                          ke + se,    sim.external_work()};
  const auto P = sim.linear_momentum();
  for (int d = 0; d < Dim; ++d) row.push_back(P[d]);
  const mechanics::EnergyBalance e = sim.energy_balance(order);
  row.insert(row.end(), {e.rigid_work, e.damping_work, e.plastic_work, e.lost(), e.numerical_dissipation(),
                         e.contact_normal_work, e.boundary_stop_work, e.stored_lead});
  const BodySums<Dim> bodies = body_sums(sim);
  bodies.append_means(row);
  if (!sim.contact_enabled()) return row;
  for (auto each : {mechanics::HeatingOrder::first, mechanics::HeatingOrder::second}) {
    row.push_back(sim.cumulative_frictional_work(each));
    for (const auto& [a, b] : sim.contact_pairs()) row.push_back(sim.cumulative_frictional_work(each, a, b));
  }
  row.push_back(static_cast<double>(sim.contact_stats().contact_nodes));
  row.push_back(static_cast<double>(sim.contact_stats().sliding_nodes));
  bodies.append_velocities(row);
  std::vector<double> work{sim.cumulative_frictional_work(order)};
  for (const auto& [a, b] : sim.contact_pairs()) work.push_back(sim.cumulative_frictional_work(order, a, b));
  append_heat_rates(row, std::move(work), sim.time(), memory);
  if (const mechanics::PenaltyContact<Dim>* pc = sim.penalty_contact()) append_penalty_row(row, *pc, sim.boundary_points());
  return row;
}

template <int Dim>
void append_penalty_row(std::vector<double>& row, const mechanics::PenaltyContact<Dim>& contact,
                        const mechanics::BoundaryPoints<Dim>& bp) {
  const mechanics::PenaltyContact<Dim>* pc = &contact;
  row.push_back(pc->stored_energy());
  std::vector<int> segments;
  for (std::size_t k = 0; k < pc->pair_count(); ++k) {
    double gap = 0.0;
    segments.clear();
    for (const auto& c : pc->contacts())
      if (c.pair == static_cast<int>(k)) {
        gap = std::min(gap, c.gap);
        segments.push_back(c.segment);
      }
    std::sort(segments.begin(), segments.end());
    segments.erase(std::unique(segments.begin(), segments.end()), segments.end());
    double length = 0.0;  // Kakouris 2024 §4.3.1: the contact length is the sum of the penetrated master segments
    for (int sgm : segments) length += bp.segment_length(static_cast<std::size_t>(sgm));
    row.push_back(pc->books(k).normal_force);
    row.push_back(static_cast<double>(pc->books(k).active));
    row.push_back(gap);
    row.push_back(length);
  }
}

// Snapshot fields (particle_output.hpp: the shapes VTK expects).
template <int Dim>
void write_fields(H5Output& out, const mechanics::Simulation<Dim>& sim, const std::vector<std::string>& fields) {
  const auto& p = sim.particles();
  ParticleArrays<Dim> a;
  a.n = p.size();
  a.position = p.position.data();
  a.velocity = p.velocity.data();
  a.initial_position = p.initial_position.data();
  a.stress = p.stress.data();
  a.stress_zz = &p.stress_zz;
  a.mass = &p.mass;
  a.volume = &p.volume;
  a.temperature = &p.temperature;
  a.material = p.material.data();
  a.body = p.body.data();
  write_particle_fields(out, a, fields);
}

template <int Dim>
void write_start_metadata(H5Output& out, const Scene& s, const mechanics::Simulation<Dim>& sim,
                          const RunOptions& options) {
  std::vector<std::string> body_names;  // by id
  for (const auto& body : sim.bodies()) body_names.push_back(body.name);
  write_start_metadata<Dim>(out, s, RunLayout<Dim>{sim.grid(), sim.materials(), body_names, sim.options(),
                                                   sim.particles().size()},
                            options);
}

template <int Dim>
void write_start_metadata(H5Output& out, const Scene& s, const RunLayout<Dim>& run, const RunOptions& options) {
  out.write_metadata("scene", s.text);
  out.write_metadata("scene_json", s.json);
  out.write_metadata("scene_file", s.source);
  std::string overrides;
  for (const auto& o : s.overrides) overrides += (overrides.empty() ? "" : "\n") + o.path + "=" + o.value;
  if (!overrides.empty()) out.write_metadata("overrides", overrides);
  out.write_metadata("version", FRICTHERM_VERSION);
  out.write_metadata("instruction_set", instruction_set());  // cmake/Arch.cmake
  out.write_metadata("command_line", options.command_line);
  char date[64] = "";
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  if (localtime_r(&now, &local)) std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%S%z", &local);
  out.write_metadata("start_date", date);
  out.write_metadata("status", "running");
  out.write_metadata("dimension", Dim);
  if (Dim == 2) {
    out.write_metadata("analysis", s.options.analysis == mechanics::Analysis::plane_stress ? "plane_stress" : "plane_strain");
    out.write_metadata("thickness", s.options.thickness);
  }
  out.write_metadata("particle_count", run.particles);
  out.write_metadata("threads", omp_get_max_threads());
  const auto& g = run.grid;
  std::ostringstream grid, materials, bodies;
  grid.precision(10);
  grid << "lo";
  for (int d = 0; d < Dim; ++d) grid << ' ' << g.lo()[d];
  grid << "; hi";
  for (int d = 0; d < Dim; ++d) grid << ' ' << g.hi()[d];
  grid << "; cells";
  for (int d = 0; d < Dim; ++d) grid << ' ' << g.cells()[static_cast<std::size_t>(d)];
  grid << "; cell_size";
  for (int d = 0; d < Dim; ++d) grid << ' ' << g.cell_size()[d];
  out.write_metadata("grid", grid.str());
  // The same as numbers (units in their attributes): grid_lo, grid_hi, grid_cells, grid_cell_size.
  std::vector<double> lo, hi, h;
  std::vector<std::int64_t> cells;
  for (int d = 0; d < Dim; ++d) {
    lo.push_back(g.lo()[d]);
    hi.push_back(g.hi()[d]);
    h.push_back(g.cell_size()[d]);
    cells.push_back(g.cells()[static_cast<std::size_t>(d)]);
  }
  out.write_metadata("grid_lo", lo);
  out.write_metadata("grid_hi", hi);
  out.write_metadata("grid_cells", cells);
  out.write_metadata("grid_cell_size", h);
  std::vector<std::string> material_names, material_kinds;  // by id
  for (const auto& mat : run.materials) {
    material_names.push_back(mat.name);
    material_kinds.push_back(mechanics::to_string(mat.kind));
  }
  out.write_metadata("material_names", material_names);
  out.write_metadata("material_kinds", material_kinds);
  out.write_metadata("body_names", run.body_names);
  out.write_metadata("cell_size", g.min_cell_size());
  for (std::size_t m = 0; m < run.materials.size(); ++m)
    materials << (m ? "; " : "") << m << ' ' << run.materials[m].name << ' '
              << mechanics::to_string(run.materials[m].kind);
  out.write_metadata("materials", materials.str());
  for (std::size_t b = 0; b < run.body_names.size(); ++b) bodies << (b ? "; " : "") << b << ' ' << run.body_names[b];
  out.write_metadata("bodies", bodies.str());
  const auto& o = run.options;
  out.write_metadata("shape_function", mechanics::to_string(o.shape));
  out.write_metadata("scheme", mechanics::to_string(o.scheme));
  out.write_metadata("cfl", o.cfl);
  out.write_metadata("end_time", s.end_time);
}

void write_microstructure_images(H5Output& out, const Scene& s, const std::string& output) {
  std::vector<std::string> written;
  try {
    written = write_generated_images(s, output);
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
  std::string list;
  for (const auto& w : written) list += (list.empty() ? "" : "; ") + w;
  if (!list.empty()) out.write_metadata("microstructure_images", list);
}

#define FRICTHERM_INSTANTIATE_RUNNER_OUTPUT(D)                                                                \
  template void append_contact_series_names<D>(std::vector<std::string>&, const mechanics::Simulation<D>&);      \
  template void append_body_series_names<D>(std::vector<std::string>&, const mechanics::Simulation<D>&);         \
  template std::vector<double> series_row<D>(const mechanics::Simulation<D>&, SeriesMemory&, mechanics::HeatingOrder); \
  template void append_penalty_row<D>(std::vector<double>&, const mechanics::PenaltyContact<D>&,            \
                                      const mechanics::BoundaryPoints<D>&);                                   \
  template void write_fields<D>(H5Output&, const mechanics::Simulation<D>&, const std::vector<std::string>&); \
  template void write_start_metadata<D>(H5Output&, const Scene&, const mechanics::Simulation<D>&, const RunOptions&); \
  template void write_start_metadata<D>(H5Output&, const Scene&, const RunLayout<D>&, const RunOptions&);
FRICTHERM_INSTANTIATE_RUNNER_OUTPUT(2)
FRICTHERM_INSTANTIATE_RUNNER_OUTPUT(3)
#undef FRICTHERM_INSTANTIATE_RUNNER_OUTPUT

}  // namespace frictherm::coupling::detail
