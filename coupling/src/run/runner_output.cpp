// What the run loop writes: snapshot fields, series rows and run metadata.
#include "run/runner_detail.hpp"

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
  for (const char* c : {"rigid_work", "damping_work", "plastic_dissipation", "energy_lost", "numerical_dissipation"})
    n.emplace_back(c);
  return n;
}

template <int Dim>
void append_contact_series_names(std::vector<std::string>& names, const mechanics::Simulation<Dim>& sim) {
  if (!sim.contact_enabled()) return;
  const auto& mats = sim.materials();
  for (const char* order : {"first", "second"}) {
    names.push_back(std::string("friction_work_") + order);
    for (const auto& [a, b] : sim.contact_pairs())
      names.push_back(std::string("friction_work_") + order + "." + mats[static_cast<std::size_t>(a)].name + "." +
                      mats[static_cast<std::size_t>(b)].name);
  }
  names.emplace_back("contact_nodes");
  names.emplace_back("sliding_nodes");
  const char* axes[3] = {"x", "y", "z"};
  for (const auto& body : sim.bodies())
    for (int d = 0; d < Dim; ++d) names.push_back(std::string("mean_velocity_") + axes[d] + "." + body.name);
  names.emplace_back("contact_heat_rate");
  for (const auto& [a, b] : sim.contact_pairs())
    names.push_back("contact_heat_rate." + mats[static_cast<std::size_t>(a)].name + "." +
                    mats[static_cast<std::size_t>(b)].name);
  // Penalty contact (docs/penalty_contact.md): the springs' energy, and per pair (master.slave) the
  // normal force, active contacts, deepest gap and the summed length of the penetrated master segments.
  if (!sim.penalty_contact()) return;
  append_penalty_series_names(names, sim.penalty_pairs(), mats);
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

template <int Dim>
void append_body_series_names(std::vector<std::string>& names, const mechanics::Simulation<Dim>& sim) {
  const char* axes[3] = {"x", "y", "z"};
  for (const auto& body : sim.bodies()) {
    names.push_back("mean_temperature." + body.name);
    for (int d = 0; d < Dim; ++d) names.push_back(std::string("mean_displacement_") + axes[d] + "." + body.name);
  }
}

namespace {

// Mass-weighted means over each body's particles: temperature (K) and displacement x - X (m).
template <int Dim>
void append_body_means(std::vector<double>& row, const mechanics::Simulation<Dim>& sim) {
  const auto& p = sim.particles();
  const std::size_t bodies = sim.bodies().size();
  std::vector<double> m(bodies, 0.0), mT(bodies, 0.0);
  std::vector<mechanics::Vec<Dim>> mu(bodies, mechanics::Vec<Dim>::Zero());
  for (std::size_t k = 0; k < p.size(); ++k) {
    const std::size_t b = static_cast<std::size_t>(p.body[k]);
    m[b] += p.mass[k];
    mT[b] += p.mass[k] * p.temperature[k];
    mu[b] += p.mass[k] * (p.position[k] - p.initial_position[k]);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();  // a body without mass has no mean
  for (std::size_t b = 0; b < bodies; ++b) {
    row.push_back(m[b] > 0.0 ? mT[b] / m[b] : nan);
    for (int d = 0; d < Dim; ++d) row.push_back(m[b] > 0.0 ? mu[b][d] / m[b] : nan);
  }
}

// contact_heat_rate: the increase of the cumulative frictional work (of the order handed to the
// thermal solver) since the previous series row over the time between them, W. The rates times the
// row intervals add up to the frictional work exactly (a telescoping sum); 0 in the first row.
template <int Dim>
void append_heat_rates(std::vector<double>& row, const mechanics::Simulation<Dim>& sim, SeriesMemory& memory,
                       mechanics::HeatingOrder order) {
  std::vector<double> work{sim.cumulative_frictional_work(order)};
  for (const auto& [a, b] : sim.contact_pairs()) work.push_back(sim.cumulative_frictional_work(order, a, b));
  const double dt = sim.time() - memory.time;
  for (std::size_t j = 0; j < work.size(); ++j)
    row.push_back(memory.has_previous && dt > 0.0 ? (work[j] - memory.work[j]) / dt : 0.0);
  memory.time = sim.time();
  memory.has_previous = true;
  memory.work = std::move(work);
}

}  // namespace

template <int Dim>
std::vector<double> series_row(const mechanics::Simulation<Dim>& sim, SeriesMemory& memory,
                               mechanics::HeatingOrder order) {
  const double ke = sim.kinetic_energy(), se = sim.strain_energy();
  std::vector<double> row{sim.time(), static_cast<double>(sim.step_count()), sim.last_time_step(), ke, se,
                          ke + se,    sim.external_work()};
  const auto P = sim.linear_momentum();
  for (int d = 0; d < Dim; ++d) row.push_back(P[d]);
  const mechanics::EnergyBalance e = sim.energy_balance(order);
  row.insert(row.end(), {e.rigid_work, e.damping_work, e.plastic_work, e.lost(), e.numerical_dissipation()});
  append_body_means(row, sim);
  if (!sim.contact_enabled()) return row;
  for (auto each : {mechanics::HeatingOrder::first, mechanics::HeatingOrder::second}) {
    row.push_back(sim.cumulative_frictional_work(each));
    for (const auto& [a, b] : sim.contact_pairs()) row.push_back(sim.cumulative_frictional_work(each, a, b));
  }
  row.push_back(static_cast<double>(sim.contact_stats().contact_nodes));
  row.push_back(static_cast<double>(sim.contact_stats().sliding_nodes));
  // Mass-weighted mean velocity of each body (what the sliding-block charts plot).
  const auto& p = sim.particles();
  std::vector<mechanics::Vec<Dim>> mv(sim.bodies().size(), mechanics::Vec<Dim>::Zero());
  std::vector<double> m(sim.bodies().size(), 0.0);
  for (std::size_t k = 0; k < p.size(); ++k) {
    const std::size_t b = static_cast<std::size_t>(p.body[k]);
    mv[b] += p.mass[k] * p.velocity[k];
    m[b] += p.mass[k];
  }
  for (std::size_t b = 0; b < mv.size(); ++b)
    for (int d = 0; d < Dim; ++d) row.push_back(m[b] > 0.0 ? mv[b][d] / m[b] : 0.0);
  append_heat_rates(row, sim, memory, order);
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

// Snapshot fields in the shapes VTK (ParaView's XDMF reader, Warp By Vector, Calculator) expects:
// vectors are (n, 3) and the stress is the full 3x3 tensor (n, 9, row-major) in 2D as in 3D. In 2D the
// z components of vectors are 0 and the stress's zz entry is the out-of-plane stress (stress_zz, 0 in
// plane stress), its xz, yz, zx, zy entries 0. position keeps (n, Dim): it is the XDMF geometry (XY in
// 2D), which VTK pads itself. docs/output.md describes every array.
template <int Dim>
void write_fields(H5Output& out, const mechanics::Simulation<Dim>& sim, const std::vector<std::string>& fields) {
  const auto& p = sim.particles();
  const std::size_t n = p.size();
  std::vector<double> buf;
  auto vectors = [&](const std::string& name, auto&& get) {
    buf.assign(n * 3, 0.0);
    for (std::size_t k = 0; k < n; ++k) {
      const mechanics::Vec<Dim> v = get(k);
      for (int d = 0; d < Dim; ++d) buf[k * 3 + static_cast<std::size_t>(d)] = v[d];
    }
    out.snapshot_field(name, buf.data(), n, 3);
  };
  auto scalars = [&](const std::string& name, const std::vector<double>& v) { out.snapshot_field(name, v.data(), n, 1); };
  for (const std::string& f : fields) {
    if (f == "position") {
      buf.resize(n * Dim);
      for (std::size_t k = 0; k < n; ++k)
        for (int d = 0; d < Dim; ++d) buf[k * Dim + static_cast<std::size_t>(d)] = p.position[k][d];
      out.snapshot_field(f, buf.data(), n, Dim);
    } else if (f == "velocity") {
      vectors(f, [&](std::size_t k) { return p.velocity[k]; });
    } else if (f == "displacement") {
      vectors(f, [&](std::size_t k) { return mechanics::Vec<Dim>(p.position[k] - p.initial_position[k]); });
      // With it the reference positions X (dim columns), the geometry of RUN_reference.xdmf: Warp By
      // Vector on `displacement` there draws x = X + u (docs/output.md "In ParaView").
      buf.resize(n * Dim);
      for (std::size_t k = 0; k < n; ++k)
        for (int d = 0; d < Dim; ++d) buf[k * Dim + static_cast<std::size_t>(d)] = p.initial_position[k][d];
      out.snapshot_field("initial_position", buf.data(), n, Dim);
    } else if (f == "stress") {
      buf.assign(n * 9, 0.0);
      for (std::size_t k = 0; k < n; ++k) {
        double* s = &buf[k * 9];
        for (int i = 0; i < Dim; ++i)
          for (int j = 0; j < Dim; ++j) s[3 * i + j] = p.stress[k](i, j);
        if (Dim == 2 && k < p.stress_zz.size()) s[8] = p.stress_zz[k];
      }
      out.snapshot_field(f, buf.data(), n, 9);
    } else if (f == "stress_zz") {
      scalars(f, p.stress_zz);
    } else if (f == "mass") {
      scalars(f, p.mass);
    } else if (f == "volume") {
      scalars(f, p.volume);
    } else if (f == "temperature") {
      scalars(f, p.temperature);
    } else if (f == "material") {
      out.snapshot_field(f, p.material.data(), n);
    } else if (f == "body") {
      out.snapshot_field(f, p.body.data(), n);
    }
  }
}

template <int Dim>
void write_start_metadata(H5Output& out, const Scene& s, const mechanics::Simulation<Dim>& sim,
                          const RunOptions& options) {
  out.write_metadata("scene", s.text);
  out.write_metadata("scene_json", s.json);
  out.write_metadata("scene_file", s.source);
  std::string overrides;
  for (const auto& o : s.overrides) overrides += (overrides.empty() ? "" : "\n") + o.path + "=" + o.value;
  if (!overrides.empty()) out.write_metadata("overrides", overrides);
  out.write_metadata("version", FRICTHERM_VERSION);
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
  out.write_metadata("particle_count", sim.particles().size());
  out.write_metadata("threads", omp_get_max_threads());
  const auto& g = sim.grid();
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
  std::vector<std::string> material_names, material_kinds, body_names;  // by id
  for (const auto& mat : sim.materials()) {
    material_names.push_back(mat.name);
    material_kinds.push_back(mechanics::to_string(mat.kind));
  }
  for (const auto& body : sim.bodies()) body_names.push_back(body.name);
  out.write_metadata("material_names", material_names);
  out.write_metadata("material_kinds", material_kinds);
  out.write_metadata("body_names", body_names);
  out.write_metadata("cell_size", g.min_cell_size());
  for (std::size_t m = 0; m < sim.materials().size(); ++m)
    materials << (m ? "; " : "") << m << ' ' << sim.materials()[m].name << ' '
              << mechanics::to_string(sim.materials()[m].kind);
  out.write_metadata("materials", materials.str());
  for (std::size_t b = 0; b < sim.bodies().size(); ++b) bodies << (b ? "; " : "") << b << ' ' << sim.bodies()[b].name;
  out.write_metadata("bodies", bodies.str());
  const auto& o = sim.options();
  out.write_metadata("shape_function", mechanics::to_string(o.shape));
  out.write_metadata("scheme", mechanics::to_string(o.scheme));
  out.write_metadata("cfl", o.cfl);
  out.write_metadata("end_time", s.end_time);
}

#define FRICTHERM_INSTANTIATE_RUNNER_OUTPUT(D)                                                                \
  template void append_contact_series_names<D>(std::vector<std::string>&, const mechanics::Simulation<D>&);      \
  template void append_body_series_names<D>(std::vector<std::string>&, const mechanics::Simulation<D>&);         \
  template std::vector<double> series_row<D>(const mechanics::Simulation<D>&, SeriesMemory&, mechanics::HeatingOrder); \
  template void append_penalty_row<D>(std::vector<double>&, const mechanics::PenaltyContact<D>&,            \
                                      const mechanics::BoundaryPoints<D>&);                                   \
  template void write_fields<D>(H5Output&, const mechanics::Simulation<D>&, const std::vector<std::string>&); \
  template void write_start_metadata<D>(H5Output&, const Scene&, const mechanics::Simulation<D>&, const RunOptions&);
FRICTHERM_INSTANTIATE_RUNNER_OUTPUT(2)
FRICTHERM_INSTANTIATE_RUNNER_OUTPUT(3)
#undef FRICTHERM_INSTANTIATE_RUNNER_OUTPUT

}  // namespace frictherm::coupling::detail
