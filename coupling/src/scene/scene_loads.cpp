// Scene parsing: boundary conditions, loads and time functions.
#include "scene/scene_detail.hpp"

#include <algorithm>
#include <cmath>

namespace frictherm::coupling {

using mechanics::TimeFunction;

TimeFunction parse_time_function(const JsonReader& f) {
  if (f.is_number()) return TimeFunction::constant(f.as_number());
  if (!f.is_object())
    f.expected("a time function: a number or an object {\"type\": \"constant\"|\"ramp\"|\"sinusoid\"|\"table\", ...}");
  const std::string type =
      f.at("type", "\"constant\", \"ramp\", \"sinusoid\" or \"table\"").as_choice({"constant", "ramp", "sinusoid", "table"});
  TimeFunction out = TimeFunction::constant(0.0);
  if (type == "constant") {
    out = TimeFunction::constant(f.number("value", Range::any()));
  } else if (type == "ramp") {
    const double value = f.number("value", Range::any());
    const double duration = f.number("duration", Range::non_negative());
    const double start = f.number("start", 0.0, Range::non_negative());
    out = TimeFunction::ramp(value, duration, start);
  } else if (type == "sinusoid") {
    const double amplitude = f.number("amplitude", Range::any());
    const bool has_omega = f.has("omega"), has_period = f.has("period");
    if (has_omega == has_period) f.fail("expected exactly one of omega (rad/s) or period (s)");
    constexpr double pi = 3.14159265358979323846;  // a local: heat/hotspots.cpp has a kPi in the same unity batch
    const double omega =
        has_omega ? f.number("omega", Range::any()) : 2.0 * pi / f.number("period", Range::positive());
    const double start = f.number("start", 0.0, Range::non_negative());
    double end = -1.0;
    if (const auto e = f.find("end")) {
      end = e->as_number(Range::non_negative());
      if (!(end > start)) e->expected("a time after start = " + format_number(start));
    }
    out = TimeFunction::sinusoid(amplitude, omega, start, end);
  } else {
    const JsonReader times_r = f.at("times", "an array of times (s)");
    const auto times = times_r.as_number_list(1);
    const JsonReader values_r = f.at("values", "an array of values, one per time");
    const auto values = values_r.as_number_list(1);
    if (values.size() != times.size())
      values_r.expected("an array of " + std::to_string(times.size()) + " numbers (one per time)");
    if (!std::is_sorted(times.begin(), times.end())) times_r.expected("times in non-decreasing order");
    out = TimeFunction::table(times, values);
  }
  f.finish();
  return out;
}

namespace detail {

void face_from_name(const std::string& name, int& axis, bool& upper) {
  axis = name[0] - 'x';
  upper = name.size() > 2 && name.substr(2) == "max";
}

namespace {

TimeFunction optional_scale(const JsonReader& obj) {
  const auto s = obj.find("scale");
  return s ? parse_time_function(*s) : TimeFunction::constant(1.0);
}

void parse_point_load(const JsonReader& l, Scene& s, const ParseContext& ctx) {
  const int dim = s.dimension;
  PointLoadSpec p;
  if (const auto b = l.find("body")) p.body = ctx.body_id(*b);
  const bool has_point = l.has("point"), has_box = l.has("box");
  if (has_point == has_box) l.fail("expected exactly one of point ([x, y(, z)]) or box ({\"lo\": .., \"hi\": ..})");
  if (has_point) {
    p.point = read_vec(l.at("point"), dim);
  } else {
    const JsonReader box = l.at("box");
    p.use_box = true;
    p.box_lo = read_vec(box.at("lo", "the lower corner"), dim);
    const JsonReader hi = box.at("hi", "the upper corner");
    p.box_hi = read_vec(hi, dim);
    for (int d = 0; d < dim; ++d)
      if (p.box_hi[d] < p.box_lo[d]) hi.expected("every component >= lo's " + format_vec(p.box_lo, dim));
    box.finish();
  }
  p.force = read_vec(l.at("force", "the force (N)"), dim);
  p.scale = optional_scale(l);
  l.finish();
  s.point_loads.push_back(p);
}

void parse_traction(const JsonReader& l, Scene& s, const ParseContext& ctx) {
  TractionSpec t;
  t.body = ctx.body_id(l.at("body", "a body name"));
  face_from_name(l.at("face", "a face name").as_choice(face_names(s.dimension)), t.axis, t.upper);
  t.traction = read_vec(l.at("traction", "the traction (Pa)"), s.dimension);
  t.scale = optional_scale(l);
  l.finish();
  s.tractions.push_back(t);
}

}  // namespace

void parse_boundary(const JsonReader& root, Scene& s, const ParseContext& /*ctx*/) {
  const auto boundary = root.find("boundary");
  if (!boundary) return;
  if (const auto fixed = boundary->find("fixed")) {
    const std::vector<std::string> axes = {"x", "y", "z"};
    const std::vector<std::string> allowed(axes.begin(), axes.begin() + s.dimension);
    for (const JsonReader& f : fixed->elements()) {
      mechanics::FixedFace face;
      face_from_name(f.at("face", "a face name").as_choice(face_names(s.dimension)), face.axis, face.upper);
      face.components = {{s.dimension > 0, s.dimension > 1, s.dimension > 2}};
      if (const auto c = f.find("components")) {
        face.components = {{false, false, false}};
        for (const JsonReader& e : c->elements(1)) {
          const std::string a = e.as_choice(allowed);
          const std::size_t k = static_cast<std::size_t>(a[0] - 'x');
          if (face.components[k]) e.fail("component \"" + a + "\" listed twice");
          face.components[k] = true;
        }
      }
      f.finish();
      s.fixed_faces.push_back(face);
    }
  }
  boundary->finish();
}

void parse_loads(const JsonReader& root, Scene& s, const ParseContext& ctx) {
  const auto loads = root.find("loads");
  if (!loads) return;
  if (const auto g = loads->find("gravity")) {
    const SceneVec v = read_vec(*g, s.dimension);
    for (int d = 0; d < 3; ++d) s.options.gravity[d] = v[d];
  }
  if (const auto points = loads->find("point"))
    for (const JsonReader& l : points->elements()) parse_point_load(l, s, ctx);
  if (const auto tractions = loads->find("traction"))
    for (const JsonReader& l : tractions->elements()) parse_traction(l, s, ctx);
  loads->finish();
}

}  // namespace detail
}  // namespace frictherm::coupling
