// Scene parsing: the "ellipse_packing" shape, a seeded random packing of elliptical grains in a
// binder (the PBX specimen of Nairn, Bardenhagen & Smith 2018, section 3 and figure 8), generated
// while parsing and then handled as an image body; and writing the image a run used.
#include <frictherm/coupling/microstructure.hpp>
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/mechanics/ellipse_packing.hpp>

#include "scene/scene_detail.hpp"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace frictherm::coupling {

namespace detail {

namespace {

constexpr double kMaxPackedGrains = 1e6;              // grains of one packing
constexpr std::size_t kMaxPackedGrainMaterials = 2000;  // with separate_grains (the scenes' material limit)

/// major_axis: {"distribution": "uniform", "min", "max"} or {"distribution": "lognormal", "median",
/// "sigma", "min", "max"} (m; the log-normal truncated to [min, max], default median e^{∓3 sigma}).
void parse_major_axis(const JsonReader& m, mechanics::EllipsePackingOptions& o) {
  if (!m.is_object())
    m.expected("{\"distribution\": \"uniform\", \"min\": m, \"max\": m} or {\"distribution\": \"lognormal\", "
               "\"median\": m, \"sigma\": s}");
  const bool lognormal = m.choice("distribution", {"uniform", "lognormal"}) == "lognormal";
  if (lognormal) {
    o.size_distribution = mechanics::SizeDistribution::lognormal;
    o.major_median = m.number("median", Range::positive());
    o.major_sigma = m.number("sigma", Range::closed(0.0, 3.0));
    o.major_min = m.number("min", o.major_median * std::exp(-3.0 * o.major_sigma), Range::positive());
    o.major_max = m.number("max", o.major_median * std::exp(3.0 * o.major_sigma), Range::positive());
  } else {
    o.size_distribution = mechanics::SizeDistribution::uniform;
    o.major_min = m.number("min", Range::positive());
    o.major_max = m.number("max", Range::positive());
  }
  if (!(o.major_max >= o.major_min))
    m.fail("expected max >= min, got min = " + format_number(o.major_min) + ", max = " + format_number(o.major_max));
  if (lognormal && !(o.major_median >= o.major_min && o.major_median <= o.major_max))
    m.fail("expected min <= median <= max");
  m.finish();
}

void parse_aspect_and_orientation(const JsonReader& shape, mechanics::EllipsePackingOptions& o) {
  if (const auto r = shape.find("aspect_ratio")) {  // minor / major axis: a number or [lo, hi]
    if (r->is_number()) {
      o.aspect_min = o.aspect_max = r->as_number(Range::left_open(0.0, 1.0));
    } else {
      const auto v = r->as_vector(2, Range::left_open(0.0, 1.0));
      if (!(v[1] >= v[0])) r->expected("[lo, hi] with 0 < lo <= hi <= 1 (minor over major axis)");
      o.aspect_min = v[0];
      o.aspect_max = v[1];
    }
  }
  if (const auto a = shape.find("orientation")) {
    if (a->is_string()) {
      a->as_choice({"random"});
    } else if (a->is_number()) {
      o.random_orientation = false;
      o.orientation = a->as_number();
    } else {
      a->expected("\"random\" or an angle of the major axes from x (rad)");
    }
  }
}

}  // namespace

void parse_ellipse_packing(const JsonReader& shape, Scene& s, ParseContext& ctx, ShapeSpec& out) {
  out.type = ShapeType::image;
  out.generated = true;
  const auto origin = shape.at("origin", "[x, y], the packed rectangle's lower-left corner (m)").as_vector(2);
  out.origin = {origin[0], origin[1]};
  const JsonReader size_r = shape.at("size", "[width, height] of the packed rectangle (m)");
  const auto size = size_r.as_vector(2, Range::positive());
  out.pixel_size = shape.number("pixel_size", Range::positive());
  for (int d = 0; d < 2; ++d) {
    const double n = size[static_cast<std::size_t>(d)] / out.pixel_size;
    if (std::fabs(n - std::round(n)) > 1e-6 * std::max(1.0, n) || std::round(n) < 1.0)
      size_r.fail("expected a whole number of pixels of pixel_size = " + format_number(out.pixel_size) + " m, got " +
                  format_number(n) + (d == 0 ? " across" : " up"));
  }
  if (!(size[0] / out.pixel_size * size[1] / out.pixel_size <= mechanics::kMaxImagePixels))  // image.hpp
    size_r.fail("expected at most 25e6 pixels of pixel_size, got " +
                format_number(size[0] / out.pixel_size * size[1] / out.pixel_size));
  // Inside the grid, checked before anything is generated (a rectangle far larger than the grid
  // would otherwise be packed first).
  for (int d = 0; d < 2; ++d) {
    const double tol = 1e-9 * (s.grid_hi[d] - s.grid_lo[d]);
    if (out.origin[d] < s.grid_lo[d] - tol || out.origin[d] + size[static_cast<std::size_t>(d)] > s.grid_hi[d] + tol)
      size_r.fail("the packed rectangle [" + format_number(out.origin[0]) + ", " + format_number(out.origin[1]) + "] to [" +
                  format_number(out.origin[0] + size[0]) + ", " + format_number(out.origin[1] + size[1]) +
                  "] m is not inside the grid (" + format_number(s.grid_lo[0]) + ", " + format_number(s.grid_lo[1]) +
                  ") to (" + format_number(s.grid_hi[0]) + ", " + format_number(s.grid_hi[1]) + ") m");
  }
  mechanics::EllipsePackingOptions o;
  o.width = size[0];
  o.height = size[1];
  o.seed = static_cast<std::uint64_t>(shape.at("seed", "an integer >= 0 (the random seed)").as_integer(0));
  const JsonReader fraction = shape.at("fraction", "the grains' target area fraction, in (0, 0.9)");
  o.fraction = fraction.as_number(Range::open(0.0, 0.9));
  const JsonReader major = shape.at("major_axis", "the distribution of the grains' major axis (full length, m)");
  parse_major_axis(major, o);
  parse_aspect_and_orientation(shape, o);
  // Sizes are drawn while a grain brings the total nearer the target: the fraction is off by up to
  // half the largest grain's area over the rectangle, which is more than 1 % in small specimens.
  const double largest = 0.125 * 3.14159265358979323846 * o.major_max * o.major_max * o.aspect_max / (o.width * o.height);
  const double tolerance = shape.number("fraction_tolerance", std::max(0.01, largest), Range::open(0.0, 1.0));
  o.gap = shape.number("gap", 0.0, Range::non_negative());
  o.edge_gap = shape.number("edge_gap", o.gap, Range::non_negative());
  const auto periodic = shape.find("periodic");
  o.periodic = periodic && periodic->as_bool();
  o.max_attempts = shape.integer("max_attempts", o.max_attempts, 1, 100000000);
  if (o.periodic && o.major_max + o.gap > 0.5 * std::min(o.width, o.height))
    periodic->fail("a periodic packing needs major_axis max + gap <= half the rectangle's smaller side (" +
                   format_number(0.5 * std::min(o.width, o.height)) + " m)");
  if (!o.periodic && o.major_min + 2.0 * o.edge_gap > std::min(o.width, o.height))
    major.fail("the smallest grain (min + 2 edge_gap = " + format_number(o.major_min + 2.0 * o.edge_gap) +
               " m) does not fit in the rectangle");
  const auto separate = shape.find("separate_grains");
  const bool separate_grains = !separate || separate->as_bool();
  {
    // The fewest grains the target fraction can take (every grain as large as major_axis max and
    // aspect_ratio allow), bounded before generation: packing time and memory grow with it.
    const double largest_area = 0.25 * 3.14159265358979323846 * o.major_max * o.major_max * o.aspect_max;
    const double fewest = std::floor(o.fraction * o.width * o.height / largest_area);
    const double limit = separate_grains ? static_cast<double>(kMaxPackedGrainMaterials) : kMaxPackedGrains;
    if (fewest > limit)
      major.fail("the target fraction needs at least " + format_number(fewest) + " grains of at most " +
                 format_number(o.major_max) + " m; expected at most " + format_number(limit) +
                 (separate_grains ? " (one material per grain; set \"separate_grains\": false for more)" : "") +
                 ": larger grains, a smaller rectangle or a smaller fraction");
  }
  const JsonReader grain_r = shape.at("grain_material", "the material of the grains (a name in \"materials\")");
  const int grain = ctx.material_id(grain_r);
  if (s.materials[static_cast<std::size_t>(grain)].is_rigid()) grain_r.fail("expected a deformable material");
  const auto binder_r = shape.find("binder_material");
  const int binder = binder_r ? ctx.material_id(*binder_r) : -1;
  const bool labels_grey = shape.choice("image_grey", {"labels", "binary"}, "labels") == "labels";
  out.write_image = shape.string("write_image", "");
  read_z_range(shape, ctx.dim, out);

  mechanics::EllipsePacking packing;
  mechanics::GrainLabels labels;
  try {
    packing = mechanics::generate_ellipse_packing(o);
    labels = mechanics::rasterise_packing(packing, out.pixel_size);
    out.image = mechanics::packing_image(labels, labels_grey ? mechanics::GrainGrey::labels : mechanics::GrainGrey::binary);
  } catch (const std::invalid_argument& e) {
    shape.fail(e.what());
  }
  out.grain_count = packing.grains.size();
  out.target_fraction = o.fraction;
  out.fraction = packing.fraction;
  if (std::fabs(packing.fraction - o.fraction) > tolerance)
    fraction.fail("the packing reached a grain fraction of " + format_number(packing.fraction) + " (" +
                  std::to_string(packing.grains.size()) + " grains placed, " + std::to_string(packing.dropped) +
                  " given up after max_attempts), not within fraction_tolerance = " + format_number(tolerance) +
                  " of " + format_number(o.fraction) +
                  "; expected a smaller fraction or gap, a wider size range, a larger max_attempts or fraction_tolerance");
  // Materials: binder pixels one material, each grain its own copy of grain_material (or all one).
  std::vector<int> material_of_label(packing.grains.size() + 1, grain);
  material_of_label[0] = binder;
  if (separate_grains) {
    std::size_t existing = 0;  // grains of this material in earlier bodies: numbering continues
    for (int t : ctx.grain_template) existing += t == grain;
    const std::string base = s.materials[static_cast<std::size_t>(grain)].name;  // a copy: materials grow below
    for (std::size_t k = 1; k < material_of_label.size(); ++k)
      material_of_label[k] = add_grain_material(s, ctx, grain, base + "#" + std::to_string(existing + k), grain_r);
  }
  out.pixel_materials.width = labels.width;
  out.pixel_materials.height = labels.height;
  out.pixel_materials.material.resize(labels.label.size());
  for (std::size_t k = 0; k < labels.label.size(); ++k)
    out.pixel_materials.material[k] = material_of_label[static_cast<std::size_t>(labels.label[k])];
  out.box_lo = {out.origin[0], out.origin[1], out.z_lo};
  out.box_hi = {out.origin[0] + size[0], out.origin[1] + size[1], out.z_hi};
}

}  // namespace detail

std::string generated_image_path(const Scene& scene, std::size_t body, const std::string& output_file) {
  const BodySpec& b = scene.bodies.at(body);
  if (!b.shape.write_image.empty()) return b.shape.write_image;
  std::string stem = output_file;
  const std::size_t slash = stem.find_last_of('/');
  const std::size_t dot = stem.find_last_of('.');
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash + 1)) stem.erase(dot);
  return stem + "_" + b.name + ".pgm";
}

void write_generated_image(const Scene& scene, std::size_t body, const std::string& path) {
  const BodySpec& b = scene.bodies.at(body);
  if (!b.shape.generated) throw std::invalid_argument("body \"" + b.name + "\" has no generated image");
  // Written under a temporary name and renamed, so a reader never sees half an image.
  const std::string temporary = temporary_path(path);
  try {
    mechanics::write_pgm(b.shape.image, temporary,
                       "frictherm ellipse_packing of body " + b.name + " in " + scene.source + ": " +
                           std::to_string(b.shape.grain_count) + " grains, fraction " + format_number(b.shape.fraction) +
                           " (target " + format_number(b.shape.target_fraction) + "), pixel " +
                           format_number(b.shape.pixel_size) + " m, lower-left corner (" +
                           format_number(b.shape.origin[0]) + ", " + format_number(b.shape.origin[1]) + ") m");
    publish_file(temporary, path, true);
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
}

std::vector<std::string> write_generated_images(const Scene& scene, const std::string& output_file) {
  std::vector<std::string> written;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    if (!scene.bodies[i].shape.generated) continue;
    written.push_back(generated_image_path(scene, i, output_file));
    write_generated_image(scene, i, written.back());
  }
  return written;
}

}  // namespace frictherm::coupling
