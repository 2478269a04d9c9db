// Image microstructures in scenes: every connected grain (or grey level) its own material, the
// ellipse_packing shape, the image a run writes, contact pairs and thermal properties of grain
// materials, and examples/pbx_microstructure_small.json.
#include "test_scene_support.hpp"

#include <frictherm/coupling/microstructure.hpp>
#include <frictherm/coupling/runner.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>

namespace fc = frictherm::coupling;
using fc::Json;
using fc::test::good_scene;
using fc::test::scene_error;
using ::testing::HasSubstr;
using ::testing::StartsWith;

namespace {

namespace fs = std::filesystem;

const std::string kExample = std::string(FRICTHERM_SOURCE_DIR) + "/examples/pbx_microstructure_small.json";

int material_index(const fc::Scene& s, const std::string& name) {
  for (std::size_t i = 0; i < s.materials.size(); ++i)
    if (s.materials[i].name == name) return static_cast<int>(i);
  ADD_FAILURE() << "no material " << name;
  return -1;
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("frictherm_micro_" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
};

/// good_scene() with a second material "soft" and body 0 an image body over `file` (0.02 m pixels).
Json image_scene(const std::string& file, const Json& levels) {
  Json s = good_scene();
  s["materials"]["soft"] = {{"type", "linear_elastic"}, {"density", 1000}, {"youngs_modulus", 1e9}, {"poisson_ratio", 0.3}};
  s["bodies"][0] = Json::parse(R"({"name": "img", "shape": {"type": "image", "origin": [0.0, 0.0], "pixel_size": 0.02}})");
  s["bodies"][0]["shape"]["file"] = file;
  s["bodies"][0]["shape"]["levels"] = levels;
  return s;
}

/// A packing body in good_scene()'s 0.2 x 0.1 m grid: 0.1 x 0.1 m of 0.005 m pixels (the particle
/// spacing of 0.01 m cells with 2 particles per cell).
Json packing_scene() {
  Json s = good_scene();
  s["materials"]["soft"] = {{"type", "linear_elastic"}, {"density", 1000}, {"youngs_modulus", 1e9}, {"poisson_ratio", 0.3}};
  s["bodies"][0] = Json::parse(R"({"name": "grains", "shape": {"type": "ellipse_packing",
      "origin": [0.0, 0.0], "size": [0.1, 0.1], "pixel_size": 0.005, "seed": 3, "fraction": 0.35,
      "major_axis": {"distribution": "uniform", "min": 0.015, "max": 0.025}, "aspect_ratio": [0.6, 1.0],
      "gap": 0.0025, "grain_material": "steel", "binder_material": "soft"}})");
  s["contact"] = Json::parse(R"({"law": {"type": "coulomb", "mu": 0.3}})");
  return s;
}

}  // namespace

TEST(SceneMicrostructure, ExampleHasOneMaterialPerGrainPlusBinderAndWalls) {
  const fc::Scene s = fc::load_scene(kExample);
  const fc::ShapeSpec& shape = s.bodies[0].shape;
  ASSERT_TRUE(shape.generated);
  const std::size_t grains = shape.grain_count;
  EXPECT_GE(grains, 8u);  // "a dozen": 50 % of 60 x 60 um in grains of ~150 um²
  EXPECT_LE(grains, 20u);
  // Achieved fraction within the default tolerance (half the largest possible grain: π/8 · 20² · 0.9 / 60² = 0.039).
  EXPECT_NEAR(shape.fraction, 0.5, 0.04);
  // Declared: hmx (the grain template, left without particles), binder, side_wall, bottom_wall,
  // piston; then hmx#1..n.
  ASSERT_EQ(s.materials.size(), 5 + grains);
  for (std::size_t k = 1; k <= grains; ++k) EXPECT_EQ(s.materials[4 + k].name, "hmx#" + std::to_string(k));
  const auto sim = fc::build_simulation<2>(s);
  std::set<int> used(sim->particles().material.begin(), sim->particles().material.end());
  EXPECT_EQ(used.size(), grains + 1 /*binder*/ + 3 /*side and bottom walls, piston*/);
  EXPECT_EQ(used.count(material_index(s, "hmx")), 0u);
  // One particle per pixel (2 x 2 um particles, 2 um pixels): grain particles = grain pixels.
  std::size_t grain_pixels = 0, grain_particles = 0;
  for (auto g : shape.image.pixels) grain_pixels += g > 0;
  for (int m : sim->particles().material) grain_particles += m >= 5;
  EXPECT_EQ(grain_particles, grain_pixels);
  // Every pair meets through the default law: Coulomb mu = 0.3 (grain-grain, grain-binder, grain-wall).
  const int g1 = material_index(s, "hmx#1"), g2 = material_index(s, "hmx#2");
  for (int other : {g2, material_index(s, "binder"), material_index(s, "side_wall"), material_index(s, "piston")})
    EXPECT_EQ(sim->contact_pair(g1, other).law.describe(), "coulomb(mu=0.3)");
  // Thermal properties: grains take hmx's (table 1: 950 J/(kg K), 0.45 W/(m K)).
  ASSERT_EQ(s.thermal.coupler.materials.size(), s.materials.size());
  EXPECT_DOUBLE_EQ(s.thermal.coupler.materials[static_cast<std::size_t>(g2)].heat_capacity, 950.0);
  EXPECT_DOUBLE_EQ(s.thermal.coupler.materials[static_cast<std::size_t>(g2)].conductivity, 0.45);
  EXPECT_EQ(s.thermal.coupler.plastic.taylor_quinney.size(), s.materials.size());
  // A reaction given for hmx makes its grains react.
  Json j = fc::parse_json_text(s.text);
  j["thermal"]["reaction"] = Json::parse(R"({"kinetics": "hmx_rogers1975", "materials": ["hmx"]})");
  const fc::Scene r = fc::parse_scene(j.dump());
  EXPECT_TRUE(r.thermal.coupler.reaction.reacts(g2));
  EXPECT_FALSE(r.thermal.coupler.reaction.reacts(material_index(r, "binder")));
  // A few steps run: the top wall closes at 3.07 m/s; the state stays finite.
  for (int i = 0; i < 5; ++i) sim->step();
  for (const auto& v : sim->particles().velocity) ASSERT_TRUE(v.allFinite());
}

TEST(SceneMicrostructure, RunWritesTheImageItUsedAndItRebuildsTheSameBody) {
  TempDir dir;
  fc::Scene s = fc::load_scene(kExample);
  s.end_time = 2e-9;  // a few steps
  s.output.snapshot_interval = s.end_time;
  fc::RunOptions opt;
  opt.output = (dir.path / "pbx.h5").string();
  opt.quiet = true;
  ASSERT_EQ(fc::run_scene(s, opt).exit_code(), 0);
  const std::string image = (dir.path / "pbx_pbx.pgm").string();
  ASSERT_EQ(fc::generated_image_path(s, 0, opt.output), image);
  const auto written = frictherm::mechanics::read_grey_image(image);
  EXPECT_EQ(written.pixels, s.bodies[0].shape.image.pixels);
  // The image (grey = grain label) as an image body, split by grey level: the same particles with the
  // same materials, grain k being "hmx#k" in both.
  Json j = fc::parse_json_text(s.text);
  j["bodies"][0]["shape"] = {{"type", "image"}, {"file", image}, {"origin", {8e-6, 8e-6}}, {"pixel_size", 2e-6}};
  j["bodies"][0]["shape"]["levels"] = Json::parse(
      R"([{"range": [0, 0], "material": "binder"}, {"range": [1, 255], "material": "hmx", "split": "grey_levels"}])");
  const fc::Scene again = fc::parse_scene(j.dump());
  const auto a = fc::build_simulation<2>(fc::load_scene(kExample));
  const auto b = fc::build_simulation<2>(again);
  ASSERT_EQ(a->particles().size(), b->particles().size());
  std::map<std::pair<double, double>, std::string> names;
  for (std::size_t k = 0; k < a->particles().size(); ++k)
    names[{a->particles().position[k][0], a->particles().position[k][1]}] =
        s.materials[static_cast<std::size_t>(a->particles().material[k])].name;
  for (std::size_t k = 0; k < b->particles().size(); ++k)
    EXPECT_EQ((names[{b->particles().position[k][0], b->particles().position[k][1]}]),
              again.materials[static_cast<std::size_t>(b->particles().material[k])].name);
}

TEST(SceneMicrostructure, ImageGrainsByConnectivityAndGreyLevel) {
  TempDir dir;
  const std::string file = (dir.path / "grains.pgm").string();
  {
    // 5 x 3 pixels of 0.02 m: a 2-pixel grain top-left, and two grains of grey 100 and 200 that touch
    // only at a corner (rows from the top).
    std::ofstream pgm(file);
    pgm << "P2\n5 3\n255\n"
           "200 200 0 0 0\n"
           "0   0   0 100 0\n"
           "0   0 200 0   0\n";
  }
  const Json binder = {{"range", {0, 0}}, {"material", "soft"}};
  Json split = {{"range", {1, 255}}, {"material", "steel"}, {"split", "grains"}, {"connectivity", 4}};
  fc::Scene s = fc::parse_scene(image_scene(file, {binder, split}).dump());
  ASSERT_EQ(s.materials.size(), 5u);  // steel, soft, steel#1..3
  EXPECT_EQ(s.materials[4].name, "steel#3");
  auto sim = fc::build_simulation<2>(s);
  std::map<int, int> count;
  for (int m : sim->particles().material) ++count[m];
  EXPECT_EQ(count[2], 2 * 16);  // steel#1: 2 pixels; a 0.02 m pixel = 2 x 2 cells of 0.01 m x 4 particles
  EXPECT_EQ(count[3], 16);      // steel#2: the grey-100 pixel (scan order: row 1 before row 2)
  EXPECT_EQ(count[4], 16);
  EXPECT_EQ(count[1], 11 * 16);  // binder: the other 11 pixels
  EXPECT_EQ(count[0], 0);        // the template has no particles
  split["connectivity"] = 8;  // the corner joins grey 100 and 200
  s = fc::parse_scene(image_scene(file, {binder, split}).dump());
  EXPECT_EQ(s.materials.size(), 4u);
  split.erase("connectivity");
  split["split"] = "grey_levels";
  s = fc::parse_scene(image_scene(file, {binder, split}).dump());
  ASSERT_EQ(s.materials.size(), 4u);
  EXPECT_EQ(s.materials[2].name, "steel#100");
  EXPECT_EQ(s.materials[3].name, "steel#200");
  sim = fc::build_simulation<2>(s);
  count.clear();
  for (int m : sim->particles().material) ++count[m];
  EXPECT_EQ(count[3], 3 * 16);
  // Mistakes name the key.
  split["connectivity"] = 4;
  EXPECT_THAT(scene_error(image_scene(file, {binder, split}).dump(), "."),
              StartsWith("bodies[0].shape.levels[1].connectivity: only for \"split\": \"grains\""));
  split = {{"range", {1, 255}}, {"material", "steel"}, {"split", "grains"}, {"connectivity", 6}};
  EXPECT_THAT(scene_error(image_scene(file, {binder, split}).dump(), "."),
              StartsWith("bodies[0].shape.levels[1].connectivity: expected 4 or 8"));
  split = {{"range", {1, 255}}, {"material", "steel"}, {"split", "each"}};
  EXPECT_THAT(scene_error(image_scene(file, {binder, split}).dump(), "."), StartsWith("bodies[0].shape.levels[1].split: "));
}

TEST(SceneMicrostructure, PackingGrainsContactPairsAndDeterminism) {
  Json j = packing_scene();
  // A pair naming the template applies to each grain; grain-grain pairs keep the default law.
  j["contact"]["pairs"] = Json::parse(R"([{"materials": ["steel", "soft"], "law": "frictionless"}])");
  const fc::Scene s = fc::parse_scene(j.dump());
  const std::size_t grains = s.bodies[0].shape.grain_count;
  ASSERT_GE(grains, 10u);
  EXPECT_EQ(s.materials.size(), 2 + grains);
  const auto sim = fc::build_simulation<2>(s);
  const int soft = material_index(s, "soft");
  for (std::size_t k = 1; k <= grains; ++k)
    EXPECT_EQ(sim->contact_pair(material_index(s, "steel#" + std::to_string(k)), soft).law.describe(), "frictionless");
  EXPECT_EQ(sim->contact_pair(material_index(s, "steel#1"), material_index(s, "steel#2")).law.describe(),
            "coulomb(mu=0.3)");
  // Same seed, same grains; another seed, other grains.
  EXPECT_EQ(fc::parse_scene(j.dump()).bodies[0].shape.image.pixels, s.bodies[0].shape.image.pixels);
  j["bodies"][0]["shape"]["seed"] = 4;
  EXPECT_NE(fc::parse_scene(j.dump()).bodies[0].shape.image.pixels, s.bodies[0].shape.image.pixels);
  // One material for all grains when asked.
  j["bodies"][0]["shape"]["separate_grains"] = false;
  EXPECT_EQ(fc::parse_scene(j.dump()).materials.size(), 2u);
}

TEST(SceneMicrostructure, PackingMistakesNameTheKey) {
  auto error_with = [](const std::string& key, const Json& value) {
    Json j = packing_scene();
    j["bodies"][0]["shape"][key] = value;
    return scene_error(j);
  };
  EXPECT_THAT(error_with("fraction", 0.85),
              AllOf(StartsWith("bodies[0].shape.fraction: the packing reached a grain fraction of "),
                    HasSubstr("not within fraction_tolerance")));
  EXPECT_THAT(error_with("size", Json::parse("[0.1, 0.0975]")),
              StartsWith("bodies[0].shape.size: expected a whole number of pixels"));
  EXPECT_THAT(error_with("major_axis", Json::parse(R"({"distribution": "uniform", "min": 0.02, "max": 0.01})")),
              StartsWith("bodies[0].shape.major_axis: expected max >= min"));
  EXPECT_THAT(error_with("major_axis", Json::parse(R"({"distribution": "gamma", "min": 0.02, "max": 0.01})")),
              StartsWith("bodies[0].shape.major_axis.distribution: "));
  EXPECT_THAT(error_with("grain_material", "hmx"), StartsWith("bodies[0].shape.grain_material: unknown material \"hmx\""));
  EXPECT_THAT(error_with("aspect_ratio", Json::parse("[0.8, 0.5]")), StartsWith("bodies[0].shape.aspect_ratio: expected"));
  EXPECT_THAT(error_with("seed", -1), StartsWith("bodies[0].shape.seed: "));
  EXPECT_THAT(error_with("colour", 1), StartsWith("bodies[0].shape.colour: unknown key"));
  Json j = packing_scene();
  j["bodies"][0]["shape"]["periodic"] = true;
  j["bodies"][0]["shape"]["major_axis"]["max"] = 0.05;  // + gap > half of 0.1 m
  EXPECT_THAT(scene_error(j), StartsWith("bodies[0].shape.periodic: a periodic packing needs"));
  j = packing_scene();
  j["bodies"][0]["shape"].erase("seed");
  EXPECT_THAT(scene_error(j), StartsWith("bodies[0].shape.seed: "));
  j = packing_scene();
  j["materials"]["steel#1"] = j["materials"]["soft"];
  EXPECT_THAT(scene_error(j), AllOf(StartsWith("bodies[0].shape.grain_material: "), HasSubstr("\"steel#1\" is already taken")));
}
