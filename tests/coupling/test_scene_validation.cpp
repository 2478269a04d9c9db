// Scene validation: one test per class of mistake; every message must name the key path.
#include "test_scene_support.hpp"

#include <gmock/gmock.h>

#include <cmath>

using frictherm::coupling::Json;
using frictherm::coupling::parse_scene;
using frictherm::coupling::test::good_scene;
using frictherm::coupling::test::scene_error;
using ::testing::HasSubstr;
using ::testing::StartsWith;

TEST(SceneValidation, GoodSceneParses) { EXPECT_NO_THROW(parse_scene(good_scene().dump())); }

TEST(SceneValidation, MalformedJsonGivesLineAndColumn) {
  const std::string text = "{\n  \"dimension\": 2,\n  \"grid\": {\"lo\": [0, 0],, \"hi\": [1, 1]}\n}\n";
  const std::string msg = scene_error(text);
  EXPECT_THAT(msg, StartsWith("malformed JSON at line 3, column"));
  const std::string unterminated = scene_error(std::string("{\"dimension\": 2,\n\"grid\": {"));
  EXPECT_THAT(unterminated, HasSubstr("malformed JSON at line 2"));
}

TEST(SceneValidation, CommentsAreAllowed) {
  std::string text = good_scene().dump(2);
  text = "// a comment\n/* another */\n" + text;
  EXPECT_NO_THROW(parse_scene(text));
}

TEST(SceneValidation, UnknownKeyNamesPathAndAllowedKeys) {
  Json s = good_scene();
  s["grid"]["cellsize"] = 0.01;
  EXPECT_THAT(scene_error(s), AllOf(StartsWith("grid.cellsize: unknown key"), HasSubstr("cell_size")));
  s = good_scene();
  s["bodies"][0]["shape"]["radius"] = 0.1;
  EXPECT_THAT(scene_error(s), StartsWith("bodies[0].shape.radius: unknown key (allowed here: type, lo, hi)"));
  s = good_scene();
  s["bodys"] = Json::array();
  EXPECT_THAT(scene_error(s), StartsWith("bodys: unknown key"));
  s = good_scene();
  s["materials"]["steel"]["yield_stress"] = 1e8;
  EXPECT_THAT(scene_error(s), StartsWith("materials.steel.yield_stress: unknown key"));
}

TEST(SceneValidation, WrongTypeNamesPathExpectedAndGot) {
  Json s = good_scene();
  s["run"]["end_time"] = "soon";
  EXPECT_EQ(scene_error(s), "run.end_time: expected a number > 0, got \"soon\"");
  s = good_scene();
  s["bodies"] = Json::object();
  EXPECT_THAT(scene_error(s), StartsWith("bodies: expected an array"));
  s = good_scene();
  s["dimension"] = 2.5;
  EXPECT_EQ(scene_error(s), "dimension: expected an integer in [2, 3], got 2.5");
  s = good_scene();
  s["bodies"][0]["particles_per_cell"] = "two";
  EXPECT_THAT(scene_error(s), StartsWith("bodies[0].particles_per_cell: expected an integer"));
}

TEST(SceneValidation, DensityMustBePositive) {
  for (double rho : {0.0, -7850.0}) {
    Json s = good_scene();
    s["materials"]["steel"]["density"] = rho;
    EXPECT_THAT(scene_error(s), StartsWith("materials.steel.density: expected a number > 0, got"));
  }
  Json s = good_scene();
  s["materials"]["steel"].erase("density");
  EXPECT_THAT(scene_error(s), StartsWith("materials.steel.density: required key missing"));
}

TEST(SceneValidation, PoissonRatioOutOfRange) {
  Json s = good_scene();
  s["materials"]["steel"]["poisson_ratio"] = 0.7;
  EXPECT_EQ(scene_error(s), "materials.steel.poisson_ratio: expected a number in (-1, 0.5), got 0.7");
  for (double nu : {0.5, -1.0}) {
    s["materials"]["steel"]["poisson_ratio"] = nu;
    EXPECT_THAT(scene_error(s), StartsWith("materials.steel.poisson_ratio: expected a number in (-1, 0.5)"));
  }
}

TEST(SceneValidation, BodyOutsideGridNamesShapeAndGridExtent) {
  Json s = good_scene();
  s["bodies"].push_back(Json::parse(R"({"name": "disk", "material": "steel",
      "shape": {"type": "disk", "center": [0.19, 0.05], "radius": 0.02}})"));
  EXPECT_THAT(scene_error(s), AllOf(StartsWith("bodies[1].shape: "), HasSubstr("not inside the grid"),
                                    HasSubstr("(0, 0) to (0.2, 0.1)")));
}

TEST(SceneValidation, CflFactorMustBeInZeroOne) {
  for (double c : {0.0, -0.1, 1.5}) {
    Json s = good_scene();
    s["solver"] = {{"cfl", c}};
    EXPECT_THAT(scene_error(s), StartsWith("solver.cfl: expected a number in (0, 1], got"));
  }
  Json s = good_scene();
  s["solver"] = {{"cfl", 1.0}};
  EXPECT_NO_THROW(parse_scene(s.dump()));
}

TEST(SceneValidation, PicRelaxationTimeMustBePositive) {
  Json s = good_scene();
  s["solver"] = {{"pic_relaxation_time", 0.0}};
  EXPECT_THAT(scene_error(s), StartsWith("solver.pic_relaxation_time: expected a number > 0"));
  s["solver"] = {{"pic_relaxation_time", 3e-8}};
  EXPECT_DOUBLE_EQ(parse_scene(s.dump()).options.pic_relaxation_time, 3e-8);
  EXPECT_TRUE(std::isinf(parse_scene(good_scene().dump()).options.pic_relaxation_time));  // pure FLIP
}

TEST(SceneValidation, VectorLengthMustMatchDimension) {
  Json s = good_scene();
  s["grid"]["lo"] = {0, 0, 0};
  EXPECT_EQ(scene_error(s),
            "grid.lo: expected an array of 2 numbers (one per dimension), got [0, 0, 0]");
  s = good_scene();
  s["bodies"][0]["velocity"] = {1.0};
  EXPECT_THAT(scene_error(s), StartsWith("bodies[0].velocity: expected an array of 2 numbers"));
  s = good_scene();
  s["loads"] = {{"gravity", {0, 0, -9.81}}};
  EXPECT_THAT(scene_error(s), StartsWith("loads.gravity: expected an array of 2 numbers"));
}

TEST(SceneValidation, UnknownMaterialOrBodyName) {
  Json s = good_scene();
  s["bodies"][0]["material"] = "stel";
  EXPECT_EQ(scene_error(s), "bodies[0].material: unknown material \"stel\" (materials defined: \"steel\")");
  s = good_scene();
  s["loads"] = Json::parse(R"({"traction": [{"body": "blok", "face": "x_max", "traction": [1e6, 0]}]})");
  EXPECT_THAT(scene_error(s), StartsWith("loads.traction[0].body: unknown body \"blok\""));
  s = good_scene();
  s["bodies"].push_back(s["bodies"][0]);
  EXPECT_THAT(scene_error(s), StartsWith("bodies[1].name: the name \"block\" is already used by bodies[0]"));
}

TEST(SceneValidation, MissingImageFile) {
  Json s = good_scene();
  s["bodies"][0] = Json::parse(R"({"name": "img", "shape": {"type": "image", "file": "no_such_image.pgm",
      "origin": [0, 0], "pixel_size": 0.001, "levels": [{"range": [0, 255], "material": "steel"}]}})");
  EXPECT_THAT(scene_error(s), AllOf(StartsWith("bodies[0].shape.file: "), HasSubstr("no_such_image.pgm")));
}

namespace {
Json contact_scene() {
  Json s = good_scene();
  s["materials"]["base"] = s["materials"]["steel"];
  s["bodies"].push_back(Json::parse(R"({"name": "floor", "material": "base",
      "shape": {"type": "rectangle", "lo": [0.0, 0.0], "hi": [0.2, 0.02]}})"));
  s["contact"] = Json::parse(R"({"normal": "avg", "separation": "displacement", "law": "frictionless",
      "pairs": [{"materials": ["base", "steel"], "normal": [0, 2],
                 "law": {"type": "smooth_static_dynamic", "mu_static": 0.4, "mu_dynamic": 0.2, "v_half": 0.05}}]})");
  return s;
}
}  // namespace

TEST(SceneValidation, ContactSectionBuildsPerMaterialFields) {
  const auto scene = parse_scene(contact_scene().dump());
  ASSERT_TRUE(scene.contact.enabled);
  ASSERT_EQ(scene.contact.pairs.size(), 1u);
  const auto sim = frictherm::coupling::build_simulation<2>(scene);
  ASSERT_TRUE(sim->contact_enabled());
  EXPECT_EQ(sim->fields().size(), 2u);  // one velocity field per material
  const int steel = 0, base = 1;  // materials are numbered in file order
  const auto& ab = sim->contact_pair(base, steel);
  EXPECT_EQ(ab.normal, frictherm::mechanics::NormalMethod::specified);
  EXPECT_DOUBLE_EQ(ab.normal_vector[1], 1.0);  // normalised
  EXPECT_DOUBLE_EQ(sim->contact_pair(steel, base).normal_vector[1], -1.0);  // seen from the other side
  EXPECT_EQ(ab.law.kind(), frictherm::mechanics::FrictionKind::smooth_static_dynamic);
  EXPECT_EQ(sim->contact_options().separation, frictherm::mechanics::SeparationMethod::displacement);
  EXPECT_EQ(sim->contact_options().default_pair.normal, frictherm::mechanics::NormalMethod::average_volume_gradient);
  EXPECT_EQ(sim->contact_options().default_pair.law.kind(), frictherm::mechanics::FrictionKind::frictionless);
}

TEST(SceneValidation, ContactMistakesNameTheKey) {
  Json s = contact_scene();
  s["contact"]["law"] = Json::parse(R"({"type": "coulomb", "mu": -0.1})");
  EXPECT_THAT(scene_error(s), StartsWith("contact.law.mu: expected a number >= 0, got -0.1"));
  s = contact_scene();
  s["contact"]["law"] = Json::parse(R"({"type": "sticky"})");
  EXPECT_THAT(scene_error(s), StartsWith("contact.law.type: expected one of"));
  s = contact_scene();
  s["contact"]["pairs"][0]["materials"] = Json::parse(R"(["base", "wood"])");
  EXPECT_THAT(scene_error(s), AllOf(StartsWith("contact.pairs[0].materials[1]: unknown material \"wood\""),
                                    HasSubstr("steel, base")));
  s = contact_scene();
  s["contact"]["normal"] = Json::parse("[0, 1]");
  EXPECT_THAT(scene_error(s), StartsWith("contact.normal: expected \"mvg\" or \"avg\""));
  s = contact_scene();
  s["contact"]["pairs"][0]["normal"] = Json::parse("[0, 0]");
  EXPECT_THAT(scene_error(s), StartsWith("contact.pairs[0].normal: expected a non-zero normal vector"));
  s = contact_scene();
  s["contact"]["pairs"][0]["law"] = Json::parse(R"({"type": "smooth_static_dynamic", "mu_static": 0.4, "mu_dynamic": 0.2, "v_half": 0})");
  EXPECT_THAT(scene_error(s), StartsWith("contact.pairs[0].law.v_half: expected a number > 0"));
  s = contact_scene();
  s["contact"]["pairs"].push_back(Json::parse(R"({"materials": ["steel", "base"], "law": "stick"})"));
  EXPECT_THAT(scene_error(s), StartsWith("contact.pairs[1].materials: this pair is already listed"));
  s = contact_scene();
  s["contact"]["law"] = Json::parse(R"({"type": "tabulated", "speeds": [0, 1], "mu": [0.3]})");
  EXPECT_THAT(scene_error(s), StartsWith("contact.law.mu: expected 2 coefficients"));
  s = contact_scene();
  s["contact"]["separation"] = "gap";
  EXPECT_THAT(scene_error(s), StartsWith("contact.separation: expected one of"));
}

TEST(SceneValidation, RequiredKeysAndChoices) {
  Json s = good_scene();
  s["run"].erase("end_time");
  EXPECT_THAT(scene_error(s), StartsWith("run.end_time: required key missing"));
  s = good_scene();
  s["units"] = "mm";
  EXPECT_EQ(scene_error(s), "units: expected \"SI\", got \"mm\"");
  s = good_scene();
  s["solver"] = {{"scheme", "rk4"}};
  EXPECT_EQ(scene_error(s), "solver.scheme: expected one of \"usf\", \"usl\", \"musl\", got \"rk4\"");
  s = good_scene();
  s["boundary"] = Json::parse(R"({"fixed": [{"face": "z_min"}]})");
  EXPECT_THAT(scene_error(s), StartsWith("boundary.fixed[0].face: expected one of"));
}

TEST(SceneValidation, DimensionSpecificKeys) {
  Json s = good_scene();
  s["dimension"] = 3;
  s["analysis"] = "plane_strain";
  EXPECT_THAT(scene_error(s), StartsWith("analysis: only for 2D scenes"));
  s = good_scene();
  s["analysis"] = "plane_stress";
  s["materials"]["steel"]["type"] = "neo_hookean";
  EXPECT_THAT(scene_error(s), StartsWith("materials.steel.type: neo_hookean needs"));
}

TEST(SceneValidation, GridMustDivideEvenly) {
  Json s = good_scene();
  s["grid"]["cell_size"] = 0.03;
  EXPECT_THAT(scene_error(s), StartsWith("grid.cell_size: expected a cell size that divides hi - lo evenly"));
  s = good_scene();
  s["grid"]["cells"] = {20, 10};
  EXPECT_THAT(scene_error(s), StartsWith("grid: expected exactly one of cell_size"));
}

TEST(SceneValidation, BodyWithoutParticlesIsNamedWhenBuilt) {
  Json s = good_scene();
  Json copy = s["bodies"][0];
  copy["name"] = "shadow";  // same region: every point already taken by the first body
  s["bodies"].push_back(copy);
  EXPECT_THAT(scene_error(s), AllOf(StartsWith("bodies[1]: "), HasSubstr("no particles")));
}

TEST(SceneValidation, MieGruneisenMaterial) {
  Json s = good_scene();
  s["materials"]["steel"] = Json::parse(R"({"type": "mie_gruneisen", "density": 1891, "C0": 3070, "S1": 1.79,
      "gamma0": 0.7, "shear_modulus": 4.81e9, "yield_stress": 2.6e8})");
  const auto scene = parse_scene(s.dump());
  const auto& g = scene.materials.at(0).mie_gruneisen;
  EXPECT_EQ(scene.materials.at(0).kind, frictherm::mechanics::MaterialKind::mie_gruneisen);
  EXPECT_DOUBLE_EQ(g.density, 1891.0);
  EXPECT_DOUBLE_EQ(g.S2, 0.0);
  EXPECT_DOUBLE_EQ(g.yield_stress, 2.6e8);
  EXPECT_NO_THROW(frictherm::coupling::build_simulation<2>(scene));
  s["materials"]["steel"]["S1"] = 12.0;  // Hugoniot singular before 10 % compression
  EXPECT_THAT(scene_error(s), StartsWith("materials.steel.S1: expected S1, S2 whose Hugoniot stays finite"));
  s["materials"]["steel"]["S1"] = 1.79;
  s["analysis"] = "plane_stress";
  EXPECT_THAT(scene_error(s), StartsWith("materials.steel.type: mie_gruneisen needs"));
}

// Issue 15 class 3: numbers outside what the reader can hold are scene errors, never UB or a raw
// nlohmann exception; duplicate keys are refused instead of last-wins.
TEST(SceneValidation, NumbersOutOfRangeAndDuplicateKeysAreRefused) {
  EXPECT_THAT(scene_error(std::string("{\"dimension\": 1e999}")),
              StartsWith("dimension: the number 1e999 at line 1, column"));
  Json s = good_scene();
  s["dimension"] = 9223372036854775808.0;  // 2^63 as a float: rounds to double(LONG_MAX)
  EXPECT_THAT(scene_error(s), StartsWith("dimension: expected an integer in [2, 3]"));
  s["dimension"] = 18446744073709551615ULL;  // unsigned, above LONG_MAX
  EXPECT_THAT(scene_error(s), StartsWith("dimension: expected an integer in [2, 3]"));
  const std::string text = good_scene().dump();
  const std::string twice = "{\"dimension\": 2, " + text.substr(1);
  EXPECT_THAT(scene_error(twice), StartsWith("dimension: duplicate key 'dimension' at line 1, column "));
}

// Issue 15 (fuzzing, docs/robustness.md): scene text beyond the reader's limits is refused with the
// key path, line and column before anything recursive touches it.
TEST(SceneValidation, JsonLimitsNameTheKeyPathAndLine) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_THAT(scene_error(deep), StartsWith("scene: objects and arrays nested deeper than 64 levels at line 1, column 65"));
  const std::string nested = scene_error("{\"description\": " + deep + "}");
  EXPECT_THAT(nested, StartsWith("description: objects and arrays"));
  EXPECT_THAT(nested, HasSubstr("nested deeper than 64 levels at line 1, column 80"));
  Json s = good_scene();
  const std::string text = s.dump(1);
  // A nested overflow names the element: grid.lo[1] on the line of "lo".
  const std::string lo = "\"lo\": [";
  std::string overflow = text;
  const std::size_t at = overflow.find(lo);
  ASSERT_NE(at, std::string::npos);
  const std::size_t first_end = overflow.find(',', at);
  overflow.insert(first_end + 1, " 1e999,");
  EXPECT_THAT(scene_error(overflow), StartsWith("grid.lo[1]: the number 1e999 at line "));
  EXPECT_THAT(scene_error("{\"" + std::string(300, 'k') + "\": 1}"),
              StartsWith("scene: a key of 300 characters at line 1, column 303; expected at most 256"));
  EXPECT_THAT(scene_error("{\"description\": \"" + std::string((1 << 20) + 1, 'x') + "\"}"),
              StartsWith("description: a string of 1048577 characters at line 1"));
  // --set values obey the same limits, named by their key.
  auto set_error = [&text](const std::string& key, const std::string& value) -> std::string {
    try {
      parse_scene(text, "<test>", ".", "scene", {frictherm::coupling::SceneOverride{key, value}});
    } catch (const frictherm::coupling::SceneError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_THAT(set_error("run.end_time", "1e999"), StartsWith("--set run.end_time: the number 1e999 at line 1, column"));
  EXPECT_THAT(set_error("description", deep), StartsWith("--set description: objects and arrays"));
  EXPECT_THAT(set_error("description", deep), HasSubstr("nested deeper than 64 levels"));
}
