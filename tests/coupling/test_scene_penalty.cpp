// Scene keys of penalty contact (coupling/src/scene/scene_contact.cpp, docs/scenes.md): the method for all
// pairs or per pair, penalty settings, master, boundary spacing; errors name the key path; the
// sliding-block example runs with either method from one key.
#include "test_scene_support.hpp"

#include <gmock/gmock.h>

#include <cmath>

namespace fc = frictherm::coupling;
namespace fm = frictherm::mechanics;
using fc::Json;
using fc::test::scene_error;
using ::testing::HasSubstr;
using ::testing::StartsWith;

namespace {

/// Two blocks of different stiffness, one on the other, with a contact section to fill in.
Json two_blocks(const Json& contact) {
  Json s = Json::parse(R"({
    "units": "SI", "dimension": 2,
    "grid": {"lo": [0, 0], "hi": [0.2, 0.1], "cell_size": 0.01},
    "materials": {"soft": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e9, "poisson_ratio": 0.3},
                  "hard": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 4e9, "poisson_ratio": 0.3}},
    "bodies": [{"name": "bottom", "material": "soft", "shape": {"type": "rectangle", "lo": [0.02, 0.02], "hi": [0.18, 0.05]}},
               {"name": "top", "material": "hard", "shape": {"type": "rectangle", "lo": [0.06, 0.05], "hi": [0.12, 0.07]}}],
    "run": {"end_time": 1e-5}
  })");
  s["contact"] = contact;
  return s;
}

}  // namespace

TEST(ScenePenalty, MethodPenaltySetsEveryPairAndTheStifferBodyIsMaster) {
  const fc::Scene scene = fc::parse_scene(two_blocks(Json::parse(R"({"method": "penalty",
      "law": {"type": "coulomb", "mu": 0.3}, "boundary_spacing": 0.004,
      "penalty": {"normal_factor": 2.0, "tangential": 1e11, "tangential_law": "incremental"}})")).dump());
  EXPECT_EQ(scene.contact.options.default_pair.method, fm::ContactMethod::penalty);
  EXPECT_DOUBLE_EQ(scene.contact.options.boundary_spacing, 0.004);
  auto sim = fc::build_simulation<2>(scene);
  ASSERT_NE(sim->penalty_contact(), nullptr);
  ASSERT_EQ(sim->penalty_pairs().size(), 1u);
  EXPECT_EQ(sim->penalty_pairs()[0].master_material, 1);  // "hard": the stiffer one
  const fm::PenaltyPairSettings& p = sim->penalty_contact()->pair(0);
  EXPECT_DOUBLE_EQ(p.normal_penalty, 2.0 * 1e9 / 0.01);  // factor × E/Δh with the smaller E (K·40)
  EXPECT_DOUBLE_EQ(p.tangential_penalty, 1e11);
  EXPECT_DOUBLE_EQ(p.mu, 0.3);
  EXPECT_EQ(p.law, fm::TangentialLaw::incremental);
  // Boundary points from the rectangles: perimeters 0.38 m and 0.16 m at ≤ 4 mm spacing.
  const auto& bp = sim->boundary_points();
  ASSERT_EQ(bp.loop_count(), 2u);
  EXPECT_NEAR(bp.loop_perimeter(0), 0.38, 1e-12);
  EXPECT_NEAR(bp.loop_perimeter(1), 0.16, 1e-12);
  EXPECT_EQ(bp.size(), 96u + 40u);  // edges cut into ceil(length / 0.004) parts: 2 (40 + 8), 2 (15 + 5)
  EXPECT_NO_THROW(sim->step());
}

TEST(ScenePenalty, PerPairMethodMasterAndPenalty) {
  const fc::Scene scene = fc::parse_scene(two_blocks(Json::parse(R"({"pairs": [{"materials": ["soft", "hard"],
      "method": "penalty", "master": "soft", "law": "frictionless", "penalty": {"normal": 3e11}}]})")).dump());
  EXPECT_EQ(scene.contact.options.default_pair.method, fm::ContactMethod::multimaterial);
  auto sim = fc::build_simulation<2>(scene);
  ASSERT_EQ(sim->penalty_pairs().size(), 1u);
  EXPECT_EQ(sim->penalty_pairs()[0].master_material, 0);
  EXPECT_DOUBLE_EQ(sim->penalty_contact()->pair(0).normal_penalty, 3e11);
  EXPECT_DOUBLE_EQ(sim->penalty_contact()->pair(0).mu, 0.0);
  // The default boundary spacing is half a cell.
  EXPECT_EQ(sim->boundary_points().size(), 76u + 32u);
}

TEST(ScenePenalty, ErrorsNameTheKeyPath) {
  EXPECT_THAT(scene_error(two_blocks(Json::parse(R"({"method": "mortar"})"))),
              StartsWith("contact.method: "));
  EXPECT_THAT(scene_error(two_blocks(Json::parse(R"({"method": "penalty", "law": {"type": "adhesion", "mu": 0.2, "shear_strength": 1e4}})"))),
              AllOf(StartsWith("contact.law: "), HasSubstr("coulomb")));
  EXPECT_THAT(scene_error(two_blocks(Json::parse(R"({"method": "penalty", "penalty": {"normal": -1}})"))),
              StartsWith("contact.penalty.normal: "));
  EXPECT_THAT(scene_error(two_blocks(Json::parse(R"({"method": "penalty", "penalty": {"normal": 1e11, "normal_factor": 2}})"))),
              StartsWith("contact.penalty.normal_factor: "));
  EXPECT_THAT(scene_error(two_blocks(Json::parse(R"({"method": "penalty", "penalty": {"stiffness": 1}})"))),
              StartsWith("contact.penalty.stiffness: unknown key"));
  EXPECT_THAT(scene_error(two_blocks(Json::parse(R"({"method": "penalty", "penalty": {"tangential_law": "spring"}})"))),
              StartsWith("contact.penalty.tangential_law: "));
  EXPECT_THAT(scene_error(two_blocks(Json::parse(R"({"pairs": [{"materials": ["soft", "hard"], "method": "penalty",
      "master": "steel", "law": "frictionless"}]})"))),
              StartsWith("contact.pairs[0].master: "));
  EXPECT_THAT(scene_error(two_blocks(Json::parse(R"({"pairs": [{"materials": ["soft", "hard"], "method": "penalty",
      "law": "stick"}]})"))),
              StartsWith("contact.pairs[0].law: "));
  EXPECT_THAT(scene_error(two_blocks(Json::parse(R"({"method": "penalty", "boundary_spacing": -0.1})"))),
              StartsWith("contact.boundary_spacing: "));
}

// examples/sliding_block.json with `--set contact.method=penalty`: the same scene runs with penalty
// contact (its pair's normal is ignored), and the block's boundary points start on the base's.
TEST(ScenePenalty, SlidingBlockExampleSwitchesMethodByOneKey) {
  const std::string file = std::string(FRICTHERM_SOURCE_DIR) + "/examples/sliding_block.json";
  const fc::Scene mm = fc::load_scene(file);
  const fc::Scene pen = fc::load_scene(file, {fc::parse_override("contact.method=penalty")});
  EXPECT_EQ(mm.contact.pairs.at(0).settings.method, fm::ContactMethod::multimaterial);
  EXPECT_EQ(pen.contact.pairs.at(0).settings.method, fm::ContactMethod::penalty);
  auto sim = fc::build_simulation<2>(pen);
  ASSERT_NE(sim->penalty_contact(), nullptr);
  EXPECT_EQ(sim->penalty_pairs()[0].master_material, 0);  // equal E: the heavier base
  for (int k = 0; k < 20; ++k) sim->step();
  EXPECT_GT(sim->contact_stats().penalty_contacts, 0);
  EXPECT_EQ(fc::build_simulation<2>(mm)->penalty_contact(), nullptr);
  // Every scheme counts them: under USF the boundary points move (and are counted) before the
  // multimaterial pass of the momentum update, whose counters must not reset penalty contact's.
  for (const char* scheme : {"usf", "usl", "musl"}) {
    const std::string scheme_key = std::string("solver.scheme=\"") + scheme + "\"";
    auto s = fc::build_simulation<2>(
        fc::load_scene(file, {fc::parse_override("contact.method=penalty"), fc::parse_override(scheme_key)}));
    for (int k = 0; k < 20; ++k) s->step();
    EXPECT_GT(s->contact_stats().penalty_contacts, 0) << scheme;
  }
}
