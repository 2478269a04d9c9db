// The human-readable summary `frictherm validate` prints.
#include "scene/scene_detail.hpp"

#include <frictherm/coupling/decomposed_support.hpp>
#include <frictherm/mechanics/mie_gruneisen.hpp>

#include <cmath>
#include <iomanip>
#include <ostream>
#include <sstream>

namespace frictherm::coupling {

namespace {

std::string g(double x) { return format_number(x); }

const char* shape_name(ShapeType t, int dim) {
  switch (t) {
    case ShapeType::box: return dim == 2 ? "rectangle" : "box";
    case ShapeType::ellipse: return dim == 2 ? "ellipse" : "ellipsoid";
    case ShapeType::annulus: return dim == 2 ? "annulus" : "spherical shell";
    case ShapeType::polygon: return dim == 2 ? "polygon" : "extruded polygon";
    case ShapeType::image: return dim == 2 ? "image" : "extruded image";
  }
  return "?";
}

template <int Dim>
void describe(const Scene& s, std::ostream& out) {
  const auto sim = build_simulation<Dim>(s);
  const auto& grid = sim->grid();
  const auto& p = sim->particles();
  // As the run's thermal start (thermal_assembly.cpp) refuses it, so that validate says it first.
  if (s.thermal.enabled) {
    const auto& props = s.thermal.coupler.materials;
    bool heated = false;
    for (std::size_t k = 0; k < p.size() && !heated; ++k) {
      const auto m = static_cast<std::size_t>(p.material[k]);
      heated = m < props.size() && props[m].conducts && p.mass[k] > 0.0;
    }
    if (!heated)
      throw SceneError("thermal.materials: no particle has a material with thermal properties (heat_capacity, "
                       "conductivity); expected at least one body of a listed material");
  }
  auto row = [&out](const std::string& label) -> std::ostream& {
    return out << std::left << std::setw(12) << label << ' ';
  };
  row("scene") << s.source << (s.description.empty() ? "" : "  (" + s.description + ")") << '\n';
  row("dimension") << Dim;
  if (Dim == 2)
    out << " (" << (s.options.analysis == mechanics::Analysis::plane_stress ? "plane stress" : "plane strain")
        << ", thickness " << g(s.options.thickness) << " m)";
  out << '\n';
  std::string cells, h;
  for (int d = 0; d < Dim; ++d) {
    cells += (d ? " x " : "") + std::to_string(grid.cells()[static_cast<std::size_t>(d)]);
    h += (d ? " x " : "") + g(grid.cell_size()[d]);
  }
  row("grid") << detail::format_vec(s.grid_lo, Dim) << " to " << detail::format_vec(s.grid_hi, Dim) << " m, "
              << cells << " cells of " << h << " m, " << grid.node_count() << " nodes (ghosts included)\n";
  row("solver") << mechanics::to_string(s.options.shape) << " shape functions, " << mechanics::to_string(s.options.scheme)
                << " update, CFL " << g(s.options.cfl);
  if (std::isfinite(s.options.max_time_step)) out << ", max time step " << g(s.options.max_time_step) << " s";
  out << '\n';
  // Grain copies ("hmx#1", "hmx#2", ...) of one template are listed as one line.
  auto grain_template = [&s](std::size_t m) {
    const std::string& n = s.materials[m].name;
    const std::size_t hash = n.rfind('#');
    return hash == std::string::npos ? std::string() : n.substr(0, hash);
  };
  for (std::size_t m = 0; m < s.materials.size(); ++m) {
    const auto& mat = s.materials[m];
    const std::string tmpl = grain_template(m);
    std::size_t last = m;
    while (!tmpl.empty() && last + 1 < s.materials.size() && grain_template(last + 1) == tmpl) ++last;
    auto& line = row(m == 0 ? "materials" : "");
    if (last > m)
      line << m << "-" << last << " " << mat.name << " ... " << s.materials[last].name << ": " << last - m + 1
           << " grains of " << tmpl << ", ";
    else
      line << m << " " << mat.name << ": ";
    out << mechanics::to_string(mat.kind) << ", density " << g(mat.density) << " kg/m^3";
    if (mat.kind == mechanics::MaterialKind::mie_gruneisen) {
      const auto& mg = mat.mie_gruneisen;
      out << ", C0 " << g(mg.C0) << " m/s, S1 " << g(mg.S1) << ", gamma0 " << g(mg.gamma0) << ", G " << g(mg.shear_modulus)
          << " Pa";
      if (mg.yield_stress > 0.0 && std::isfinite(mg.yield_stress)) out << ", yield " << g(mg.yield_stress) << " Pa";
      out << ", wave speed " << g(mechanics::mie_gruneisen_wave_speed(mg, 1.0, 0.0)) << " m/s";
    } else if (!mat.is_rigid()) {
      out << ", E " << g(mat.youngs_modulus) << " Pa, nu " << g(mat.poisson_ratio) << ", wave speed "
          << g(mat.p_wave_speed(s.options.analysis)) << " m/s";
    }
    out << '\n';
    m = last;
  }
  for (std::size_t b = 0; b < sim->bodies().size(); ++b) {
    const BodySpec& spec = s.bodies[b];
    row(b == 0 ? "bodies" : "") << b << " " << spec.name << ": " << shape_name(spec.shape.type, Dim) << ", "
                                << (spec.material >= 0 ? s.materials[static_cast<std::size_t>(spec.material)].name
                                    : spec.shape.generated
                                        ? "ellipse packing of " + std::to_string(spec.shape.grain_count) +
                                              " grains, area fraction " + g(spec.shape.fraction)
                                    : spec.shape.pixel_materials.width > 0 ? std::string("a material per grain")
                                                                           : std::string("materials by grey level"))
                                << ", " << sim->bodies()[b].particle_count << " particles\n";
  }
  row("particles") << p.size() << " (" << s.bodies.front().particles_per_cell << " per cell per direction)\n";
  row("loads") << s.fixed_faces.size() << " fixed faces, " << s.point_loads.size() << " point loads, "
               << s.tractions.size() << " tractions";
  if (s.options.gravity.squaredNorm() > 0.0) out << ", gravity";
  out << '\n';
  const double dt = sim->stable_time_step();
  row("time step") << g(dt) << " s (stable at t = 0)\n";
  if (std::isfinite(dt) && dt > 0.0) {
    const double steps = std::ceil(s.end_time / dt);
    row("steps") << "about " << g(steps) << " to end_time " << g(s.end_time) << " s";
    if (s.max_steps > 0 && steps > static_cast<double>(s.max_steps))
      out << " (more than max_steps " << s.max_steps << ": the run will stop early)";
    out << '\n';
  }
  const SceneCost& c = s.cost;
  row("estimate") << "at most " << g(c.particles) << " particles, " << g(c.grid_nodes) << " grid nodes, "
                  << g(c.threads) << " thread(s): about " << g(std::round(c.memory_bytes / 1e6)) << " MB of memory (limit "
                  << g(std::round(c.memory_limit / 1e6)) << " MB, " << c.memory_limit_source << "), "
                  << g(c.steps) << " steps, " << g(std::round(c.output_bytes / 1e6)) << " MB of snapshots\n";
  const double snaps = std::ceil(s.end_time / s.output.snapshot_interval - 1e-9) + 1.0;
  row("output") << s.output.file << ": " << g(snaps) << " snapshots, series "
                << (s.output.series_interval > 0.0 ? "every " + g(s.output.series_interval) + " s" : std::string("every step"))
                << '\n';
  const std::string refusal = decomposed_run_refusal(s);  // "KEY: VALUE is not supported ...; the serial run ..."
  row("mpirun") << (refusal.empty() ? "mpirun -n K frictherm run decomposes it (docs/distributed_run.md)"
                                     : "serial only (" + refusal.substr(0, refusal.find("; the serial run")) + ")")
                << '\n';
}

}  // namespace

void describe_scene(const Scene& scene, std::ostream& out) {
  if (scene.dimension == 2)
    describe<2>(scene, out);
  else
    describe<3>(scene, out);
}

}  // namespace frictherm::coupling
