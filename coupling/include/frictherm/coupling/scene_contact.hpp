#pragma once
// The scene section `contact` (docs/scenes.md, docs/contact.md): multimaterial contact with a friction
// law per material pair.
//
//   "contact": {"normal": "mvg", "separation": "position", "position_correction": 0.8,
//               "law": {"type": "coulomb", "mu": 0.3},
//               "pairs": [{"materials": ["base", "block"], "normal": [0, 1],
//                          "law": {"type": "adhesion", "mu": 0.2, "shear_strength": 4.4e4}}]}
//
// Penalty contact on boundary points (Kakouris 2024, 2D; docs/penalty_contact.md) for all pairs or
// per pair, with the same laws (coulomb or frictionless), so a scene switches method by one key:
//
//   "contact": {"method": "penalty", "boundary_spacing": 0.0025,
//               "penalty": {"normal_factor": 1.0, "tangential_law": "return_mapping"},
//               "pairs": [{"materials": ["base", "block"], "law": {"type": "coulomb", "mu": 0.2},
//                          "master": "base", "penalty": {"normal": 5e11}}]}
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

/// A friction law object: {"type": "coulomb", "mu": 0.2}, ..., {"type": "expression",
/// "sliding_traction": "mu_s*N + S_a", "constants": {"mu_s": 0.3, "S_a": 1e4}}, or the bare strings
/// "stick" and "frictionless".
mechanics::FrictionLaw parse_friction_law(const JsonReader& law);

/// Reads the optional `contact` section; material names resolve against `material_names`.
ContactSpec parse_contact_section(const JsonReader& root, int dimension, const std::vector<std::string>& material_names);

}  // namespace frictherm::coupling
