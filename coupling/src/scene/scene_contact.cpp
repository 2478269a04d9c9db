// Scene section `contact`: friction laws, normals and contact detection per material pair, and the
// contact method (multimaterial or penalty on boundary points) with its penalty settings.
#include <frictherm/coupling/scene_contact.hpp>

#include <frictherm/mechanics/friction_expression.hpp>

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <stdexcept>

namespace frictherm::coupling {

namespace {

/// Runs a FrictionLaw factory; its std::invalid_argument (which names the parameter) gets the key path.
template <class F>
mechanics::FrictionLaw checked(const JsonReader& at, F&& make) {
  try {
    return make();
  } catch (const std::invalid_argument& e) {
    at.fail(e.what());
  }
}

constexpr std::size_t kMaxExpressionConstants = 1000;  // named constants of one expression law

/// {"type": "expression", "sliding_traction": "<S in N, A, v>", "constants": {"name": number, ...}}:
/// muParser's refusals (syntax, unknown names, S < 0 or not finite at a sample point) get the key path.
mechanics::FrictionLaw parse_expression_law(const JsonReader& law) {
  const JsonReader text = law.at("sliding_traction", "an expression for the sliding traction S (Pa) in N (Pa), A (m^2), v (m/s)");
  if (!text.is_string()) text.expected("a string: an expression in N (Pa), A (m^2), v (m/s), e.g. \"0.3*N\"");
  std::map<std::string, double> constants;
  if (const auto c = law.find("constants")) {
    if (!c->is_object()) c->expected("an object of named numbers, e.g. {\"mu_s\": 0.35}");
    const auto members = c->members();
    // Each is a muParser definition (about 14 us apiece, linear: 200,000 took 2.8 s of CPU); a law
    // reads a handful. Bounded so that validation stays fast (issue 34).
    if (members.size() > kMaxExpressionConstants)
      c->fail("expected at most " + std::to_string(kMaxExpressionConstants) + " named constants, got " +
              std::to_string(members.size()));
    for (const auto& [name, value] : members) constants[name] = value.as_number();
  }
  try {
    return mechanics::expression_friction_law(text.as_string(), constants);
  } catch (const mechanics::FrictionExpressionError& e) {
    const std::string& key = e.key();
    if (key.rfind("constants.", 0) == 0) law.at("constants").at(key.substr(10)).fail(e.what());
    text.fail(e.what());
  }
}

/// "mvg", "avg" or a vector (a specified normal, from the pair's first material to its second).
void parse_normal(const JsonReader& n, int dim, bool vector_allowed, mechanics::ContactPairSettings& s) {
  if (n.is_string()) {
    s.normal = mechanics::normal_method_from_string(n.as_choice({"mvg", "avg"}));
    return;
  }
  if (!vector_allowed) n.expected("\"mvg\" or \"avg\" (a specified normal belongs to a pair in contact.pairs)");
  if (!n.is_array()) n.expected("\"mvg\", \"avg\" or an array of " + std::to_string(dim) + " numbers (a specified normal)");
  const std::vector<double> v = n.as_vector(static_cast<std::size_t>(dim));
  double len2 = 0.0;
  for (double x : v) len2 += x * x;
  if (!(len2 > 0.0)) n.fail("expected a non-zero normal vector");
  s.normal = mechanics::NormalMethod::specified;
  s.normal_vector.setZero();
  for (int d = 0; d < dim; ++d) s.normal_vector[d] = v[static_cast<std::size_t>(d)];
}

/// "penalty": {"normal": ε_N | "normal_factor": f, "tangential": ε_T, "tangential_law": ...,
/// "search_radius": m, "paper_terms": bool} (Kakouris 2024; docs/penalty_contact.md).
void parse_penalty(const JsonReader& p, mechanics::PenaltySettings& s) {
  if (!p.is_object()) p.expected("an object with \"normal\" or \"normal_factor\", \"tangential\", \"tangential_law\", \"search_radius\"");
  if (p.has("normal") && p.has("normal_factor"))
    p.at("normal_factor").fail("give either \"normal\" (N/m^3) or \"normal_factor\" (multiple of E/h), not both");
  if (const auto n = p.find("normal")) s.normal_penalty = n->as_number(Range::positive()), s.normal_factor = 1.0;
  if (const auto f = p.find("normal_factor")) s.normal_factor = f->as_number(Range::positive()), s.normal_penalty = 0.0;
  s.tangential_penalty = p.number("tangential", s.tangential_penalty, Range::non_negative());
  s.law = mechanics::tangential_law_from_string(
      p.choice("tangential_law", {"return_mapping", "incremental"}, mechanics::to_string(s.law)));
  s.search_radius = p.number("search_radius", s.search_radius, Range::non_negative());
  if (const auto t = p.find("paper_terms")) s.paper_correction_terms = t->as_bool();
  p.finish();
}

/// Penalty contact takes a coulomb or frictionless law (Kakouris 2024 eq. 32).
void check_penalty_law(const mechanics::ContactPairSettings& s, const JsonReader& at) {
  if (s.method != mechanics::ContactMethod::penalty) return;
  const auto k = s.law.kind();
  if (k != mechanics::FrictionKind::coulomb && k != mechanics::FrictionKind::frictionless)
    at.fail("penalty contact takes a \"coulomb\" or \"frictionless\" law, got " + s.law.describe());
}

}  // namespace

mechanics::FrictionLaw parse_friction_law(const JsonReader& law) {
  using mechanics::FrictionLaw;
  const std::vector<std::string> types{"stick", "frictionless", "coulomb", "linear_velocity", "adhesion",
                                       "static_dynamic", "smooth_static_dynamic", "composite", "tabulated", "expression"};
  if (law.is_string()) {
    const std::string t = law.as_choice({"stick", "frictionless"});
    return t == "stick" ? FrictionLaw::stick() : FrictionLaw::frictionless();
  }
  if (!law.is_object()) law.expected("a friction law: \"stick\", \"frictionless\" or an object with \"type\"");
  const std::string type = law.at("type", "one of stick, frictionless, coulomb, linear_velocity, adhesion, "
                                          "static_dynamic, smooth_static_dynamic, composite, tabulated, expression")
                               .as_choice(types);
  const Range mu_range = Range::non_negative();
  FrictionLaw out;
  if (type == "stick") {
    out = FrictionLaw::stick();
  } else if (type == "frictionless") {
    out = FrictionLaw::frictionless();
  } else if (type == "coulomb") {
    const double mu = law.number("mu", mu_range);
    out = checked(law, [&] { return FrictionLaw::coulomb(mu); });
  } else if (type == "linear_velocity") {
    const double mu = law.number("mu", mu_range), k = law.number("k", Range::non_negative());
    out = checked(law, [&] { return FrictionLaw::linear_velocity(mu, k); });
  } else if (type == "adhesion") {
    const double mu = law.number("mu", mu_range), sa = law.number("shear_strength", Range::non_negative());
    const double na = law.number("tensile_strength", std::numeric_limits<double>::infinity(), Range::positive());
    out = checked(law, [&] { return FrictionLaw::adhesion(mu, sa, na); });
  } else if (type == "static_dynamic" || type == "smooth_static_dynamic") {
    const double ms = law.number("mu_static", mu_range), md = law.number("mu_dynamic", mu_range);
    if (type == "static_dynamic") {
      out = checked(law, [&] { return FrictionLaw::static_dynamic(ms, md); });
    } else {
      const double vh = law.number("v_half", Range::positive());
      out = checked(law, [&] { return FrictionLaw::smooth_static_dynamic(ms, md, vh); });
    }
  } else if (type == "composite") {  // eq 21 with every term: S = N (mu(v) + k v) + S_a
    const double ms = law.number("mu_static", mu_range);
    const double md = law.number("mu_dynamic", ms, mu_range);
    const double inf = std::numeric_limits<double>::infinity();
    const double vh = law.number("v_half", inf, Range::positive());
    if (md != ms && std::isinf(vh)) law.at("v_half", "the transition speed v_half (m/s, > 0): required when mu_dynamic differs from mu_static");
    const double k = law.number("k", 0.0, Range::non_negative());
    const double sa = law.number("shear_strength", 0.0, Range::non_negative());
    const double na = law.number("tensile_strength", inf, Range::positive());
    out = checked(law, [&] { return FrictionLaw::composite(ms, md, vh, k, sa, na); });
  } else if (type == "expression") {  // any S(N, A_c, |Δv'|) of eq 21, parsed by muParser
    out = parse_expression_law(law);
  } else {  // tabulated
    const std::vector<double> speeds = law.at("speeds", "an array of sliding speeds (m/s), increasing").as_number_list(1, Range::non_negative());
    const std::vector<double> mu = law.at("mu", "an array of friction coefficients, one per speed").as_number_list(1, mu_range);
    if (mu.size() != speeds.size())
      law.at("mu").fail("expected " + std::to_string(speeds.size()) + " coefficients (one per speed), got " +
                        std::to_string(mu.size()));
    out = checked(law, [&] { return FrictionLaw::tabulated(speeds, mu); });
  }
  law.finish();
  return out;
}

// Contact detection (docs/contact.md, "Contact detection"). Without a "separation" key every scene
// gets extent detection: the normal stop where the particle domains overlap, a law's area term where
// they touch. Position separation floated the Coulomb sliding block by 21 / 4.2 / 2.4 um at 5 / 2.5 /
// 1.25 mm (extent: under 1 um, 0.5 ms means) and lost an area law's traction (adhesion sliding block
// 7.1 / 1.5 / 56 % of v_max against 0.3 / 0.2 / 0.8 %).
static void parse_detection(const JsonReader& c, ContactSpec& spec) {
  mechanics::ContactOptions& o = spec.options;
  o.separation = mechanics::separation_method_from_string(
      c.choice("separation", {"position", "displacement", "velocity_only", "extent"}, "extent"));
  o.position_correction = c.number("position_correction", 0.8, Range{0.0, 2.0, false, true});
  // Extent detection handles slivers itself (normal contact only, see docs/contact.md), so by default
  // it drops no material; the other detections drop slivers below 1e-6 of the node's mass.
  if (o.separation == mechanics::SeparationMethod::extent) o.use_extent_detection();
  o.extent_tolerance = c.number("extent_tolerance", o.extent_tolerance, Range{0.0, 1.0, false, false});
  o.min_mass_fraction = c.number("min_mass_fraction", o.min_mass_fraction, Range{0.0, 0.5, false, true});
  o.sliver_fraction = c.number("sliver_fraction", o.sliver_fraction, Range{0.0, 0.5, false, true});
  o.light_touch_fraction = c.number("light_touch_fraction", 0.0, Range{0.0, 0.5, false, true});
  o.area = c.choice("area", {"domain", "surface"}, "surface") == "surface" ? mechanics::ContactAreaMethod::surface
                                                                         : mechanics::ContactAreaMethod::domain;
  // Normal-stress regularisation of friction (docs/contact.md, "Normal-stress regularisation").
  if (const auto r = c.find("regularization")) {
    if (!r->is_object()) r->expected("an object {\"slip_length\": L (m), \"time\": tau (s)}");
    o.regularization_slip_length = r->at("slip_length", "the slip length L (m, > 0)").as_number(Range::positive());
    o.regularization_time = r->at("time", "the relaxation time tau (s, > 0)").as_number(Range::positive());
    r->finish();
  }
}

ContactSpec parse_contact_section(const JsonReader& root, int dim, const std::vector<std::string>& material_names) {
  ContactSpec spec;
  const auto c = root.find("contact");
  if (!c) return spec;
  if (!c->is_object()) c->expected("an object (see docs/contact.md)");
  spec.enabled = true;
  mechanics::ContactOptions& o = spec.options;
  o.default_pair.method =
      mechanics::contact_method_from_string(c->choice("method", {"multimaterial", "penalty"}, "multimaterial"));
  if (o.default_pair.method == mechanics::ContactMethod::penalty && dim != 2)
    c->at("method").fail("penalty contact is 2D only (expected \"multimaterial\" in 3D)");
  if (const auto pen = c->find("penalty")) parse_penalty(*pen, o.default_pair.penalty);
  o.boundary_spacing = c->number("boundary_spacing", 0.0, Range::non_negative());
  if (const auto n = c->find("normal")) parse_normal(*n, dim, false, o.default_pair);
  if (const auto law = c->find("law")) {
    o.default_pair.law = parse_friction_law(*law);
    o.default_pair.origin = law->path();  // named when the law fails during the run
    check_penalty_law(o.default_pair, *law);
  } else if (o.default_pair.method == mechanics::ContactMethod::penalty) {
    o.default_pair.law = mechanics::FrictionLaw::frictionless();  // the default "stick" has no penalty form
  }
  auto material_id = [&](const JsonReader& name) {
    const std::string n = name.as_string();
    const auto it = std::find(material_names.begin(), material_names.end(), n);
    if (it == material_names.end()) {
      std::string known;
      for (const auto& m : material_names) known += (known.empty() ? "" : ", ") + m;
      name.fail("unknown material " + describe_json(name.json()) + " (defined: " + known + ")");
    }
    return static_cast<int>(it - material_names.begin());
  };
  if (const auto pairs = c->find("pairs")) {
    // Series columns name a pair "<a>.<b>" (friction_work_first.a.b, contact_heat_rate.a.b, ...): two
    // pairs whose names join alike ('a' + 'b.c', 'a.b' + 'c') would give one column twice (issue 34:
    // validate passed, the run failed). Each pair's joined names, both orders, to its index.
    std::map<std::string, std::size_t> joined;
    std::set<std::pair<int, int>> listed;
    for (const JsonReader& p : pairs->elements()) {
      if (!p.is_object()) p.expected("an object with \"materials\": [a, b] and a \"law\"");
      const JsonReader mats = p.at("materials", "an array of two material names");
      const auto names = mats.elements();
      if (names.size() != 2) mats.expected("an array of two material names");
      ContactPairSpec ps;
      ps.material_a = material_id(names[0]);
      ps.material_b = material_id(names[1]);
      if (ps.material_a == ps.material_b) mats.fail("expected two different materials");
      if (!listed.emplace(std::min(ps.material_a, ps.material_b), std::max(ps.material_a, ps.material_b)).second)
        mats.fail("this pair is already listed");
      const std::string& a = material_names[static_cast<std::size_t>(ps.material_a)];
      const std::string& b = material_names[static_cast<std::size_t>(ps.material_b)];
      for (const std::string& name : {a + "." + b, b + "." + a})
        if (const auto it = joined.find(name); it != joined.end())
          mats.fail("the names '" + a + "' and '" + b + "' joined with '.' give '" + name + "', as the materials of " +
                    "contact.pairs[" + std::to_string(it->second) + "] do: the series columns (friction_work_first." +
                    name + ", ...) would be one; rename a material so that joined names differ");
      joined.emplace(a + "." + b, spec.pairs.size());
      joined.emplace(b + "." + a, spec.pairs.size());
      ps.settings = o.default_pair;
      if (const auto m = p.find("method")) {
        ps.settings.method = mechanics::contact_method_from_string(m->as_choice({"multimaterial", "penalty"}));
        if (ps.settings.method == mechanics::ContactMethod::penalty && dim != 2)
          m->fail("penalty contact is 2D only (expected \"multimaterial\" in 3D)");
      }
      const JsonReader law = p.at("law", "a friction law");
      ps.settings.law = parse_friction_law(law);
      ps.settings.origin = law.path();
      check_penalty_law(ps.settings, law);
      if (const auto n = p.find("normal")) parse_normal(*n, dim, true, ps.settings);
      if (const auto pen = p.find("penalty")) parse_penalty(*pen, ps.settings.penalty);
      if (const auto m = p.find("master")) {
        const int id = material_id(*m);
        if (id != ps.material_a && id != ps.material_b) m->fail("expected one of the pair's two materials");
        ps.settings.penalty.master = id;
      }
      p.finish();
      spec.pairs.push_back(ps);
    }
  }
  parse_detection(*c, spec);
  c->finish();
  return spec;
}

}  // namespace frictherm::coupling
