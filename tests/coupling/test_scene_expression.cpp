// Friction laws written as expressions in scenes ("type": "expression", docs/contact.md): the scene's
// law is the mechanics law it names, and every bad expression is refused naming its key path, by
// the parser and by `frictherm validate` with exit code 2.
#include "test_scene_support.hpp"

#include <frictherm/coupling/scene_contact.hpp>
#include <frictherm/mechanics/friction.hpp>

#include <gmock/gmock.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

using frictherm::coupling::Json;
using frictherm::coupling::JsonReader;
using frictherm::coupling::parse_friction_law;
using frictherm::coupling::test::good_scene;
using frictherm::coupling::test::scene_error;
using frictherm::mechanics::ContactImpulse;
using frictherm::mechanics::FrictionLaw;
using ::testing::HasSubstr;
using ::testing::StartsWith;

namespace {

/// Two materials in contact; pair 0 has the given law.
Json expression_scene(const Json& law) {
  Json s = good_scene();
  s["materials"]["base"] = s["materials"]["steel"];
  s["bodies"].push_back(Json::parse(R"({"name": "floor", "material": "base",
      "shape": {"type": "rectangle", "lo": [0.0, 0.0], "hi": [0.2, 0.02]}})"));
  s["contact"] = Json::parse(R"({"pairs": [{"materials": ["base", "steel"], "normal": [0, 1]}]})");
  s["contact"]["pairs"][0]["law"] = law;
  return s;
}

Json expression_law(const std::string& text, const Json& constants = Json()) {
  Json law = {{"type", "expression"}, {"sliding_traction", text}};
  if (!constants.is_null()) law["constants"] = constants;
  return law;
}

}  // namespace

TEST(SceneExpressionLaw, BuildsTheLawItWrites) {
  const Json law = expression_law("((mu_s*v_half + mu_d*v)/(v_half + v) + k*v)*N + S_a",
                                  {{"mu_s", 0.35}, {"mu_d", 0.2}, {"v_half", 0.05}, {"k", 0.02}, {"S_a", 3e5}});
  const auto scene = frictherm::coupling::parse_scene(expression_scene(law).dump());
  const FrictionLaw& e = scene.contact.pairs.at(0).settings.law;
  EXPECT_EQ(e.kind(), frictherm::mechanics::FrictionKind::user);
  EXPECT_THAT(e.describe(), StartsWith("user(expression: S = ((mu_s*v_half"));
  // Same outcome as the composite law it spells out, at a node sticking and at nodes sliding.
  const FrictionLaw c = FrictionLaw::composite(0.35, 0.2, 0.05, 0.02, 3e5);
  const double n_star = 1e-7;  // N = 1 MPa on A_c = 1e-6 m² over dt = 1e-7 s
  for (double d_t : {0.3e-7, 0.8e-7, 3e-7, 1e-5}) {
    const ContactImpulse node{-n_star, d_t, 2e-6, 1e-6, 1e-7};
    const auto a = e.in_contact(node), b = c.in_contact(node);
    ASSERT_EQ(a.stick, b.stick) << d_t;
    EXPECT_NEAR(a.slide_impulse, b.slide_impulse, 1e-10 * b.slide_impulse) << d_t;  // root finder, 1e-14 brackets
  }
  EXPECT_NO_THROW(frictherm::coupling::build_simulation<2>(scene));
}

TEST(SceneExpressionLaw, MistakesNameTheKeyPath) {
  const std::string at = "contact.pairs[0].law.";
  EXPECT_THAT(scene_error(expression_scene(expression_law("mu_s*N +", {{"mu_s", 0.3}}))),
              AllOf(StartsWith(at + "sliding_traction: cannot parse \"mu_s*N +\": Unexpected end of expression"),
                    HasSubstr("position 9")));
  EXPECT_THAT(scene_error(expression_scene(expression_law("mu*N"))),
              StartsWith(at + "sliding_traction: unknown variable mu in \"mu*N\" (the variables are N [Pa], A [m^2], v [m/s]"));
  EXPECT_THAT(scene_error(expression_scene(expression_law("0.3*N - 1e3*v"))),
              StartsWith(at + "sliding_traction: the sliding traction \"0.3*N - 1e3*v\" gives S = -1 Pa at N = 0 Pa"));
  EXPECT_THAT(scene_error(expression_scene(expression_law("log(N)"))),
              StartsWith(at + "sliding_traction: the sliding traction \"log(N)\" gives S = -inf Pa at N = 0 Pa"));
  EXPECT_THAT(scene_error(expression_scene(expression_law("sqrt(0.5 - v)*N"))),
              AllOf(StartsWith(at + "sliding_traction: the sliding traction"), HasSubstr("nan Pa at N = 0 Pa, A = 1e-10 m^2, v = 1 m/s")));
  EXPECT_THAT(scene_error(expression_scene(expression_law("N", {{"v", 1}}))),
              StartsWith(at + "constants.v: the name 'v' is a variable"));
  EXPECT_THAT(scene_error(expression_scene(expression_law("N", {{"mu", "high"}}))),
              StartsWith(at + "constants.mu: expected a number"));
  EXPECT_THAT(scene_error(expression_scene(expression_law("N", Json::array()))), StartsWith(at + "constants: expected an object"));
  Json law = expression_law("0.3*N");
  law["sliding_traction"] = 0.3;
  EXPECT_THAT(scene_error(expression_scene(law)), StartsWith(at + "sliding_traction: expected a string"));
  law = expression_law("0.3*N");
  law["static_traction"] = "0.4*N";  // the stick limit is the expression at v = 0
  EXPECT_THAT(scene_error(expression_scene(law)), StartsWith(at + "static_traction: unknown key"));
  law.erase("static_traction");
  law.erase("sliding_traction");
  EXPECT_THAT(scene_error(expression_scene(law)), StartsWith(at + "sliding_traction: required key missing"));
}

namespace {
struct CliRun {
  int code = -1;
  std::string output;
};
CliRun validate(const Json& scene, const std::string& name) {
  const auto path = std::filesystem::temp_directory_path() / (name + "_" + std::to_string(getpid()) + ".json");
  std::ofstream(path) << scene.dump(2);
  const std::string cmd = std::string("'") + FRICTHERM_EXE + "' validate '" + path.string() + "' 2>&1";
  CliRun r;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
    const int status = pclose(p);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  std::filesystem::remove(path);
  return r;
}
}  // namespace

TEST(SceneExpressionLaw, ValidateExitsTwoNamingTheKey) {
  const CliRun ok = validate(expression_scene(expression_law("mu_s*N", {{"mu_s", 0.3}})), "expr_ok");
  EXPECT_EQ(ok.code, 0) << ok.output;
  const std::pair<std::string, std::string> bad[] = {
      {"0.3*N +", "contact.pairs[0].law.sliding_traction: cannot parse"},
      {"0.3*N*x", "contact.pairs[0].law.sliding_traction: unknown variable x"},
      {"0.3*N - 1e3*v", "contact.pairs[0].law.sliding_traction: the sliding traction \"0.3*N - 1e3*v\" gives S = -1 Pa"},
      {"0.3*N/v", "nan Pa at N = 0 Pa, A = 1e-10 m^2, v = 0 m/s"}};
  for (const auto& [text, message] : bad) {
    const CliRun r = validate(expression_scene(expression_law(text)), "expr_bad");
    EXPECT_EQ(r.code, 2) << text << "\n" << r.output;
    EXPECT_THAT(r.output, AllOf(HasSubstr("contact.pairs[0].law.sliding_traction: "), HasSubstr(message))) << text;
  }
}
