// Scene sections `thermal` and `coupling`: validated into a ThermalSceneSpec (docs/scenes.md).
#include <frictherm/coupling/scene_thermal.hpp>

#include "scene/scene_detail.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <stdexcept>
#include <unordered_map>

namespace frictherm::coupling {

namespace {

void parse_integrator(const JsonReader& t, ThermalSceneSpec& spec) {
  CouplerOptions& c = spec.coupler;
  thermal::IntegratorOptions& o = c.integrator_options;
  std::vector<std::string> names = thermal::integrator_names();
  names.insert(names.begin(), "auto");  // coupler.hpp: matrix-free forward Euler or cvode_bdf by window
  c.integrator = t.choice("integrator", names, "auto");
  const bool explicit_allowed = c.integrator == "forward_euler" || c.integrator == "auto";
  // CVODE refuses a tolerance near the unit round-off ("too much accuracy requested" once
  // 2.2e-16 / rtol > 1): at least 1e-14 (issue 34: rtol 1e-300 failed the run).
  o.rtol = t.number("rtol", o.rtol, Range{1e-14, 1.0, false, true});
  o.atol = t.number("atol", o.atol, Range::positive());
  o.max_steps = t.integer("max_steps", o.max_steps, 1, std::numeric_limits<int>::max());
  if (const auto ls = t.find("linear_solver")) {
    std::vector<std::string> allowed;
    if (c.integrator == "cvode_bdf" || c.integrator == "arkode_dirk" || c.integrator == "auto")
      allowed = {"klu", "pcg"};
    if (c.integrator == "cvode_adams") allowed = {"fixed_point", "klu", "pcg"};
    if (allowed.empty()) ls->fail("not used by the explicit integrator " + c.integrator + " (remove it)");
    o.linear_solver = ls->as_choice(allowed);
  }
  o.krylov_maxl = static_cast<int>(t.integer("krylov_maxl", o.krylov_maxl, 1, 100000));
  // The PETSc preconditioner of a decomposed run's Krylov solve (thermal::DistributedOptions; the serial
  // run's PCG is Jacobi-preconditioned and its KLU needs none: they do not read it).
  if (const auto pc = t.find("preconditioner")) {
    if (c.integrator == "forward_euler" || c.integrator == "arkode_erk")
      pc->fail("not used by the explicit integrator " + c.integrator + " (remove it)");
    spec.preconditioner = pc->as_choice({"jacobi", "bjacobi", "hypre"});
  }
  o.reinit_every_window = t.find("reinit_every_window") ? t.at("reinit_every_window").as_bool() : false;
  if (const auto fe = t.find("forward_euler")) {
    if (!explicit_allowed) fe->fail("only for \"integrator\": \"forward_euler\" or \"auto\"");
    o.fe_stability_policy = fe->choice("stability", {"substep", "refuse", "unguarded"}, "substep");
    o.fe_safety = fe->number("safety", o.fe_safety, Range::left_open(0.0, 1.0));
    o.fe_max_dt = fe->number("max_dt", 0.0, Range::non_negative());
    o.fe_limit_estimate = fe->choice("limit_estimate", {"gershgorin", "power"}, "gershgorin");
    fe->finish();
  }
  if (const auto mf = t.find("matrix_free_max_substeps")) {
    if (!explicit_allowed) mf->fail("only for \"integrator\": \"forward_euler\" or \"auto\"");
    c.matrix_free_max_substeps = t.integer("matrix_free_max_substeps", c.matrix_free_max_substeps, 0, 1000000);
  }
  try {
    thermal::make_integrator(c.assembled_integrator(), o);  // the thermal module's own checks, before any step
  } catch (const std::invalid_argument& e) {
    t.fail(e.what());
  }
}

constexpr double kDefaultTaylorQuinney = 0.9;  // the classical fraction for metals; docs/scenes.md

void parse_materials(const JsonReader& t, ThermalSceneSpec& spec, const std::vector<mechanics::Material>& mats,
                     std::optional<JsonReader>& taylor_quinney_key) {
  std::vector<std::string> names;
  std::unordered_map<std::string, std::size_t> index;  // a name's material id (a lookup, not a search)
  for (const auto& m : mats) {
    index.emplace(m.name, names.size());
    names.push_back(m.name);
  }
  spec.coupler.materials.assign(mats.size(), ThermalProperties{});
  spec.coupler.plastic.taylor_quinney.assign(mats.size(), 0.0);
  const JsonReader table =
      t.at("materials", "an object mapping material names to {\"heat_capacity\": J/(kg K), \"conductivity\": W/(m K)}");
  for (const auto& [name, m] : table.members()) {
    const auto found = index.find(name);
    if (found == index.end()) {
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
      m.fail("no material of this name in \"materials\" (defined: " + known + ")");
    }
    if (!m.is_object()) m.expected("an object with heat_capacity and conductivity");
    ThermalProperties& p = spec.coupler.materials[found->second];
    p.conducts = true;
    p.heat_capacity = m.number("heat_capacity", Range::positive());
    p.conductivity = m.number("conductivity", Range::non_negative());
    if (const auto tq = m.find("taylor_quinney"); tq && !taylor_quinney_key) taylor_quinney_key = tq;
    spec.coupler.plastic.taylor_quinney[found->second] =
        m.number("taylor_quinney", kDefaultTaylorQuinney, Range::closed(0.0, 1.0));
    m.finish();
  }
  for (std::size_t i = 0; i < mats.size(); ++i)
    if (!mats[i].is_rigid() && !spec.coupler.materials[i].conducts)
      table.fail("missing material \"" + mats[i].name +
                 "\" (every deformable material needs heat_capacity and conductivity; rigid ones may be left out)");
}

void parse_reaction(const JsonReader& t, ThermalSceneSpec& spec, const std::vector<mechanics::Material>& mats) {
  const auto r = t.find("reaction");
  if (!r) return;
  if (!r->is_object()) r->expected("an object {\"kinetics\": ..., \"materials\": [names]}");
  ReactionOptions& rx = spec.coupler.reaction;
  rx.enabled = true;
  const JsonReader k = r->at("kinetics", "\"hmx_rogers1975\" or {\"prefactor\", \"activation_energy\", \"heat_of_reaction\"}");
  if (k.is_string()) {
    rx.kinetics_name = k.as_choice({"hmx_rogers1975"});
    rx.kinetics = thermal::hmx_kinetics_rogers1975();
  } else if (k.is_object()) {
    rx.kinetics_name = "explicit";
    rx.kinetics.prefactor = k.number("prefactor", Range::positive());
    rx.kinetics.activation_temperature = k.number("activation_energy", Range::positive()) / thermal::kGasConstant;
    rx.kinetics.specific_heat_of_reaction = k.number("heat_of_reaction", Range::non_negative());
    k.finish();
  } else {
    k.expected("\"hmx_rogers1975\" or an object {\"prefactor\": 1/s, \"activation_energy\": J/mol, "
               "\"heat_of_reaction\": J/kg}");
  }
  rx.reacting.assign(mats.size(), 0);
  const JsonReader list = r->at("materials", "an array of the names of the materials that react");
  for (const JsonReader& e : list.elements(1)) {
    const std::string name = e.as_string();
    std::size_t id = 0;
    while (id < mats.size() && mats[id].name != name) ++id;
    if (id == mats.size()) e.fail("no material of this name in \"materials\"");
    if (!spec.coupler.materials[id].conducts)
      e.fail("material \"" + name + "\" has no thermal properties (list it in thermal.materials)");
    rx.reacting[id] = 1;
  }
  if (const auto d = r->find("during_loading")) rx.during_loading = d->as_bool();
  r->finish();
}

void parse_fixed_faces(const JsonReader& t, ThermalSceneSpec& spec, int dim) {
  const auto list = t.find("fixed_temperature");
  if (!list) return;
  for (const JsonReader& e : list->elements()) {
    if (!e.is_object()) e.expected("an object {\"face\": NAME, \"temperature\": K}");
    FixedTemperatureFace f;
    const std::string face = e.choice("face", face_names(dim));
    detail::face_from_name(face, f.axis, f.upper);
    f.temperature = e.number("temperature", Range::positive());
    e.finish();
    spec.coupler.fixed_faces.push_back(f);
  }
}

// A scene that names no window gets an adaptive one (issue 13): a window every step costs a whole
// assembly per step, and windows that let no node rise by more than this give the same heat (the
// books are exact for any window) and lag the every-step temperatures by at most about this much.
constexpr double kDefaultWindowRise = 0.1;  // K
// ... and that let no conducting particle travel more than this many cells: a node's pending heat goes
// to the particles on it at the window's end, so a slider that moved on leaves heat behind, an error
// first order in the travel (docs/coupling.md, "Window policies": the main example's hottest
// particles 10 % of the peak rise off with 2e-4 s windows, 7.1 / 3.6 / 1.8 % with 0.2 / 0.1 / 0.05 cells).
constexpr double kDefaultWindowTravel = 0.05;  // cells
// Matrix-free windows reuse their gather while particles moved less than this many cells
// (docs/performance.md: measured error against gathering every window).
constexpr double kDefaultReuseDistance = 0.01;

void default_window(WindowPolicy& w) {
  w.kind = WindowPolicy::Kind::adaptive;
  w.max_temperature_rise = kDefaultWindowRise;
  w.max_travel = kDefaultWindowTravel;
}

void parse_window(const JsonReader& c, WindowPolicy& w) {
  const auto win = c.find("window");
  if (!win) return;  // the default set by parse_thermal_scene
  const std::vector<std::string> policies{"every_step", "every_n_steps", "adaptive"};
  const std::string policy = win->is_string() ? win->as_choice(policies)
                             : win->is_object()
                                 ? win->choice("policy", policies)
                                 : (win->expected("\"every_step\" or an object {\"policy\": ...}"), std::string());
  if (policy == "every_step") {
    w.kind = WindowPolicy::Kind::every_step;
  } else if (policy == "every_n_steps") {
    if (!win->is_object()) win->expected("an object {\"policy\": \"every_n_steps\", \"steps\": N}");
    w.kind = WindowPolicy::Kind::every_n_steps;
    w.steps = win->integer("steps", 1, std::numeric_limits<int>::max());
  } else {
    default_window(w);  // "adaptive" alone: the default rise
    if (!win->is_object()) return;
    w.max_temperature_rise = win->number("max_temperature_rise", kDefaultWindowRise, Range::positive());
    w.max_duration = win->number("max_duration", w.max_duration, Range::positive());
    w.max_steps = win->integer("max_steps", 0, 1, std::numeric_limits<int>::max());
    w.max_travel = win->number("max_travel", kDefaultWindowTravel, Range::non_negative());
  }
  if (win->is_object()) win->finish();
}

// coupling.interface_temperature: true/false, or {"enabled": bool, "bins_per_level": n, "patch_length": ℓ}.
void parse_interface_temperature(const JsonReader& c, InterfaceTemperatureOptions& o, double h) {
  const auto it = c.find("interface_temperature");
  if (!it) return;
  if (!it->is_object()) {
    o.enabled = it->as_bool();
    return;
  }
  o.enabled = !it->find("enabled") || it->at("enabled").as_bool();
  o.bins_per_level = static_cast<int>(it->integer("bins_per_level", o.bins_per_level, 2, 64));
  o.patch_length = it->number("patch_length", 0.0, Range::non_negative());
  // The patch around a contact node spans at most 64 cells (65^Dim lattice offsets; beyond that it is
  // not an interface spot): InterfaceTemperature's own check, here so that validate says it.
  if (h > 0.0 && o.patch_length > 64.0 * h)
    it->at("patch_length").fail("expected at most 64 cells (" + format_number(64.0 * h) + " m with " +
                                format_number(h) + " m cells), got " + format_number(o.patch_length) + " m (" +
                                format_number(o.patch_length / h) + " cells)");
  it->finish();
}

void parse_hotspots(const JsonReader& c, HotSpotOptions& h, HotSpotFateOptions& f, CouplerOptions& coupler) {
  const auto hs = c.find("hotspots");
  if (!hs) return;
  // "interface": judged by the sub-cell interface temperature, which this turns on.
  if (hs->choice("temperature", {"grid", "interface"}, "grid") == "interface") {
    coupler.hotspots_by_interface_temperature = true;
    if (!coupler.interface_temperature.enabled) {
      if (const auto it = c.find("interface_temperature"))
        it->fail("is off, but \"hotspots\": {\"temperature\": \"interface\"} needs it");
      coupler.interface_temperature.enabled = true;
    }
  }
  h.mode = hs->choice("mode", {"rise", "absolute"}, "rise") == "absolute" ? HotSpotOptions::Mode::absolute
                                                                           : HotSpotOptions::Mode::rise;
  h.threshold = hs->number("threshold", h.threshold,
                           h.mode == HotSpotOptions::Mode::absolute ? Range::positive() : Range::non_negative());
  h.link_factor = hs->number("link_factor", h.link_factor, Range::closed(1.0, 10.0));
  h.min_particles = static_cast<std::size_t>(hs->integer("min_particles", 1, 1, std::numeric_limits<int>::max()));
  f.runaway_progress = hs->number("runaway_progress", f.runaway_progress, Range::left_open(0.0, 1.0));
  f.runaway_temperature = hs->number("runaway_temperature", f.runaway_temperature, Range::positive());
  hs->finish();
}

}  // namespace

const char* to_string(WindowPolicy::Kind kind) {
  switch (kind) {
    case WindowPolicy::Kind::every_step: return "every_step";
    case WindowPolicy::Kind::every_n_steps: return "every_n_steps";
    case WindowPolicy::Kind::adaptive: return "adaptive";
  }
  return "?";
}

ThermalSceneSpec parse_thermal_sections(const JsonReader& root, int dimension,
                                        const std::vector<mechanics::Material>& materials, double thickness,
                                        double min_cell_size) {
  ThermalSceneSpec spec;
  const auto t = root.find("thermal");
  const auto c = root.find("coupling");
  if (!t) {
    if (c) c->fail("needs a \"thermal\" section (the thermal solver and the materials' heat capacity and conductivity)");
    return spec;
  }
  if (!t->is_object()) t->expected("an object with at least \"materials\"");
  spec.enabled = true;
  default_window(spec.coupler.window);
  spec.coupler.reuse_distance = kDefaultReuseDistance;
  spec.coupler.thickness = dimension == 2 ? thickness : 1.0;
  parse_integrator(*t, spec);
  spec.coupler.assembly.active_mass_fraction =
      t->number("active_mass_fraction", spec.coupler.assembly.active_mass_fraction, Range::open(0.0, 1.0));
  std::optional<JsonReader> taylor_quinney_key;
  parse_materials(*t, spec, materials, taylor_quinney_key);
  parse_reaction(*t, spec, materials);
  parse_fixed_faces(*t, spec, dimension);
  t->finish();
  if (c && !c->is_object()) c->expected("an object");
  spec.coupler.plastic.enabled = c && c->find("plastic_heating") && c->at("plastic_heating").as_bool();
  if (taylor_quinney_key && !spec.coupler.plastic.enabled)
    taylor_quinney_key->fail("only used with \"coupling\": {\"plastic_heating\": true}");
  if (!c) return spec;
  if (!c->is_object()) c->expected("an object");
  parse_window(*c, spec.coupler.window);
  spec.heating_order = c->choice("heating_order", {"first", "second"}, "second") == "first" ? HeatingOrder::first
                                                                                           : HeatingOrder::second;
  if (const auto cont = c->find("continuation")) {
    // At most 1e12 s (~32,000 years): 1e20 s exhausted CVODE's steps in a window and 1e300 s failed its
    // corrector (the run failed; issue 34), 1e12 s completes.
    spec.continuation_duration = cont->number("duration", Range::left_open(0.0, 1e12));
    spec.continuation_intervals = cont->integer("intervals", spec.continuation_intervals, 1, 100000);  // (10^5: as snapshots)
    spec.stop_when_decided = cont->find("stop_when_decided") && cont->at("stop_when_decided").as_bool();
    cont->finish();
  }
  spec.coupler.subgrid_relaxation_time =
      c->number("subgrid_relaxation_time", spec.coupler.subgrid_relaxation_time, Range::positive());
  spec.reuse_distance_given = static_cast<bool>(c->find("reuse_distance"));
  spec.coupler.reuse_distance = c->number("reuse_distance", spec.coupler.reuse_distance, Range::closed(0.0, 0.5));
  parse_interface_temperature(*c, spec.coupler.interface_temperature, min_cell_size);
  parse_hotspots(*c, spec.coupler.hotspots, spec.coupler.fates, spec.coupler);
  c->finish();
  return spec;
}

}  // namespace frictherm::coupling
