#pragma once
// The scene section `contact` (docs/scenes.md, docs/contact.md): multimaterial contact with a friction
// law per material pair.
//
//   "contact": {"normal": "mvg", "separation": "position", "position_correction": 0.8,
//               "law": {"type": "coulomb", "mu": 0.3},
//               "pairs": [{"materials": ["base", "block"], "normal": [0, 1],
//                          "law": {"type": "adhesion", "mu": 0.2, "shear_strength": 4.4e4}}]}
//
// Without a `contact` section all deformable materials share one velocity field.
#include <frictherm/coupling/json_reader.hpp>
#include <frictherm/mechanics/contact.hpp>

#include <string>
#include <vector>

namespace frictherm::coupling {

struct ContactPairSpec {
  int material_a = -1, material_b = -1;  // ids in Scene::materials; a specified normal points from a to b
  mechanics::ContactPairSettings settings;
};

struct ContactSpec {
  bool enabled = false;
  mechanics::ContactOptions options;  // default law and normal for pairs not listed, detection settings
  std::vector<ContactPairSpec> pairs;
};

/// A friction law object: {"type": "coulomb", "mu": 0.2}, ... or the bare strings "stick" and
/// "frictionless".
mechanics::FrictionLaw parse_friction_law(const JsonReader& law);

/// Reads the optional `contact` section; material names resolve against `material_names`.
ContactSpec parse_contact_section(const JsonReader& root, int dimension, const std::vector<std::string>& material_names);

}  // namespace frictherm::coupling
