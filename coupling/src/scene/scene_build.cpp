// From a parsed Scene to a finalized mechanics::Simulation<Dim>, and the `validate` summary.
#include "scene/scene_detail.hpp"

#include <cmath>
#include <ostream>

namespace frictherm::coupling {

namespace {

using detail::to_vec;

template <int Dim>
std::unique_ptr<mechanics::Region<Dim>> make_region(const ShapeSpec& s, int material) {
  switch (s.type) {
    case ShapeType::box: return mechanics::make_box<Dim>(to_vec<Dim>(s.lo), to_vec<Dim>(s.hi), material);
    case ShapeType::ellipse:
      return mechanics::make_ellipse<Dim>(to_vec<Dim>(s.center), to_vec<Dim>(s.semi_axes), s.angle, material);
    case ShapeType::annulus:
      return mechanics::make_annulus<Dim>(to_vec<Dim>(s.center), s.inner_radius, s.outer_radius, material);
    case ShapeType::polygon: {
      std::vector<mechanics::Vec<2>> v;
      for (const auto& p : s.vertices) v.emplace_back(p[0], p[1]);
      return mechanics::make_polygon<Dim>(v, s.z_lo, s.z_hi, material);
    }
    case ShapeType::image:
      if (s.pixel_materials.width > 0)  // a material per pixel (grains split into materials, ellipse_packing)
        return mechanics::make_pixel_region<Dim>(s.pixel_materials, mechanics::Vec<2>(s.origin[0], s.origin[1]),
                                                 s.pixel_size, s.z_lo, s.z_hi);
      return mechanics::make_image_region<Dim>(s.image, mechanics::Vec<2>(s.origin[0], s.origin[1]), s.pixel_size,
                                               s.levels, s.z_lo, s.z_hi);
  }
  throw std::logic_error("unknown shape type");
}

}  // namespace

template <int Dim>
std::unique_ptr<mechanics::Simulation<Dim>> build_simulation(const Scene& scene) {
  if (scene.dimension != Dim)
    throw std::logic_error("build_simulation<" + std::to_string(Dim) + "> called for a " +
                           std::to_string(scene.dimension) + "D scene");
  mechanics::IVec<Dim> cells{};
  for (int d = 0; d < Dim; ++d) cells[static_cast<std::size_t>(d)] = scene.cells[static_cast<std::size_t>(d)];
  const mechanics::Grid<Dim> grid(to_vec<Dim>(scene.grid_lo), to_vec<Dim>(scene.cell_size), cells);
  auto sim = std::make_unique<mechanics::Simulation<Dim>>(grid, scene.options);
  // The parser has already checked what the mechanics checks again; its messages get the key path.
  for (const auto& m : scene.materials) {
    try {
      sim->add_material(m);
    } catch (const std::invalid_argument& e) {
      throw SceneError("materials." + m.name + ": " + e.what());
    }
  }
  if (scene.contact.enabled) {
    sim->enable_contact(scene.contact.options);
    for (const ContactPairSpec& p : scene.contact.pairs) sim->set_contact_pair(p.material_a, p.material_b, p.settings);
  }
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const BodySpec& b = scene.bodies[i];
    const std::string path = "bodies[" + std::to_string(i) + "]";
    try {
      const auto region = make_region<Dim>(b.shape, b.material);
      sim->add_body(b.name, *region, b.particles_per_cell, to_vec<Dim>(b.velocity), b.temperature);
    } catch (const std::invalid_argument& e) {
      throw SceneError(path + ": " + e.what());
    }
  }
  for (const auto& f : scene.fixed_faces) sim->fix_face(f);
  try {
    sim->finalize();  // sets up penalty contact: its pairs and the bodies' boundary points
  } catch (const std::invalid_argument& e) {
    throw SceneError(std::string("contact: ") + e.what());
  }
  // Loads are added one by one after finalize() so that a load selecting no particle is named.
  for (std::size_t i = 0; i < scene.point_loads.size(); ++i) {
    const PointLoadSpec& p = scene.point_loads[i];
    mechanics::PointLoad<Dim> load;
    load.body = p.body;
    load.point = to_vec<Dim>(p.point);
    load.use_box = p.use_box;
    load.box_lo = to_vec<Dim>(p.box_lo);
    load.box_hi = to_vec<Dim>(p.box_hi);
    load.force = to_vec<Dim>(p.force);
    load.scale = p.scale;
    try {
      sim->add_point_load(load);
    } catch (const std::invalid_argument& e) {
      throw SceneError("loads.point[" + std::to_string(i) + "]: " + e.what() +
                       (p.use_box ? " (no particle of the body lies in the box)" : ""));
    }
  }
  for (std::size_t i = 0; i < scene.tractions.size(); ++i) {
    const TractionSpec& t = scene.tractions[i];
    mechanics::EdgeTraction<Dim> load;
    load.body = t.body;
    load.axis = t.axis;
    load.upper = t.upper;
    load.traction = to_vec<Dim>(t.traction);
    load.scale = t.scale;
    try {
      sim->add_edge_traction(load);
    } catch (const std::invalid_argument& e) {
      throw SceneError("loads.traction[" + std::to_string(i) + "]: " + e.what());
    }
  }
  return sim;
}

template std::unique_ptr<mechanics::Simulation<2>> build_simulation<2>(const Scene&);
template std::unique_ptr<mechanics::Simulation<3>> build_simulation<3>(const Scene&);

}  // namespace frictherm::coupling
