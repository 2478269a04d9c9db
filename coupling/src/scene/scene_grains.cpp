// Scene parsing: image microstructures with every grain its own material (Nairn, Bardenhagen &
// Smith 2018, section 3: each HMX particle a separate material, so that friction acts between
// grains and between grains and binder). A grain material is a copy of a declared "template"
// material named "<template>#<k>"; contact pairs and thermal properties given for the template
// apply to its grains.
#include "scene/scene_detail.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <cstdint>
#include <unordered_set>
#include <stdexcept>

namespace frictherm::coupling::detail {

namespace {

// nm² per-pair tables in the mechanics (pair settings, pair work): 2000 materials ~ 80 MB.
constexpr std::size_t kMaxMaterials = 2000;
constexpr double kMaxContactPairs = 2e5;  // material pairs after grain expansion (each holds its own law)

}  // namespace

int add_grain_material(Scene& s, ParseContext& ctx, int template_id, const std::string& name,
                       const JsonReader& where) {
  if (std::find(ctx.material_names.begin(), ctx.material_names.end(), name) != ctx.material_names.end())
    where.fail("the grain material name \"" + name + "\" is already taken (rename the material called \"" + name +
               "\")");
  if (s.materials.size() >= kMaxMaterials)
    where.fail("more than " + std::to_string(kMaxMaterials) +
               " materials with one per grain; expected fewer grains (or grains not split into materials)");
  mechanics::Material m = s.materials[static_cast<std::size_t>(template_id)];
  m.name = name;
  s.materials.push_back(m);
  ctx.material_names.push_back(name);
  ctx.grain_template.resize(s.materials.size() - 1, -1);
  ctx.grain_template.push_back(template_id);
  return static_cast<int>(s.materials.size()) - 1;
}

void split_image_levels(const std::vector<LevelSplit>& splits, Scene& s, ParseContext& ctx, ShapeSpec& out) {
  const mechanics::GreyImage& img = out.image;
  out.pixel_materials = mechanics::materials_by_level(img, out.levels);
  // The level deciding each pixel (the first whose range holds its grey), as materials_by_level does.
  std::vector<int> level_of(img.pixels.size(), -1);
  for (std::size_t k = 0; k < img.pixels.size(); ++k)
    for (std::size_t i = 0; i < out.levels.size(); ++i)
      if (img.pixels[k] >= out.levels[i].min_level && img.pixels[k] <= out.levels[i].max_level) {
        level_of[k] = static_cast<int>(i);
        break;
      }
  for (const LevelSplit& split : splits) {
    const int tmpl = out.levels[split.level].material;
    const std::string base = s.materials[static_cast<std::size_t>(tmpl)].name;  // a copy: materials grow below
    if (split.by_grey_level) {
      std::set<int> greys;
      for (std::size_t k = 0; k < img.pixels.size(); ++k)
        if (level_of[k] == static_cast<int>(split.level)) greys.insert(img.pixels[k]);
      std::map<int, int> material_of_grey;
      for (int g : greys) {  // the same grey level is the same material in every body
        const std::string name = base + "#" + std::to_string(g);
        const auto it = std::find(ctx.material_names.begin(), ctx.material_names.end(), name);
        const std::size_t id = static_cast<std::size_t>(it - ctx.material_names.begin());
        material_of_grey[g] = (it != ctx.material_names.end() && id < ctx.grain_template.size() &&
                               ctx.grain_template[id] == tmpl)
                                  ? static_cast<int>(id)
                                  : add_grain_material(s, ctx, tmpl, name, split.where);
      }
      for (std::size_t k = 0; k < img.pixels.size(); ++k)
        if (level_of[k] == static_cast<int>(split.level)) out.pixel_materials.material[k] = material_of_grey[img.pixels[k]];
    } else {
      mechanics::GreyImage mask = img;  // 1 where this level decides the pixel
      for (std::size_t k = 0; k < img.pixels.size(); ++k) mask.pixels[k] = level_of[k] == static_cast<int>(split.level);
      const mechanics::GrainLabels labels = mechanics::label_grains(mask, 1, 1, split.connectivity);
      std::size_t existing = 0;  // grains of this template in earlier bodies: numbering continues
      for (int t : ctx.grain_template) existing += t == tmpl;
      std::vector<int> material_of_label(static_cast<std::size_t>(labels.count()) + 1, -1);
      for (int l = 1; l <= labels.count(); ++l)
        material_of_label[static_cast<std::size_t>(l)] =
            add_grain_material(s, ctx, tmpl, base + "#" + std::to_string(existing + static_cast<std::size_t>(l)), split.where);
      for (std::size_t k = 0; k < img.pixels.size(); ++k)
        if (labels.label[k] > 0) out.pixel_materials.material[k] = material_of_label[static_cast<std::size_t>(labels.label[k])];
    }
  }
}

void expand_grain_contact_pairs(Scene& s, const ParseContext& ctx) {
  if (!s.contact.enabled || ctx.grain_template.empty()) return;
  // The template itself and its grains, gathered once (linear in the materials).
  std::map<int, std::vector<int>> members;
  for (std::size_t id = 0; id < ctx.grain_template.size(); ++id)
    if (ctx.grain_template[id] >= 0) members[ctx.grain_template[id]].push_back(static_cast<int>(id));
  auto members_of = [&](int m) {
    std::vector<int> out{m};
    const auto it = members.find(m);
    if (it != members.end()) out.insert(out.end(), it->second.begin(), it->second.end());
    return out;
  };
  // Bounded before anything is generated: every listed pair expands to |A| x |B| pairs.
  double total = 0.0;
  for (std::size_t i = 0; i < s.contact.pairs.size(); ++i) {
    const ContactPairSpec& p = s.contact.pairs[i];
    const double n = static_cast<double>(members_of(p.material_a).size()) * static_cast<double>(members_of(p.material_b).size());
    total += n;
    if (total > kMaxContactPairs)
      throw SceneError("contact.pairs[" + std::to_string(i) + "]: the grains of its materials make " + format_number(total) +
                       " material pairs with the pairs before it; expected at most " + format_number(kMaxContactPairs) +
                       " (fewer grains, or pair the binder with the grain template only where needed)");
  }
  // Explicit pairs win over expansions; a hash set of unordered pairs keeps the expansion linear.
  auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(std::min(a, b))) << 32) |
           static_cast<std::uint32_t>(std::max(a, b));
  };
  std::unordered_set<std::uint64_t> listed;
  for (const ContactPairSpec& q : s.contact.pairs) listed.insert(key(q.material_a, q.material_b));
  const std::vector<ContactPairSpec> given = s.contact.pairs;
  for (const ContactPairSpec& p : given)
    for (int a : members_of(p.material_a))
      for (int b : members_of(p.material_b)) {
        if (a == b || !listed.insert(key(a, b)).second) continue;
        ContactPairSpec e = p;
        e.material_a = a;
        e.material_b = b;
        s.contact.pairs.push_back(e);
      }
}

void extend_grain_thermal(Scene& s, const ParseContext& ctx) {
  if (!s.thermal.enabled) return;
  // Every per-material table of the thermal sections is sized to the declared materials; a grain
  // material takes its template's entry (properties, Taylor–Quinney fraction, whether it reacts).
  auto extend = [&](auto& table) {
    if (table.size() != ctx.declared_materials) return;  // not used by this scene (empty)
    for (std::size_t id = table.size(); id < s.materials.size(); ++id) {
      const int t = id < ctx.grain_template.size() ? ctx.grain_template[id] : -1;
      if (t < 0) throw std::logic_error("material " + s.materials[id].name + " is neither declared nor a grain");
      const auto entry = table[static_cast<std::size_t>(t)];
      table.push_back(entry);
    }
  };
  extend(s.thermal.coupler.materials);
  extend(s.thermal.coupler.plastic.taylor_quinney);
  extend(s.thermal.coupler.reaction.reacting);
}

}  // namespace frictherm::coupling::detail
