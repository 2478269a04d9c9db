// Scene parsing: the document root, grid, materials, solver, run and output sections.
// Bodies and loads live in scene_bodies.cpp and scene_loads.cpp.
#include "scene/scene_detail.hpp"

#include <frictherm/mechanics/mie_gruneisen.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace frictherm::coupling {

using detail::ParseContext;
using detail::read_vec;

namespace {

const char* const kAxisNames[3] = {"x", "y", "z"};

void parse_grid(const JsonReader& root, Scene& s) {
  const JsonReader grid = root.at("grid", "an object with lo, hi and cell_size or cells");
  const int dim = s.dimension;
  const JsonReader lo_r = grid.at("lo", "an array of " + std::to_string(dim) + " numbers");
  const JsonReader hi_r = grid.at("hi", "an array of " + std::to_string(dim) + " numbers");
  s.grid_lo = read_vec(lo_r, dim);
  s.grid_hi = read_vec(hi_r, dim);
  for (int d = 0; d < dim; ++d)
    if (!(s.grid_hi[d] > s.grid_lo[d]))
      hi_r.fail(std::string("expected every component greater than grid.lo's, but ") + kAxisNames[d] + " hi = " +
                format_number(s.grid_hi[d]) + " <= lo = " + format_number(s.grid_lo[d]));
  const bool has_h = grid.has("cell_size"), has_n = grid.has("cells");
  if (has_h == has_n) grid.fail("expected exactly one of cell_size (m) or cells (count per direction)");
  double total = 1.0;
  if (has_h) {
    const JsonReader h = grid.at("cell_size");
    if (h.is_number()) {
      const double v = h.as_number(Range::positive());
      for (int d = 0; d < dim; ++d) s.cell_size[d] = v;
    } else {
      s.cell_size = read_vec(h, dim, Range::positive());
    }
    for (int d = 0; d < dim; ++d) {
      const double extent = s.grid_hi[d] - s.grid_lo[d];
      const double n = extent / s.cell_size[d];
      const double r = std::round(n);
      if (r < 1.0 || std::fabs(n - r) > 1e-6 * std::max(1.0, n))
        h.fail(std::string("expected a cell size that divides hi - lo evenly, but in ") + kAxisNames[d] + " " +
               format_number(extent) + " m / " + format_number(s.cell_size[d]) + " m = " + format_number(n) +
               " cells");
      if (r > 1e7) h.fail("expected at most 10^7 cells per direction, got " + format_number(r));
      s.cells[d] = static_cast<int>(r);
      s.cell_size[d] = extent / r;  // exact division of [lo, hi]
      total *= r;
    }
  } else {
    const JsonReader n = grid.at("cells");
    if (!n.is_array() || n.json().size() != static_cast<std::size_t>(dim))
      n.expected("an array of " + std::to_string(dim) + " integers (cells per direction)");
    const auto items = n.elements();
    for (int d = 0; d < dim; ++d) {
      s.cells[d] = static_cast<int>(items[static_cast<std::size_t>(d)].as_integer(1, 10000000));
      s.cell_size[d] = (s.grid_hi[d] - s.grid_lo[d]) / s.cells[d];
      total *= s.cells[d];
    }
  }
  if (total > 5e7) grid.fail("the grid has " + format_number(total) + " cells; expected at most 5e7");
  grid.finish();
}

mechanics::Material parse_material(const JsonReader& m, const std::string& name, const Scene& s) {
  mechanics::Material mat;
  mat.name = name;
  const JsonReader type = m.at("type", "\"linear_elastic\", \"neo_hookean\", \"mie_gruneisen\" or \"rigid\"");
  mat.kind = mechanics::material_kind_from_string(
      type.as_choice({"linear_elastic", "neo_hookean", "mie_gruneisen", "rigid"}));
  if (mat.kind == mechanics::MaterialKind::mie_gruneisen) {
    if (s.options.analysis == mechanics::Analysis::plane_stress)
      type.fail("mie_gruneisen needs \"analysis\": \"plane_strain\" or a 3D scene (an equation of state has no "
                "plane-stress form)");
    mechanics::MieGruneisenParams& g = mat.mie_gruneisen;
    mat.density = g.density = m.number("density", Range::positive());
    g.C0 = m.number("C0", Range::positive());
    g.S1 = m.number("S1");
    g.S2 = m.number("S2", 0.0, Range::any());
    g.gamma0 = m.number("gamma0", Range::non_negative());
    g.shear_modulus = m.number("shear_modulus", Range::non_negative());
    g.yield_stress = m.number("yield_stress", std::numeric_limits<double>::infinity(), Range::positive());
    g.hardening_modulus = m.number("hardening_modulus", 0.0, Range::non_negative());
    try {
      mechanics::validate(g, s.options.analysis, m.path());
    } catch (const std::invalid_argument& e) {
      throw SceneError(e.what());
    }
    m.finish();
    return mat;
  }
  if (mat.is_rigid()) {
    mat.density = m.number("density", 1000.0, Range::positive());
    if (const auto b = m.find("boundary")) mat.rigid_boundary = b->as_bool();
    const auto v = m.find("velocity");
    if (v) {
      const std::string what = "an array of " + std::to_string(s.dimension) +
                               " time functions (numbers or {\"type\": ...} objects), one per dimension" +
                               (mat.rigid_boundary ? " or null for a free component" : "");
      if (!v->is_array() || v->json().size() != static_cast<std::size_t>(s.dimension)) v->expected(what);
      std::size_t d = 0;
      for (const JsonReader& f : v->elements()) {
        if (f.json().is_null()) {
          if (!mat.rigid_boundary) f.fail("a free (null) component needs \"boundary\": true on the material");
          mat.rigid_controls[d] = false;
          mat.rigid_velocity.push_back(mechanics::TimeFunction::constant(0.0));
        } else {
          mat.rigid_velocity.push_back(parse_time_function(f));
        }
        ++d;
      }
    } else {
      mat.rigid_velocity.assign(static_cast<std::size_t>(s.dimension), mechanics::TimeFunction::constant(0.0));
    }
  } else {
    if (mat.kind == mechanics::MaterialKind::neo_hookean && s.options.analysis == mechanics::Analysis::plane_stress)
      type.fail("neo_hookean needs \"analysis\": \"plane_strain\" or a 3D scene, not plane_stress");
    mat.density = m.number("density", Range::positive());
    mat.youngs_modulus = m.number("youngs_modulus", Range::positive());
    mat.poisson_ratio = m.number("poisson_ratio", Range::open(-1.0, 0.5));
  }
  m.finish();
  return mat;
}

void parse_materials(const JsonReader& root, Scene& s, ParseContext& ctx) {
  const JsonReader mats = root.at("materials", "an object mapping material names to their properties");
  const auto members = mats.members();
  if (members.empty()) mats.expected("at least one material");
  for (const auto& [name, m] : members) {
    detail::check_result_name(m, name, "material");
    if (!m.is_object()) m.expected("an object with the material's type and properties");
    s.materials.push_back(parse_material(m, name, s));
    ctx.material_names.push_back(name);
  }
  mats.finish();
}

/// Contact is on and some pair (or the default pair) uses multimaterial (grid) contact.
bool uses_grid_contact(const ContactSpec& contact) {
  if (!contact.enabled) return false;
  bool grid_contact = contact.options.default_pair.method == mechanics::ContactMethod::multimaterial;
  for (const ContactPairSpec& p : contact.pairs)
    grid_contact = grid_contact || p.settings.method == mechanics::ContactMethod::multimaterial;
  return grid_contact;
}

/// The update scheme of a scene that names none: USL when a pair uses multimaterial (grid) contact,
/// whose frictional heat MUSL makes grow with the time step (docs/transfer.md, "What they do for
/// frictional heat"), MUSL otherwise, and MUSL with linear shape functions: with USL (and USF) every
/// contact scene measured blew up with them, MUSL ran each (docs/contact.md, "Linear shape
/// functions and multimaterial contact").
mechanics::UpdateScheme default_update_scheme(const ContactSpec& contact, mechanics::ShapeKind shape) {
  if (shape == mechanics::ShapeKind::linear) return mechanics::UpdateScheme::musl;
  return uses_grid_contact(contact) ? mechanics::UpdateScheme::usl : mechanics::UpdateScheme::musl;
}

void parse_solver(const JsonReader& root, Scene& s) {  // after the contact section: default_update_scheme
  s.options.scheme = default_update_scheme(s.contact, s.options.shape);
  const auto solver = root.find("solver");
  if (!solver) return;
  s.options.shape = mechanics::shape_kind_from_string(solver->choice(
      "shape_function", {"linear", "ugimp", "quadratic_bspline", "extended_bspline", "ebs"}, "ugimp"));
  s.options.scheme = default_update_scheme(s.contact, s.options.shape);
  if (s.options.shape == mechanics::ShapeKind::extended_bspline)  // C_c, Kakouris 2024 eq. 20
    s.options.ebs_occupation = solver->number("ebs_occupation", s.options.ebs_occupation, Range::closed(0.0, 1.0));
  else if (const auto c = solver->find("ebs_occupation"))
    c->fail("only with \"shape_function\": \"extended_bspline\"");
  s.options.scheme = mechanics::update_scheme_from_string(
      solver->choice("scheme", {"usf", "usl", "musl"}, mechanics::to_string(s.options.scheme)));
  if (s.options.shape == mechanics::ShapeKind::linear && s.options.scheme != mechanics::UpdateScheme::musl &&
      uses_grid_contact(s.contact))
    s.notes.push_back(std::string("solver.scheme \"") + mechanics::to_string(s.options.scheme) +
                      "\" with \"shape_function\": \"linear\" and multimaterial contact: every contact scene "
                      "measured blew up with this combination, MUSL runs them (\"scheme\": \"musl\", the default "
                      "for linear shape functions with contact; docs/contact.md, \"Linear shape functions and "
                      "multimaterial contact\")");
  s.options.cfl = solver->number("cfl", 0.5, Range::left_open(0.0, 1.0));
  if (const auto m = solver->find("max_time_step")) s.options.max_time_step = m->as_number(Range::positive());
  if (const auto t = solver->find("pic_relaxation_time")) s.options.pic_relaxation_time = t->as_number(Range::positive());
  if (const auto u = solver->find("particle_update")) {  // FLIP, XPIC(m) or FMPM(k): transfer.hpp
    if (u->is_string()) {
      s.options.particle_update = mechanics::particle_update_from_string(u->as_choice({"flip", "xpic", "fmpm"}));
    } else {
      if (!u->is_object()) u->expected("\"flip\" or an object {\"type\": \"xpic\" or \"fmpm\", \"order\": 1..50}");
      s.options.particle_update = mechanics::particle_update_from_string(u->choice("type", {"flip", "xpic", "fmpm"}, "flip"));
      s.options.transfer_order = static_cast<int>(u->integer("order", 2, 1, 50));
      u->finish();
    }
    if (s.options.particle_update != mechanics::ParticleUpdate::flip && std::isfinite(s.options.pic_relaxation_time))
      u->fail("XPIC and FMPM filter the particle velocities themselves; remove solver.pic_relaxation_time");
  }
  if (const auto d = solver->find("damping")) {  // mass-proportional damping over [0, until)
    if (!d->is_object()) d->expected("an object {\"rate\": c (1/s), \"until\": t (s)}");
    s.options.damping_rate = d->number("rate", Range::positive());
    s.options.damping_until = d->number("until", Range::positive());
    d->finish();
  }
  solver->finish();
}

constexpr double kMinEndTime = 1e-290;  // s: end_time / 10^6 stays a normal double

void parse_run(const JsonReader& root, Scene& s) {
  const JsonReader run = root.at("run", "an object with at least end_time (s)");
  s.end_time = run.number("end_time", Range::positive());
  // The default intervals are end_time / 20 and / 5000, snapshot_count divides it by up to 10^6:
  // 5e-324 s made them 0 and the refusal blamed snapshot_interval (issue 34).
  if (s.end_time < kMinEndTime) run.at("end_time").expected("a time of at least " + format_number(kMinEndTime) + " s");
  s.max_steps = run.integer("max_steps", 0, 1, std::numeric_limits<long>::max());
  s.threads = static_cast<int>(run.integer("threads", 0, 1, 1024));
  if (run.has("checkpoint_interval")) s.checkpoint_interval = run.number("checkpoint_interval", Range::positive());
  if (run.has("max_memory")) s.max_memory = run.number("max_memory", Range::positive());
  run.finish();
}

void parse_output(const JsonReader& root, Scene& s) {
  OutputSpec& o = s.output;
  o.file = s.name + ".h5";
  o.snapshot_interval = s.end_time / 20.0;
  o.series_interval = s.end_time / 5000.0;
  o.fields = snapshot_field_names(s.dimension);
  const auto out = root.find("output");
  if (!out) return;
  o.file = out->string("file", o.file);
  if (o.file.empty()) out->at("file").expected("a file name");
  const bool has_interval = out->has("snapshot_interval"), has_count = out->has("snapshot_count");
  if (has_interval && has_count) out->fail("expected snapshot_interval or snapshot_count, not both");
  if (has_interval) o.snapshot_interval = out->number("snapshot_interval", Range::positive());
  if (has_count) o.snapshot_interval = s.end_time / static_cast<double>(out->integer("snapshot_count", 1, 1000000));
  o.series_interval = out->number("series_interval", o.series_interval, Range::non_negative());
  if (const auto w = out->find("overwrite")) o.overwrite = w->as_bool();
  if (const auto f = out->find("fields")) {
    const auto known = snapshot_field_names(s.dimension);
    std::vector<std::string> fields{"position"};  // the XDMF geometry: always written
    for (const JsonReader& e : f->elements(1)) {
      const std::string name = e.as_choice(known);
      if (std::find(fields.begin(), fields.end(), name) == fields.end()) fields.push_back(name);
    }
    o.fields = fields;
  }
  out->finish();
}

/// "bodies[0].velocity" -> "/bodies/0/velocity".
Json::json_pointer pointer_of(const std::string& path) {
  if (path.empty() || path.back() == '.' || path.front() == '.' || path.front() == '[')
    throw SceneError("--set " + path + ": expected a key path such as solver.cfl or bodies[0].velocity");
  std::string p;
  std::string token;
  auto flush = [&] {
    if (token.empty()) throw SceneError("--set " + path + ": expected a key path such as solver.cfl or bodies[0].velocity");
    std::string escaped;
    for (char c : token) escaped += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
    p += "/" + escaped;
    token.clear();
  };
  for (std::size_t i = 0; i < path.size(); ++i) {
    const char c = path[i];
    if (c == '.') {
      if (i > 0 && path[i - 1] == ']') continue;
      flush();
    } else if (c == '[') {
      if (!(i > 0 && path[i - 1] == ']')) flush();  // a[1][2]: the second index right after the first
      const std::size_t close = path.find(']', i);
      if (close == std::string::npos) throw SceneError("--set " + path + ": missing ']'");
      token = path.substr(i + 1, close - i - 1);
      if (token.empty() || token.find_first_not_of("0123456789") != std::string::npos)
        throw SceneError("--set " + path + ": expected an index in [...]");
      flush();
      i = close;
      if (i + 1 < path.size() && path[i + 1] != '.' && path[i + 1] != '[')
        throw SceneError("--set " + path + ": expected '.' or '[' after ']', e.g. bodies[0].velocity");
    } else {
      token += c;
    }
  }
  if (!token.empty() || p.empty()) flush();
  return Json::json_pointer(p);
}

/// An array index in a --set path may append one element, not grow the array to any size
/// (`bodies[200000000]=1` would allocate 2e8 nulls).
void check_indices(const Json& doc, const Json::json_pointer& ptr, const std::string& path) {
  if (ptr.empty()) return;
  const Json::json_pointer parent = ptr.parent_pointer();
  check_indices(doc, parent, path);
  const std::string& token = ptr.back();
  if (token.empty() || token.find_first_not_of("0123456789") != std::string::npos) return;  // a key, not an index
  // A number under a missing or null parent makes that parent an array of index + 1 elements
  // (nlohmann::json's pointer creation): an empty array, as far as appending goes.
  const bool absent = !doc.contains(parent) || doc.at(parent).is_null();
  if (!absent && !doc.at(parent).is_array()) return;  // an object's key, or JSON refuses it
  const std::size_t size = absent ? 0 : doc.at(parent).size();
  if (token.size() > 9 || std::stoul(token) > size)
    throw SceneError("--set " + path + ": index " + token + " is beyond the end of an array of " + std::to_string(size) +
                     " elements (expected at most " + std::to_string(size) + ", which appends one)");
}

void apply_overrides(Json& doc, const std::vector<SceneOverride>& overrides) {
  for (const SceneOverride& o : overrides) {
    Json value;
    try {
      value = parse_json_text(o.value, o.path);  // the limits of scene text (json_text.cpp) hold here too
    } catch (const JsonSyntaxError&) {
      value = o.value;  // a bare word: a string
    } catch (const SceneError& e) {
      throw SceneError(std::string("--set ") + e.what());
    }
    try {
      const Json::json_pointer ptr = pointer_of(o.path);
      check_indices(doc, ptr, o.path);
      if (value.is_null()) {  // KEY=null removes an object key (nothing to do when it is absent)
        const Json::json_pointer parent = ptr.parent_pointer();
        if (doc.contains(parent) && doc.at(parent).is_array())
          throw SceneError("--set " + o.path + "=null: null removes an object's key; an array element cannot be " +
                           "removed (give it a value, or set the whole array)");
        if (doc.contains(ptr) && doc.at(parent).is_object()) doc.at(parent).erase(ptr.back());
      } else {
        doc[ptr] = value;
      }
    } catch (const Json::exception&) {
      throw SceneError("--set " + o.path + ": cannot set this key (a part of its path is not an object or array)");
    }
  }
}

}  // namespace

SceneOverride parse_override(const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw SceneError("--set " + assignment + ": expected KEY.PATH=VALUE, e.g. solver.cfl=0.3");
  return {assignment.substr(0, eq), assignment.substr(eq + 1)};
}

std::vector<std::string> snapshot_field_names(int dimension) {
  std::vector<std::string> f{"position", "velocity", "displacement", "stress"};
  if (dimension == 2) f.push_back("stress_zz");
  for (const char* n : {"mass", "volume", "temperature", "material", "body"}) f.emplace_back(n);
  return f;
}

std::vector<std::string> face_names(int dimension) {
  std::vector<std::string> f;
  for (int d = 0; d < dimension; ++d) {
    f.push_back(std::string(kAxisNames[d]) + "_min");
    f.push_back(std::string(kAxisNames[d]) + "_max");
  }
  return f;
}

Scene parse_scene(const std::string& text, const std::string& source, const std::string& base_dir,
                  const std::string& name, const std::vector<SceneOverride>& overrides) {
  Json doc = parse_json_text(text);
  apply_overrides(doc, overrides);
  const JsonReader root(doc, "");
  if (!doc.is_object()) root.expected("a JSON object at the top level of the scene");
  // Unknown top-level keys first, so a misspelt section is reported as such.
  for (const char* key : {"units", "description", "dimension", "analysis", "thickness", "grid", "materials",
                          "bodies", "boundary", "loads", "contact", "solver", "run", "output", "thermal", "coupling"})
    root.has(key);
  root.finish();

  Scene s;
  s.text = text;
  s.overrides = overrides;
  s.json = doc.dump(2, ' ', false, Json::error_handler_t::replace);  // /meta/scene_json: json.loads reads it
  s.source = source;
  s.name = name;
  s.description = root.string("description", "");
  if (const auto u = root.find("units")) u->as_choice({"SI"});
  s.dimension = static_cast<int>(root.at("dimension", "2 or 3").as_integer(2, 3));
  if (s.dimension == 2) {
    s.options.analysis = root.choice("analysis", {"plane_strain", "plane_stress"}, "plane_strain") == "plane_stress"
                             ? mechanics::Analysis::plane_stress
                             : mechanics::Analysis::plane_strain;
    s.options.thickness = root.number("thickness", 1.0, Range::positive());
  } else {
    s.options.analysis = mechanics::Analysis::three_d;
    for (const char* key : {"analysis", "thickness"})
      if (const auto v = root.find(key)) v->fail("only for 2D scenes (a 3D scene is always fully three-dimensional)");
  }

  ParseContext ctx;
  ctx.dim = s.dimension;
  ctx.base_dir = base_dir;
  parse_grid(root, s);
  parse_materials(root, s, ctx);
  ctx.declared_materials = s.materials.size();  // image bodies may add one material per grain after these
  parse_run(root, s);  // before bodies and output: defaults depend on end_time
  detail::parse_bodies(root, s, ctx);
  detail::parse_boundary(root, s, ctx);
  detail::parse_loads(root, s, ctx);
  s.contact = parse_contact_section(root, s.dimension, ctx.material_names);  // scene_contact.cpp
  parse_solver(root, s);
  detail::expand_grain_contact_pairs(s, ctx);  // scene_grains.cpp: pairs of a grain template -> its grains
  parse_output(root, s);
  // Thermal properties are given per declared material; grain materials take their template's.
  const std::vector<mechanics::Material> declared(s.materials.begin(),
                                                  s.materials.begin() + static_cast<long>(ctx.declared_materials));
  s.thermal = parse_thermal_sections(root, s.dimension, declared, s.options.thickness,  // scene_thermal.cpp
                                     *std::min_element(s.cell_size.begin(), s.cell_size.begin() + s.dimension));
  detail::extend_grain_thermal(s, ctx);
  // coupling.heating_order, when the scene names none, follows the update scheme: the first-order work
  // (Nairn 2018 eq. 27) under USL and USF, where it converges faster in C and in h than the second
  // order; the second order (eqs. 34/36) under MUSL, the paper's scheme, where the first order is far
  // too high at large steps (docs/coupling.md, "Which heating order").
  const auto coupling = root.find("coupling");
  if (!(coupling && coupling->is_object() && coupling->find("heating_order")))
    s.thermal.heating_order = s.options.scheme == mechanics::UpdateScheme::musl ? mechanics::HeatingOrder::second
                                                                                : mechanics::HeatingOrder::first;
  s.cost = estimate_scene_cost(s);  // before any particle or grid array exists
  check_scene_cost(s, s.cost);
  return s;
}

Scene load_scene(const std::string& path, const std::vector<SceneOverride>& overrides) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError("cannot read scene file '" + path + "': it is a folder");
  // A regular file of bounded size: /dev/zero, a FIFO or /dev/stdin would be read without end.
  const auto status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw SceneError("cannot read scene file '" + path + "': not a regular file (a device, pipe or socket)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError("cannot open scene file '" + path + "'");
  const auto bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > kMaxSceneBytes)
    throw SceneError("scene file '" + path + "' holds " + std::to_string(bytes) + " bytes; expected at most " +
                     std::to_string(kMaxSceneBytes) + " (8 MiB)");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw SceneError("cannot read scene file '" + path + "'");
  // Folder of the scene (for relative image paths) and its name (default output file).
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = name.find_last_of('.');
  if (dot != std::string::npos && dot > 0) name = name.substr(0, dot);
  if (name.empty()) name = "scene";
  return parse_scene(text.str(), path, dir, name, overrides);
}

}  // namespace frictherm::coupling
