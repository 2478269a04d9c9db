// A decomposed run's grid, options and particles from a scene, agreed errors, the books' log line and
// the traffic record (decomposed_setup.hpp).
#include "distributed_run/decomposed_setup.hpp"

#include "run/runner_thermal.hpp"

#include "scene/scene_detail.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace frictherm::coupling::detail {

std::string agreed_error(MPI_Comm comm, const std::string& error) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int mine = error.empty() ? size : rank;
  int first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return "";
  int length = rank == first ? static_cast<int>(error.size()) : 0;
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  std::string text = rank == first ? error : std::string(static_cast<std::size_t>(length), ' ');
  MPI_Bcast(text.data(), length, MPI_CHAR, first, comm);
  return text;
}

bool penalty_contact_scene(const Scene& scene) {
  if (!scene.contact.enabled) return false;
  bool penalty = scene.contact.options.default_pair.method == mechanics::ContactMethod::penalty;
  for (const ContactPairSpec& p : scene.contact.pairs) penalty = penalty || p.settings.method == mechanics::ContactMethod::penalty;
  return penalty;
}

bool plastic_heating(const Scene& scene) { return scene.thermal.enabled && scene.thermal.coupler.plastic.enabled; }

bool interface_temperature(const Scene& scene) {
  return scene.thermal.enabled && scene.thermal.coupler.interface_temperature.enabled;
}

bool gather_reuse(const Scene& scene) {
  const CouplerOptions& c = scene.thermal.coupler;
  return scene.thermal.enabled && scene.thermal.reuse_distance_given && c.reuse_distance > 0.0 &&
         (c.integrator == "forward_euler" || c.integrator == "auto");
}

bool interface_reaction(const Scene& scene) {
  return interface_temperature(scene) && scene.thermal.coupler.reaction.enabled;
}

template <int Dim>
mechanics::Grid<Dim> scene_grid(const Scene& scene) {
  mechanics::IVec<Dim> cells{};
  for (int d = 0; d < Dim; ++d) cells[static_cast<std::size_t>(d)] = scene.cells[static_cast<std::size_t>(d)];
  return mechanics::Grid<Dim>(to_vec<Dim>(scene.grid_lo), to_vec<Dim>(scene.cell_size), cells);
}

namespace {

// Penalty contact: the serial build's boundary points and pairs (Simulation::setup_penalty: the bodies'
// boundary loops, master/slave choice, penalties), with its velocity fields renamed as the decomposed
// ones (a field per material), and each material's mean particle mass, the serial
// penalty_state_.reference_mass (Σ m_p over the material's particles in the serial order, over their count).
// Every rank builds the scene (the penalty scenes are small: the EBS benchmarks).
template <int Dim>
void add_penalty(const Scene& scene, typename mechanics::DecomposedMpm<Dim>::Options& o) {
  if (!penalty_contact_scene(scene)) return;
  const auto sim = build_simulation<Dim>(scene);
  const mechanics::PenaltyContact<Dim>* pc = sim->penalty_contact();
  if (!pc) return;  // no two present materials in penalty contact
  const auto material_of = [&](int field) { return sim->fields()[static_cast<std::size_t>(field)].material; };
  o.penalty_points = sim->boundary_points();
  for (auto& f : o.penalty_points.field) f = material_of(f);
  for (auto& f : o.penalty_points.loop_field) f = material_of(f);
  for (std::size_t k = 0; k < pc->pair_count(); ++k) {
    mechanics::PenaltyPairSettings ps = pc->pair(k);
    ps.master = material_of(ps.master);
    ps.slave = material_of(ps.slave);
    o.penalty_pairs.push_back(ps);
    o.penalty_materials.push_back({sim->penalty_pairs()[k].master_material, sim->penalty_pairs()[k].slave_material});
  }
  const mechanics::Particles<Dim>& p = sim->particles();
  std::vector<double> mass(scene.materials.size(), 0.0);
  std::vector<std::size_t> count(scene.materials.size(), 0);
  for (std::size_t k = 0; k < p.size(); ++k) {
    mass[static_cast<std::size_t>(p.material[k])] += p.mass[k];
    ++count[static_cast<std::size_t>(p.material[k])];
  }
  o.penalty_reference_mass.assign(mass.size(), 0.0);
  for (std::size_t m = 0; m < mass.size(); ++m)
    if (count[m] > 0) o.penalty_reference_mass[m] = mass[m] / static_cast<double>(count[m]);
}

}  // namespace

template <int Dim>
typename mechanics::DecomposedMpm<Dim>::Options decomposed_options(const Scene& scene) {
  typename mechanics::DecomposedMpm<Dim>::Options o;
  o.shape = scene.options.shape;
  o.analysis = scene.options.analysis;
  o.thickness = scene.options.thickness;
  o.ebs_occupation = scene.options.ebs_occupation;  // C_c of the extended B-spline (docs/ebs.md)
  for (int d = 0; d < Dim; ++d) o.gravity[d] = scene.options.gravity[d];
  o.pic_relaxation_time = scene.options.pic_relaxation_time;
  o.particle_update = scene.options.particle_update;
  o.transfer_order = scene.options.transfer_order;
  o.musl = scene.options.scheme == mechanics::UpdateScheme::musl;
  o.usf = scene.options.scheme == mechanics::UpdateScheme::usf;
  o.damping_rate = scene.options.damping_rate;
  o.damping_until = scene.options.damping_until;
  o.fixed_faces = scene.fixed_faces;
  o.contact = scene.contact.enabled;
  if (o.contact) {
    o.contact_options = scene.contact.options;
    for (const ContactPairSpec& p : scene.contact.pairs) o.contact_pairs.push_back({p.material_a, p.material_b, p.settings});
  }
  if (o.contact) add_penalty<Dim>(scene, o);
  o.particle_scalars = {"temperature", "reference_temperature"};  // T_p and T0_p (hot spots' reference)
  // The plastic work already handed to the heat (DecomposedHeatOptions::plastic_work_heated).
  if (plastic_heating(scene)) o.particle_scalars.emplace_back("plastic_work_heated");
  // T_int,p of the sub-cell interface temperature (DecomposedHeatOptions::interface_scalar).
  if (interface_temperature(scene)) o.particle_scalars.emplace_back("interface_temperature");
  // λ_p of the reaction (DecomposedHeatOptions::progress_scalar).
  if (scene.thermal.enabled && scene.thermal.coupler.reaction.enabled) o.particle_scalars.emplace_back("reaction_progress");
  // λ_int,p and k(T_int,p) of the interface reaction (DecomposedHeatOptions::interface_progress_scalar,
  // interface_rate_scalar): they move with their particles.
  if (interface_reaction(scene)) o.particle_scalars.insert(o.particle_scalars.end(), {"interface_reaction_progress", "interface_reaction_rate"});
  // The particle's body (the serial Particles::body; exact as a double): the series' per-body means
  // and the snapshots' body field (issue 32).
  o.particle_scalars.emplace_back("body");
  // Where each particle was last gathered (DecomposedHeatOptions::reuse_scalar), its V_p and Rayleigh
  // term then; stencils there lie up to reuse_distance (≤ 0.5) cells from its current ones, so they
  // may reach one node beyond the kernel's reach: one more ghost layer.
  if (gather_reuse(scene)) {
    for (int d = 0; d < Dim; ++d) o.particle_scalars.push_back("gathered_at_" + std::to_string(d));
    o.particle_scalars.insert(o.particle_scalars.end(), {"gathered_at_volume", "gathered_at_rayleigh"});
    o.extra_ghost_width = 1;
  }
  return o;
}

template <int Dim>
std::vector<typename mechanics::DecomposedMpm<Dim>::Particle> scene_particles(
    MPI_Comm comm, const Scene& scene, std::vector<mechanics::ParticleLoad<Dim>>& loads) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::vector<typename mechanics::DecomposedMpm<Dim>::Particle> all;
  std::vector<double> packed;  // per load: particle id, source (loads.point[i], then loads.traction[j]), force
  std::string error;
  if (rank == 0) {
    try {
      // The serial run's own particles, in its order (finalized: grouped by material).
      const auto sim = build_simulation<Dim>(scene);
      const mechanics::Particles<Dim>& p = sim->particles();
      all.resize(p.size());
      for (std::size_t k = 0; k < all.size(); ++k) {
        auto& q = all[k];
        q.id = static_cast<std::int64_t>(k);
        q.mass = p.mass[k];
        q.volume = p.volume[k];
        q.position = p.position[k];
        q.velocity = p.velocity[k];
        q.half_size = p.half_size[k];
        q.stress = p.stress[k];
        q.stress_zz = p.stress_zz[k];
        q.material = p.material[k];
        q.plastic_strain = p.plastic_strain[k];  // the Mie-Grüneisen/J2 state (zeros for other materials)
        q.internal_energy = p.internal_energy[k];
        q.plastic_work = p.plastic_work[k];
        q.scalars = {p.temperature[k], p.temperature[k]};
        if (plastic_heating(scene)) q.scalars.push_back(p.plastic_work[k]);  // as PlasticHeatSource::start
        if (interface_temperature(scene)) q.scalars.push_back(p.temperature[k]);  // T_p before any heat
        if (scene.thermal.enabled && scene.thermal.coupler.reaction.enabled) q.scalars.push_back(0.0);  // fresh
        if (interface_reaction(scene)) q.scalars.insert(q.scalars.end(), {0.0, -1.0});  // fresh, no reading yet
        q.scalars.push_back(static_cast<double>(p.body[k]));
        if (gather_reuse(scene)) q.scalars.insert(q.scalars.end(), Dim + 2, 0.0);  // not gathered yet
      }
      for (const mechanics::ParticleLoad<Dim>& L : sim->particle_loads()) {
        packed.push_back(static_cast<double>(L.particle));
        packed.push_back(static_cast<double>(L.source));
        for (int d = 0; d < Dim; ++d) packed.push_back(L.force[d]);
      }
    } catch (const SceneError& e) {
      error = e.what();
      if (error.empty()) error = "the particles could not be built";
    }
  }
  if (const std::string why = agreed_error(comm, error); !why.empty()) throw SceneError(why);
  // The resolved loads on every rank (each rank applies those of the particles it holds), their time
  // functions from the scene's load of origin.
  long count = static_cast<long>(packed.size());
  MPI_Bcast(&count, 1, MPI_LONG, 0, comm);
  packed.resize(static_cast<std::size_t>(count));
  MPI_Bcast(packed.data(), static_cast<int>(count), MPI_DOUBLE, 0, comm);
  loads.clear();
  const std::size_t points = scene.point_loads.size();
  for (std::size_t a = 0; a + 2 + Dim <= packed.size(); a += 2 + Dim) {
    mechanics::ParticleLoad<Dim> L;
    L.particle = static_cast<std::int64_t>(packed[a]);
    const auto source = static_cast<std::size_t>(packed[a + 1]);
    L.source = static_cast<int>(source);
    for (int d = 0; d < Dim; ++d) L.force[d] = packed[a + 2 + static_cast<std::size_t>(d)];
    L.scale = source < points ? scene.point_loads[source].scale : scene.tractions[source - points].scale;
    loads.push_back(std::move(L));
  }
  return all;
}

#define FRICTHERM_INSTANTIATE_DECOMPOSED_SETUP(D)                                                         \
  template mechanics::Grid<D> scene_grid<D>(const Scene&);                                                \
  template mechanics::DecomposedMpm<D>::Options decomposed_options<D>(const Scene&);                      \
  template std::vector<mechanics::DecomposedMpm<D>::Particle> scene_particles<D>(                \
      MPI_Comm, const Scene&, std::vector<mechanics::ParticleLoad<D>>&);
FRICTHERM_INSTANTIATE_DECOMPOSED_SETUP(2)
FRICTHERM_INSTANTIATE_DECOMPOSED_SETUP(3)
#undef FRICTHERM_INSTANTIATE_DECOMPOSED_SETUP

void write_decomposed_heat_metadata(H5Output& out, const Scene& scene, const DecomposedHeat& heat, double pending,
                                    double particle_reaction_heat, long hotspots_seen) {
  const DecomposedHeatBooks& b = heat.books();
  // The serial EnergyBooks from the books summed over ranks. Without the reuse every matrix-free window
  // gathers its particles afresh (no partial refresh); the assembly residual is the worst of the heat
  // capacity's partition of unity and K·1 = 0 (assembled windows), as the serial Coupler's.
  EnergyBooks e;
  e.work_received = b.work_received;
  e.plastic_work_received = b.plastic_work_received;
  e.plastic_heat_received = b.plastic_heat_received;
  e.heat_delivered = b.heat_delivered;
  e.plastic_heat_delivered = b.plastic_heat_delivered;
  e.reaction_heat_released = b.reaction_heat_released;
  e.heat_relocated = b.heat_relocated;
  e.nodal_energy_change = b.nodal_energy_change;
  e.windows = b.windows;
  e.continuation_intervals = b.continuation_intervals;
  e.steps = b.steps;
  e.min_window = b.min_window;
  e.max_window = b.max_window;
  e.max_assembly_residual = std::max(b.max_capacity_residual, b.max_row_sum_residual);
  e.matrix_free_windows = b.windows - b.assembled_windows;
  e.matrix_free_substeps = b.substeps;
  // With the reuse (gather_reuse) the gathers and refreshes counted as the serial Coupler counts them.
  const bool reuse = gather_reuse(scene);
  e.matrix_free_gathers = reuse ? b.gathers : e.matrix_free_windows;
  e.matrix_free_refreshes = reuse ? b.refreshes : 0;
  write_thermal_metadata(out, ThermalMetadata{scene.thermal.coupler, scene.thermal.heating_order, e,
                                              heat.integrator_stats(),  // global counts
                                              particle_reaction_heat, pending, b.particle_energy_change,
                                              static_cast<std::int64_t>(hotspots_seen)});
  // The decomposed heat's own entries: the Krylov path's preconditioner, its windows, the residual
  // under its own name, the interface temperature's flux histories summed over ranks (= work received).
  out.write_metadata("thermal_preconditioner", scene.thermal.preconditioner);
  out.write_metadata("thermal_assembled_windows", b.assembled_windows);
  out.write_metadata("max_capacity_residual", b.max_capacity_residual);
  if (heat.interface_enabled()) out.write_metadata("interface_heat_recorded", heat.interface_heat_recorded());
}

void print_decomposed_books(std::ostream& log, const DecomposedHeatBooks& b, int ranks) {
  // Relative to the heat received: frictional work plus plastic heat; the energy changes also hold
  // the reaction's heat.
  const double w = b.work_received + b.plastic_heat_received, scale = w != 0.0 ? std::fabs(w) : 1.0;
  const double e = w + b.reaction_heat_released;
  char reaction[96] = "";
  if (b.reaction_heat_released != 0.0)
    std::snprintf(reaction, sizeof reaction, " reaction heat released %.9g J,", b.reaction_heat_released);
  char line[760];
  std::snprintf(line, sizeof line,
                "frictherm: energy books over %d ranks: frictional work received %.9g J, plastic heat received %.9g J, "
                "heat delivered %.9g J,%s nodal energy change %.9g J, particle energy change %.9g J (largest "
                "difference %.2g of the heat received)\n",
                ranks, b.work_received, b.plastic_heat_received, b.heat_delivered,
                reaction,
                b.nodal_energy_change, b.particle_energy_change,
                std::max({std::fabs(b.heat_delivered - w), std::fabs(b.nodal_energy_change - e),
                          std::fabs(b.particle_energy_change - e)}) / scale);
  log << line;
}

void record_decomposed_traffic(MPI_Comm comm, const mechanics::DecomposedTraffic& t, std::size_t local_particles,
                               H5Output* out, std::ostream* log) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const double steps = std::max(1L, t.steps);
  const char* names[] = {"ghost_nodes", "grid_exchange_bytes", "migrated_particles_per_step",
                         "migration_bytes_per_step", "field_entries_per_step", "field_bytes_per_step",
                         "local_particles"};
  double mine[7] = {static_cast<double>(t.ghost_nodes),
                    static_cast<double>(t.ghost_nodes) * t.values_per_node * sizeof(double),
                    (t.particles_sent + t.particles_received) / steps,
                    (t.particles_sent + t.particles_received) * static_cast<double>(t.particle_bytes) / steps,
                    2.0 * t.field_entries_sent / steps,  // sent to the owners and received back
                    2.0 * t.field_entries_sent * static_cast<double>(t.field_entry_bytes) / steps,
                    static_cast<double>(local_particles)};
  double sum[7], max[7];
  MPI_Reduce(mine, sum, 7, MPI_DOUBLE, MPI_SUM, 0, comm);
  MPI_Reduce(mine, max, 7, MPI_DOUBLE, MPI_MAX, 0, comm);
  if (rank != 0) return;
  auto number = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return std::string(buf);
  };
  std::string line = "frictherm: traffic per rank (mean / largest):";
  for (int i = 0; i < 7; ++i) {
    if (out) {
      out->write_metadata(std::string("traffic_") + names[i] + "_mean", sum[i] / size);
      out->write_metadata(std::string("traffic_") + names[i] + "_max", max[i]);
    }
    line += std::string(i ? ", " : " ") + names[i] + " " + number(sum[i] / size) + " / " + number(max[i]);
  }
  if (log) *log << line << "\n";
}

}  // namespace frictherm::coupling::detail
