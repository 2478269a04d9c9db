// Scene parsing: bodies and their shapes (rectangle/box, disk/sphere, ellipse/ellipsoid, annulus,
// polygon, image; ellipse_packing in scene_packing.cpp, grains as materials in scene_grains.cpp), with
// the check that every body lies inside the grid.
#include "scene/scene_detail.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace frictherm::coupling::detail {

// z_range [z0, z1]: required for planar shapes in 3D, not allowed in 2D.
void read_z_range(const JsonReader& shape, int dim, ShapeSpec& out) {
  if (dim == 2) {
    if (const auto z = shape.find("z_range")) z->fail("only for 3D scenes (2D shapes are planar)");
    return;
  }
  const JsonReader z = shape.at("z_range", "[z0, z1], the extrusion of the planar shape in z (m)");
  const auto v = z.as_vector(2);
  if (!(v[1] > v[0])) z.expected("[z0, z1] with z1 > z0");
  out.z_lo = v[0];
  out.z_hi = v[1];
}

namespace {

std::string join_names(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "\"" : ", \"") + n + "\"";
  return out.empty() ? "none" : out;
}

void parse_box(const JsonReader& shape, int dim, ShapeSpec& out) {
  out.type = ShapeType::box;
  out.lo = read_vec(shape.at("lo", "the lower corner"), dim);
  const JsonReader hi = shape.at("hi", "the upper corner");
  out.hi = read_vec(hi, dim);
  for (int d = 0; d < dim; ++d)
    if (!(out.hi[d] > out.lo[d])) hi.expected("every component greater than lo's " + format_vec(out.lo, dim));
  out.box_lo = out.lo;
  out.box_hi = out.hi;
}

void parse_ellipse(const JsonReader& shape, int dim, bool round, ShapeSpec& out) {
  out.type = ShapeType::ellipse;
  out.center = read_vec(shape.at("center", "the centre"), dim);
  if (round) {
    const double r = shape.number("radius", Range::positive());
    for (int d = 0; d < dim; ++d) out.semi_axes[d] = r;
  } else {
    out.semi_axes = read_vec(shape.at("semi_axes", "the semi-axes"), dim, Range::positive());
    if (dim == 2) {
      out.angle = shape.number("angle", 0.0, Range::any());
    } else if (const auto a = shape.find("angle")) {
      a->fail("only for 2D ellipses (3D ellipsoids are axis-aligned)");
    }
  }
  // Tight bounding box of the (rotated) ellipse.
  const double c = std::cos(out.angle), sn = std::sin(out.angle);
  SceneVec half = out.semi_axes;
  if (dim == 2) {
    const double a = out.semi_axes[0], b = out.semi_axes[1];
    half[0] = std::sqrt(a * a * c * c + b * b * sn * sn);
    half[1] = std::sqrt(a * a * sn * sn + b * b * c * c);
  }
  for (int d = 0; d < dim; ++d) {
    out.box_lo[d] = out.center[d] - half[d];
    out.box_hi[d] = out.center[d] + half[d];
  }
}

void parse_annulus(const JsonReader& shape, int dim, ShapeSpec& out) {
  out.type = ShapeType::annulus;
  out.center = read_vec(shape.at("center", "the centre"), dim);
  out.inner_radius = shape.number("inner_radius", Range::non_negative());
  const JsonReader ro = shape.at("outer_radius", "a number > inner_radius");
  out.outer_radius = ro.as_number(Range::positive());
  if (!(out.outer_radius > out.inner_radius))
    ro.expected("a number greater than inner_radius = " + format_number(out.inner_radius));
  for (int d = 0; d < dim; ++d) {
    out.box_lo[d] = out.center[d] - out.outer_radius;
    out.box_hi[d] = out.center[d] + out.outer_radius;
  }
}

void parse_polygon(const JsonReader& shape, int dim, ShapeSpec& out) {
  out.type = ShapeType::polygon;
  const JsonReader verts = shape.at("vertices", "an array of [x, y] points");
  for (const JsonReader& v : verts.elements(3)) {
    const auto p = v.as_vector(2);
    out.vertices.push_back({p[0], p[1]});
  }
  // Vertices on one line (or on one point) enclose nothing, yet the even-odd test would let the
  // lattice points on that line in, each with a full particle's volume.
  const auto& v0 = out.vertices[0];
  const auto& far = *std::max_element(out.vertices.begin(), out.vertices.end(), [&](const auto& a, const auto& b) {
    return std::hypot(a[0] - v0[0], a[1] - v0[1]) < std::hypot(b[0] - v0[0], b[1] - v0[1]);
  });
  const double dx = far[0] - v0[0], dy = far[1] - v0[1], span2 = dx * dx + dy * dy;
  bool flat = true;
  for (const auto& q : out.vertices)
    flat = flat && std::fabs(dx * (q[1] - v0[1]) - dy * (q[0] - v0[0])) <= 1e-12 * span2;
  if (flat) verts.fail("expected a polygon that encloses an area, but its vertices lie on one line");
  read_z_range(shape, dim, out);
  out.box_lo = {out.vertices[0][0], out.vertices[0][1], out.z_lo};
  out.box_hi = {out.vertices[0][0], out.vertices[0][1], out.z_hi};
  for (const auto& p : out.vertices)
    for (int d = 0; d < 2; ++d) {
      out.box_lo[d] = std::min(out.box_lo[d], p[d]);
      out.box_hi[d] = std::max(out.box_hi[d], p[d]);
    }
}

void parse_image(const JsonReader& shape, Scene& s, ParseContext& ctx, ShapeSpec& out) {
  out.type = ShapeType::image;
  const JsonReader file = shape.at("file", "the path of a PGM, BMP, PNG or TIFF image, relative to the scene file");
  const std::string rel = file.as_string();
  if (rel.empty()) file.expected("a file name");
  out.image_file = (rel[0] == '/' || ctx.base_dir.empty()) ? rel : ctx.base_dir + "/" + rel;
  try {
    out.image = mechanics::read_grey_image(out.image_file);
  } catch (const std::exception& e) {
    file.fail(e.what());
  }
  const auto origin = shape.at("origin", "[x, y], the image's lower-left corner (m)").as_vector(2);
  out.origin = {origin[0], origin[1]};
  out.pixel_size = shape.number("pixel_size", Range::positive());
  const JsonReader levels = shape.at("levels", "an array of {\"range\": [g0, g1], \"material\": NAME}");
  std::vector<LevelSplit> splits;
  for (const JsonReader& l : levels.elements(1)) {
    const JsonReader range = l.at("range", "[g0, g1], grey levels");
    if (!range.is_array() || range.json().size() != 2) range.expected("[g0, g1], two grey levels");
    const auto g = range.elements();
    mechanics::GreyLevelMaterial level;
    level.min_level = static_cast<int>(g[0].as_integer(0, out.image.max_value));
    level.max_level = static_cast<int>(g[1].as_integer(level.min_level, out.image.max_value));
    level.material = ctx.material_id(l.at("material", "a material name"));
    if (const auto split = l.find("split")) {  // each connected grain / each grey level its own material
      LevelSplit sp{out.levels.size(), split->as_choice({"grains", "grey_levels"}) == "grey_levels",
                    mechanics::Connectivity::eight, l};
      if (const auto c = l.find("connectivity")) {
        if (sp.by_grey_level) c->fail("only for \"split\": \"grains\"");
        const long v = c->as_integer(4, 8);
        if (v != 4 && v != 8) c->expected("4 or 8 (neighbours sharing an edge, or an edge or a corner)");
        sp.connectivity = v == 4 ? mechanics::Connectivity::four : mechanics::Connectivity::eight;
      }
      if (s.materials[static_cast<std::size_t>(level.material)].is_rigid())
        split->fail("grains of a rigid material cannot be split (expected a deformable material)");
      splits.push_back(sp);
    } else if (const auto c = l.find("connectivity")) {
      c->fail("only with \"split\": \"grains\"");
    }
    l.finish();
    out.levels.push_back(level);
  }
  read_z_range(shape, ctx.dim, out);
  if (!splits.empty()) split_image_levels(splits, s, ctx, out);
  out.box_lo = {out.origin[0], out.origin[1], out.z_lo};
  out.box_hi = {out.origin[0] + out.image.width * out.pixel_size, out.origin[1] + out.image.height * out.pixel_size,
                out.z_hi};
}

ShapeSpec parse_shape(const JsonReader& shape, Scene& s, ParseContext& ctx) {
  const std::string type =
      shape.at("type", "the shape's type").as_choice({"rectangle", "box", "disk", "sphere", "ellipse", "ellipsoid",
                                                      "annulus", "polygon", "image", "ellipse_packing"});
  ShapeSpec out;
  if (type == "rectangle" || type == "box") parse_box(shape, ctx.dim, out);
  else if (type == "disk" || type == "sphere") parse_ellipse(shape, ctx.dim, /*round=*/true, out);
  else if (type == "ellipse" || type == "ellipsoid") parse_ellipse(shape, ctx.dim, /*round=*/false, out);
  else if (type == "annulus") parse_annulus(shape, ctx.dim, out);
  else if (type == "polygon") parse_polygon(shape, ctx.dim, out);
  else if (type == "image") parse_image(shape, s, ctx, out);
  else parse_ellipse_packing(shape, s, ctx, out);  // scene_packing.cpp
  shape.finish();
  return out;
}

void check_inside_grid(const JsonReader& shape, const ShapeSpec& spec, const Scene& s) {
  const int dim = s.dimension;
  for (int d = 0; d < dim; ++d) {
    const double tol = 1e-9 * (s.grid_hi[d] - s.grid_lo[d]);
    if (spec.box_lo[d] < s.grid_lo[d] - tol || spec.box_hi[d] > s.grid_hi[d] + tol)
      shape.fail("the body's bounding box " + format_vec(spec.box_lo, dim) + " to " + format_vec(spec.box_hi, dim) +
                 " m is not inside the grid " + format_vec(s.grid_lo, dim) + " to " + format_vec(s.grid_hi, dim) +
                 " m");
  }
}

}  // namespace

void parse_bodies(const JsonReader& root, Scene& s, ParseContext& ctx) {
  const JsonReader bodies = root.at("bodies", "an array of bodies");
  for (const JsonReader& b : bodies.elements(1)) {
    if (!b.is_object()) b.expected("an object describing a body");
    BodySpec body;
    const std::size_t index = s.bodies.size();
    const auto name = b.find("name");
    body.name = name ? name->as_string() : "body" + std::to_string(index);
    if (name) check_result_name(*name, body.name, "body");
    const auto same = std::find(ctx.body_names.begin(), ctx.body_names.end(), body.name);
    if (same != ctx.body_names.end())
      (name ? *name : b).fail("the name \"" + body.name + "\" is already used by bodies[" +
                              std::to_string(same - ctx.body_names.begin()) + "]");
    const JsonReader shape = b.at("shape", "an object with the body's shape");
    body.shape = parse_shape(shape, s, ctx);
    const bool image = body.shape.type == ShapeType::image;
    if (image) {
      if (const auto m = b.find("material"))
        m->fail("not allowed for an image body or an ellipse_packing body (the shape chooses the materials)");
    } else {
      body.material = ctx.material_id(b.at("material", "the name of a material"));
    }
    const auto ppc = b.find("particles_per_cell");
    body.particles_per_cell = ppc ? static_cast<int>(ppc->as_integer(1, 10)) : 2;
    if (!s.bodies.empty() && body.particles_per_cell != s.bodies.front().particles_per_cell)
      (ppc ? *ppc : b).fail("every body must use the same particles_per_cell; bodies[0] uses " +
                            std::to_string(s.bodies.front().particles_per_cell) + ", this one " +
                            std::to_string(body.particles_per_cell));
    if (const auto v = b.find("velocity")) {
      if (!image && s.materials[static_cast<std::size_t>(body.material)].is_rigid())
        v->fail("not allowed for a body of rigid material \"" + ctx.material_names[static_cast<std::size_t>(body.material)] +
                "\": it moves with the material's velocity");
      body.velocity = read_vec(*v, s.dimension);
    }
    body.temperature = b.number("temperature", 293.15, Range::positive());
    b.finish();
    check_inside_grid(shape, body.shape, s);
    ctx.body_names.push_back(body.name);
    s.bodies.push_back(std::move(body));
  }
}

int ParseContext::material_id(const JsonReader& name) const {
  const std::string n = name.as_string();
  const auto it = std::find(material_names.begin(), material_names.end(), n);
  if (it == material_names.end())
    name.fail("unknown material " + describe_json(name.json()) + " (materials defined: " + join_names(material_names) + ")");
  return static_cast<int>(it - material_names.begin());
}

int ParseContext::body_id(const JsonReader& name) const {
  const std::string n = name.as_string();
  const auto it = std::find(body_names.begin(), body_names.end(), n);
  if (it == body_names.end()) name.fail("unknown body \"" + n + "\" (bodies defined: " + join_names(body_names) + ")");
  return static_cast<int>(it - body_names.begin());
}

SceneVec read_vec(const JsonReader& value, int dim, const Range& range) {
  const auto v = value.as_vector(static_cast<std::size_t>(dim), range);
  SceneVec out{};
  for (int d = 0; d < dim; ++d) out[d] = v[static_cast<std::size_t>(d)];
  return out;
}

void check_result_name(const JsonReader& where, const std::string& name, const char* what) {
  if (name.empty()) where.fail(std::string(what) + " names must not be empty");
  if (name.find('/') != std::string::npos)
    where.fail(std::string(what) + " names must not contain '/' (they name columns of the HDF5 results), got \"" +
               name + "\"");
}

std::string format_vec(const SceneVec& v, int dim) {
  std::string out = "(";
  for (int d = 0; d < dim; ++d) out += (d ? ", " : "") + format_number(v[d]);
  return out + ")";
}

}  // namespace frictherm::coupling::detail
