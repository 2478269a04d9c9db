// Scene keys of the heat sources (issue 5): plastic heating, the reaction, runaway criteria and
// stop_when_decided — parsed values and the validation messages (key path + what was expected).
#include "test_scene_support.hpp"

#include <frictherm/thermal/reaction.hpp>

#include <gmock/gmock.h>

#include <cmath>

namespace fc = frictherm::coupling;
namespace ft = frictherm::thermal;
using fc::Json;
using fc::test::good_scene;
using fc::test::scene_error;
using ::testing::HasSubstr;

namespace {

Json heat_scene() {
  Json s = good_scene();
  s["thermal"] = Json::parse(R"({"materials": {"steel": {"heat_capacity": 490, "conductivity": 45}}})");
  s["coupling"] = Json::object();
  return s;
}

}  // namespace

TEST(SceneHeatSources, DefaultsAreOff) {
  const fc::Scene s = fc::parse_scene(heat_scene().dump());
  EXPECT_FALSE(s.thermal.coupler.plastic.enabled);
  EXPECT_FALSE(s.thermal.coupler.reaction.enabled);
  EXPECT_FALSE(s.thermal.stop_when_decided);
  EXPECT_EQ(s.thermal.coupler.fates.runaway_progress, 0.5);
  EXPECT_TRUE(std::isinf(s.thermal.coupler.fates.runaway_temperature));
}

TEST(SceneHeatSources, ParsesPlasticHeatingReactionAndFates) {
  Json j = heat_scene();
  j["coupling"] = Json::parse(R"({"plastic_heating": true,
      "continuation": {"duration": 1e-6, "stop_when_decided": true},
      "hotspots": {"runaway_progress": 0.9, "runaway_temperature": 1500}})");
  j["thermal"]["reaction"] = Json::parse(R"({"kinetics": "hmx_rogers1975", "materials": ["steel"]})");
  fc::Scene s = fc::parse_scene(j.dump());
  EXPECT_TRUE(s.thermal.coupler.plastic.enabled);
  EXPECT_EQ(s.thermal.coupler.plastic.taylor_quinney.at(0), 0.9);  // the default fraction
  EXPECT_TRUE(s.thermal.coupler.reaction.enabled);
  EXPECT_TRUE(s.thermal.coupler.reaction.reacts(0));
  EXPECT_EQ(s.thermal.coupler.reaction.kinetics.prefactor, ft::hmx_kinetics_rogers1975().prefactor);
  EXPECT_TRUE(s.thermal.stop_when_decided);
  EXPECT_EQ(s.thermal.coupler.fates.runaway_progress, 0.9);
  EXPECT_EQ(s.thermal.coupler.fates.runaway_temperature, 1500.0);

  j["thermal"]["materials"]["steel"]["taylor_quinney"] = 0.6;
  j["thermal"]["reaction"]["kinetics"] = Json::parse(
      R"({"prefactor": 1e10, "activation_energy": 1.5e5, "heat_of_reaction": 1e6})");
  s = fc::parse_scene(j.dump());
  EXPECT_EQ(s.thermal.coupler.plastic.taylor_quinney.at(0), 0.6);
  EXPECT_EQ(s.thermal.coupler.reaction.kinetics.prefactor, 1e10);
  EXPECT_NEAR(s.thermal.coupler.reaction.kinetics.activation_temperature, 1.5e5 / ft::kGasConstant, 1e-9);
  EXPECT_EQ(s.thermal.coupler.reaction.kinetics.specific_heat_of_reaction, 1e6);
}

TEST(SceneHeatSources, BadInputNamesTheKey) {
  Json j = heat_scene();
  j["thermal"]["materials"]["steel"]["taylor_quinney"] = 0.9;
  EXPECT_THAT(scene_error(j), HasSubstr("thermal.materials.steel.taylor_quinney: only used with"));
  j["coupling"]["plastic_heating"] = true;
  j["thermal"]["materials"]["steel"]["taylor_quinney"] = 1.5;
  EXPECT_THAT(scene_error(j), HasSubstr("thermal.materials.steel.taylor_quinney: expected"));

  j = heat_scene();
  j["thermal"]["reaction"] = Json::parse(R"({"kinetics": "tnt", "materials": ["steel"]})");
  EXPECT_THAT(scene_error(j), HasSubstr("thermal.reaction.kinetics"));
  j["thermal"]["reaction"] = Json::parse(R"({"kinetics": "hmx_rogers1975", "materials": ["hmx"]})");
  EXPECT_THAT(scene_error(j), HasSubstr("thermal.reaction.materials[0]: no material of this name"));
  j["thermal"]["reaction"] = Json::parse(R"({"kinetics": {"prefactor": 1e10, "activation_energy": -1,
                                                          "heat_of_reaction": 1e6}, "materials": ["steel"]})");
  EXPECT_THAT(scene_error(j), HasSubstr("thermal.reaction.kinetics.activation_energy: expected"));
  j["thermal"]["reaction"] = Json::parse(R"({"kinetics": "hmx_rogers1975", "materials": ["steel"], "order": 1})");
  EXPECT_THAT(scene_error(j), HasSubstr("thermal.reaction.order: unknown key"));

  j = heat_scene();
  j["coupling"]["hotspots"] = Json::parse(R"({"runaway_progress": 0})");
  EXPECT_THAT(scene_error(j), HasSubstr("coupling.hotspots.runaway_progress: expected"));
  j["coupling"]["hotspots"] = Json::object();
  j["coupling"]["continuation"] = Json::parse(R"({"duration": 1e-6, "stop_when_decided": "yes"})");
  EXPECT_THAT(scene_error(j), HasSubstr("coupling.continuation.stop_when_decided"));
}
