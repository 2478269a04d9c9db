// Scenes that parse: simulations built from them, defaults, time functions, images.
#include "test_scene_support.hpp"

#include <gmock/gmock.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <unistd.h>

namespace fc = frictherm::coupling;
using fc::Json;
using fc::JsonReader;
using fc::parse_scene;
using fc::test::good_scene;
using fc::test::scene_error;
using ::testing::HasSubstr;
using ::testing::StartsWith;

TEST(SceneBuild, RectangleHasPpcSquaredParticlesPerCell) {
  const fc::Scene s = parse_scene(good_scene().dump());
  const auto sim = fc::build_simulation<2>(s);
  // 0.1 x 0.05 m = 10 x 5 cells, 2 x 2 particles each.
  EXPECT_EQ(sim->particles().size(), 200u);
  ASSERT_EQ(sim->bodies().size(), 1u);
  EXPECT_EQ(sim->bodies()[0].name, "block");
  EXPECT_NEAR(sim->particles().mass[0], 7850 * 0.005 * 0.005 * 1.0, 1e-12);
}

TEST(SceneBuild, ThreeDimensionalBoxAndSphere) {
  Json s = Json::parse(R"({
    "dimension": 3,
    "grid": {"lo": [0, 0, 0], "hi": [0.1, 0.1, 0.1], "cells": [10, 10, 10]},
    "materials": {"rubber": {"type": "neo_hookean", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.4}},
    "bodies": [{"name": "cube", "material": "rubber", "particles_per_cell": 3,
                "shape": {"type": "box", "lo": [0, 0, 0], "hi": [0.02, 0.03, 0.04]}},
               {"name": "ball", "material": "rubber", "particles_per_cell": 3,
                "shape": {"type": "sphere", "center": [0.06, 0.06, 0.06], "radius": 0.03}}],
    "run": {"end_time": 1e-3}
  })");
  const fc::Scene scene = parse_scene(s.dump());
  const auto sim = fc::build_simulation<3>(scene);
  EXPECT_EQ(sim->bodies()[0].particle_count, 2u * 3u * 4u * 27u);
  const double expected_ball = 4.0 / 3.0 * 3.14159265358979 * std::pow(0.03, 3) / std::pow(0.01 / 3, 3);
  EXPECT_NEAR(static_cast<double>(sim->bodies()[1].particle_count), expected_ball, 0.03 * expected_ball);
}

// The update scheme a scene gets when it names none: USL with multimaterial (grid) contact, whose
// frictional heat MUSL makes grow with the time step (docs/transfer.md), except with linear shape
// functions (MUSL: USL blows up with them, docs/contact.md); MUSL without contact or with penalty
// contact only; a named scheme always wins.
TEST(SceneBuild, DefaultUpdateSchemeFollowsTheContactMethod) {
  using frictherm::mechanics::UpdateScheme;
  Json j = good_scene();
  EXPECT_EQ(parse_scene(j.dump(), "<test>", ".", "s").options.scheme, UpdateScheme::musl);
  j["contact"] = Json::parse(R"({"law": {"type": "coulomb", "mu": 0.3}})");
  EXPECT_EQ(parse_scene(j.dump(), "<test>", ".", "s").options.scheme, UpdateScheme::usl);
  j["solver"] = Json::parse(R"({"scheme": "musl"})");
  EXPECT_EQ(parse_scene(j.dump(), "<test>", ".", "s").options.scheme, UpdateScheme::musl);
  j["solver"] = Json::parse(R"({"cfl": 0.4})");
  EXPECT_EQ(parse_scene(j.dump(), "<test>", ".", "s").options.scheme, UpdateScheme::usl);
  j["solver"] = Json::parse(R"({"shape_function": "linear"})");  // USL blows up with linear shapes
  EXPECT_EQ(parse_scene(j.dump(), "<test>", ".", "s").options.scheme, UpdateScheme::musl);
  j["solver"] = Json::parse(R"({"shape_function": "linear", "scheme": "usl"})");
  EXPECT_EQ(parse_scene(j.dump(), "<test>", ".", "s").options.scheme, UpdateScheme::usl);
  j["contact"] = Json::parse(R"({"method": "penalty", "boundary_spacing": 0.005})");
  j.erase("solver");
  EXPECT_EQ(parse_scene(j.dump(), "<test>", ".", "s").options.scheme, UpdateScheme::musl);
}

// A named USL or USF with linear shape functions and multimaterial contact runs, but with a note
// naming solver.scheme and MUSL (every contact scene measured blew up with it, docs/contact.md);
// no note for the default, for MUSL, for uGIMP, without contact or with penalty contact only.
TEST(SceneBuild, LinearShapesWithUslAndGridContactGetANote) {
  Json j = good_scene();
  const auto notes = [&j] { return parse_scene(j.dump(), "<test>", ".", "s").notes; };
  j["contact"] = Json::parse(R"({"law": {"type": "coulomb", "mu": 0.3}})");
  for (const char* scheme : {"usl", "usf"}) {
    j["solver"] = Json{{"shape_function", "linear"}, {"scheme", scheme}};
    const std::vector<std::string> n = notes();
    ASSERT_EQ(n.size(), 1u) << scheme;
    EXPECT_NE(n[0].find(std::string("solver.scheme \"") + scheme + "\""), std::string::npos) << n[0];
    EXPECT_NE(n[0].find("musl"), std::string::npos) << n[0];
  }
  j["solver"] = Json{{"shape_function", "linear"}};
  EXPECT_TRUE(notes().empty());
  j["solver"] = Json{{"shape_function", "linear"}, {"scheme", "musl"}};
  EXPECT_TRUE(notes().empty());
  j["solver"] = Json{{"shape_function", "ugimp"}, {"scheme", "usl"}};
  EXPECT_TRUE(notes().empty());
  j["solver"] = Json{{"shape_function", "linear"}, {"scheme", "usl"}};
  j["contact"] = Json::parse(R"({"method": "penalty", "boundary_spacing": 0.005})");
  EXPECT_TRUE(notes().empty());
  j.erase("contact");
  EXPECT_TRUE(notes().empty());
}

TEST(SceneBuild, DefaultsAreApplied) {
  const fc::Scene s = parse_scene(good_scene().dump(), "<test>", ".", "my_scene");
  EXPECT_EQ(s.output.file, "my_scene.h5");
  EXPECT_DOUBLE_EQ(s.output.snapshot_interval, 1e-5 / 20);
  EXPECT_DOUBLE_EQ(s.output.series_interval, 1e-5 / 5000);
  EXPECT_EQ(s.output.fields, fc::snapshot_field_names(2));
  EXPECT_EQ(s.options.analysis, frictherm::mechanics::Analysis::plane_strain);
  EXPECT_EQ(s.options.shape, frictherm::mechanics::ShapeKind::ugimp);
  EXPECT_EQ(s.options.scheme, frictherm::mechanics::UpdateScheme::musl);
  EXPECT_DOUBLE_EQ(s.options.cfl, 0.5);
  EXPECT_DOUBLE_EQ(s.options.thickness, 1.0);
  EXPECT_EQ(s.bodies[0].particles_per_cell, 2);
  EXPECT_DOUBLE_EQ(s.bodies[0].temperature, 293.15);
}

TEST(SceneBuild, LoadsBoundaryAndOutputOptions) {
  Json s = good_scene();
  s["boundary"] = Json::parse(R"({"fixed": [{"face": "x_min", "components": ["x"]}, {"face": "y_max"}]})");
  s["loads"] = Json::parse(R"({"gravity": [0, -9.81],
      "point": [{"body": "block", "point": [0.15, 0.07], "force": [0, -10]},
                {"box": {"lo": [0.05, 0.02], "hi": [0.06, 0.07]}, "force": [5, 0], "scale": 2}],
      "traction": [{"body": "block", "face": "x_max", "traction": [1e6, 0],
                    "scale": {"type": "ramp", "value": 1, "duration": 1e-6}}]})");
  s["output"] = Json::parse(R"({"file": "x.h5", "snapshot_count": 4, "series_interval": 0,
                                "fields": ["stress", "body"]})");
  const fc::Scene scene = parse_scene(s.dump());
  ASSERT_EQ(scene.fixed_faces.size(), 2u);
  EXPECT_EQ(scene.fixed_faces[0].axis, 0);
  EXPECT_FALSE(scene.fixed_faces[0].upper);
  EXPECT_TRUE(scene.fixed_faces[0].components[0]);
  EXPECT_FALSE(scene.fixed_faces[0].components[1]);
  EXPECT_TRUE(scene.fixed_faces[1].upper);
  EXPECT_DOUBLE_EQ(scene.options.gravity[1], -9.81);
  ASSERT_EQ(scene.point_loads.size(), 2u);
  EXPECT_EQ(scene.point_loads[1].body, -1);
  EXPECT_TRUE(scene.point_loads[1].use_box);
  EXPECT_DOUBLE_EQ(scene.point_loads[1].scale(3.0), 2.0);
  ASSERT_EQ(scene.tractions.size(), 1u);
  EXPECT_DOUBLE_EQ(scene.tractions[0].scale(0.5e-6), 0.5);
  EXPECT_EQ(scene.output.file, "x.h5");
  EXPECT_DOUBLE_EQ(scene.output.snapshot_interval, 1e-5 / 4);
  EXPECT_EQ(scene.output.series_interval, 0.0);
  EXPECT_EQ(scene.output.fields, (std::vector<std::string>{"position", "stress", "body"}));
  EXPECT_NO_THROW(fc::build_simulation<2>(scene));
}

TEST(SceneBuild, PointLoadBoxWithoutParticlesIsNamed) {
  Json s = good_scene();
  s["loads"] = Json::parse(R"({"point": [{"box": {"lo": [0.0, 0.0], "hi": [0.01, 0.01]}, "force": [1, 0]}]})");
  EXPECT_THAT(scene_error(s), StartsWith("loads.point[0]: "));
}

namespace {
frictherm::mechanics::TimeFunction tf(const std::string& text) {
  const Json j = Json::parse(text);
  return fc::parse_time_function(JsonReader(j, "f"));
}
std::string tf_error(const std::string& text) {
  try {
    tf(text);
  } catch (const fc::SceneError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(SceneTimeFunction, AllKinds) {
  EXPECT_DOUBLE_EQ(tf("2.5")(7.0), 2.5);
  EXPECT_DOUBLE_EQ(tf(R"({"type": "constant", "value": -1})")(0.3), -1.0);
  const auto ramp = tf(R"({"type": "ramp", "value": 4, "duration": 2, "start": 1})");
  EXPECT_DOUBLE_EQ(ramp(0.5), 0.0);
  EXPECT_DOUBLE_EQ(ramp(2.0), 2.0);
  EXPECT_DOUBLE_EQ(ramp(10.0), 4.0);
  const auto sine = tf(R"({"type": "sinusoid", "amplitude": 3, "period": 4})");
  EXPECT_NEAR(sine(1.0), 3.0, 1e-12);
  const auto sine2 = tf(R"({"type": "sinusoid", "amplitude": 1, "omega": 2, "start": 1, "end": 2})");
  EXPECT_NEAR(sine2(1.5), std::sin(1.0), 1e-12);
  EXPECT_DOUBLE_EQ(sine2(2.5), 0.0);
  const auto table = tf(R"({"type": "table", "times": [0, 1, 3], "values": [0, 10, 30]})");
  EXPECT_DOUBLE_EQ(table(2.0), 20.0);
  EXPECT_DOUBLE_EQ(table(5.0), 30.0);
}

TEST(SceneTimeFunction, Errors) {
  EXPECT_THAT(tf_error(R"({"type": "sinusoid", "amplitude": 1, "omega": 2, "period": 3})"),
              StartsWith("f: expected exactly one of omega"));
  EXPECT_THAT(tf_error(R"({"type": "table", "times": [0, 1], "values": [1]})"), StartsWith("f.values: expected"));
  EXPECT_THAT(tf_error(R"({"type": "table", "times": [1, 0], "values": [1, 2]})"),
              StartsWith("f.times: expected times in non-decreasing order"));
  EXPECT_THAT(tf_error(R"({"type": "square", "value": 1})"), StartsWith("f.type: expected one of"));
  EXPECT_THAT(tf_error(R"({"type": "ramp", "value": 1, "duration": -1})"),
              StartsWith("f.duration: expected a number >= 0"));
  EXPECT_THAT(tf_error(R"({"type": "ramp", "value": 1, "duration": 1, "slope": 2})"),
              StartsWith("f.slope: unknown key"));
  EXPECT_THAT(tf_error(R"("fast")"), StartsWith("f: expected a time function"));
}

TEST(SceneBuild, RigidMaterialVelocityHistory) {
  Json s = good_scene();
  s["materials"]["platen"] = Json::parse(R"({"type": "rigid", "velocity": [{"type": "ramp", "value": 2, "duration": 1}, 0]})");
  s["bodies"].push_back(Json::parse(R"({"name": "platen", "material": "platen",
      "shape": {"type": "rectangle", "lo": [0.0, 0.02], "hi": [0.05, 0.07]}})"));
  const fc::Scene scene = parse_scene(s.dump());
  ASSERT_EQ(scene.materials.size(), 2u);
  EXPECT_TRUE(scene.materials[1].is_rigid());
  EXPECT_DOUBLE_EQ(scene.materials[1].density, 1000.0);
  EXPECT_DOUBLE_EQ(scene.materials[1].rigid_velocity_at(0.5)[0], 1.0);
  EXPECT_NO_THROW(fc::build_simulation<2>(scene));
  s["bodies"][1]["velocity"] = {1, 0};
  EXPECT_THAT(scene_error(s), StartsWith("bodies[1].velocity: not allowed for a body of rigid material"));
}

TEST(SceneBuild, ImageBodyMapsGreyLevelsToMaterials) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("frictherm_scene_image_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  {
    std::ofstream pgm(dir / "two.pgm");
    pgm << "P2\n4 2\n255\n0 0 255 255\n0 0 255 255\n";  // left half black, right half white
  }
  Json s = good_scene();
  s["materials"]["soft"] = {{"type", "linear_elastic"}, {"density", 1000}, {"youngs_modulus", 1e9}, {"poisson_ratio", 0.3}};
  s["bodies"][0] = Json::parse(R"({"name": "img", "shape": {"type": "image", "file": "two.pgm",
      "origin": [0.0, 0.0], "pixel_size": 0.02,
      "levels": [{"range": [0, 100], "material": "steel"}, {"range": [101, 255], "material": "soft"}]}})");
  const fc::Scene scene = parse_scene(s.dump(), "<test>", dir.string());
  const auto sim = fc::build_simulation<2>(scene);
  // 0.08 x 0.04 m = 8 x 4 cells, 4 particles each, half of them in each material.
  EXPECT_EQ(sim->particles().size(), 128u);
  std::size_t steel = 0;
  for (auto m : sim->particles().material) steel += (m == 0);
  EXPECT_EQ(steel, 64u);
  s["bodies"][0]["material"] = "steel";
  EXPECT_THAT(scene_error(s.dump(), dir.string()), StartsWith("bodies[0].material: not allowed for an image body"));
  fs::remove_all(dir);
}

TEST(SceneBuild, LoadSceneNamesItAfterTheFile) {
  namespace fs = std::filesystem;
  const fs::path file = fs::temp_directory_path() / ("frictherm_scene_" + std::to_string(::getpid()) + ".json");
  {
    std::ofstream out(file);
    out << "// comment\n" << good_scene().dump(2);
  }
  const fc::Scene s = fc::load_scene(file.string());
  EXPECT_EQ(s.name, file.stem().string());
  EXPECT_EQ(s.output.file, file.stem().string() + ".h5");
  EXPECT_THAT(s.text, StartsWith("// comment"));
  fs::remove(file);
  EXPECT_THAT([&] { fc::load_scene(file.string()); }, ::testing::Throws<fc::SceneError>());
}

TEST(JsonReader, PathsAndFinish) {
  const Json j = Json::parse(R"({"a": {"b": [1, {"c": true}]}, "x": 1})");
  const JsonReader root(j, "");
  const JsonReader a = root.at("a");
  EXPECT_EQ(a.path(), "a");
  const auto items = a.at("b").elements();
  EXPECT_EQ(items[1].at("c").path(), "a.b[1].c");
  EXPECT_EQ(items[0].as_integer(0, 5), 1);
  EXPECT_THROW(items[0].as_integer(2, 5), fc::SceneError);
  EXPECT_NO_THROW(a.finish());
  try {
    root.finish();
    FAIL() << "finish() should reject x";
  } catch (const fc::SceneError& e) {
    EXPECT_EQ(std::string(e.what()), "x: unknown key (allowed here: a)");
  }
  EXPECT_EQ(fc::Range::open(-1, 0.5).describe(), "a number in (-1, 0.5)");
  EXPECT_EQ(fc::Range::left_open(0, 1).describe(), "a number in (0, 1]");
  EXPECT_EQ(fc::Range::positive().describe(), "a number > 0");
}

TEST(SceneBuild, EveryShapeBuilds) {
  Json s = good_scene();
  s["bodies"] = Json::parse(R"([
    {"name": "e", "material": "steel", "shape": {"type": "ellipse", "center": [0.03, 0.015], "semi_axes": [0.02, 0.01], "angle": 0.5}},
    {"name": "a", "material": "steel", "shape": {"type": "annulus", "center": [0.08, 0.05], "inner_radius": 0.01, "outer_radius": 0.03}},
    {"name": "p", "material": "steel", "shape": {"type": "polygon", "vertices": [[0.12, 0.01], [0.19, 0.01], [0.15, 0.09]]}}
  ])");
  const auto sim = fc::build_simulation<2>(parse_scene(s.dump()));
  const double h2 = 0.005 * 0.005;  // area per particle
  EXPECT_NEAR(sim->bodies()[0].particle_count * h2, 3.14159265358979 * 0.02 * 0.01, 0.1 * 6.3e-4);
  EXPECT_NEAR(sim->bodies()[1].particle_count * h2, 3.14159265358979 * (0.03 * 0.03 - 0.01 * 0.01), 0.1 * 2.5e-3);
  EXPECT_NEAR(sim->bodies()[2].particle_count * h2, 0.5 * 0.07 * 0.08, 0.1 * 2.8e-3);
  s["bodies"][2]["shape"]["z_range"] = {0, 1};
  EXPECT_THAT(scene_error(s), StartsWith("bodies[2].shape.z_range: only for 3D scenes"));
  s["bodies"][2]["shape"].erase("z_range");
  s["bodies"][0]["shape"]["angle"] = 1.2;  // the rotated ellipse now pokes out below y = 0
  EXPECT_THAT(scene_error(s), StartsWith("bodies[0].shape: the body's bounding box"));
}

TEST(SceneBuild, ExtrudedPolygonIn3D) {
  Json s = Json::parse(R"({
    "dimension": 3,
    "grid": {"lo": [0, 0, 0], "hi": [0.1, 0.1, 0.05], "cell_size": 0.01},
    "materials": {"m": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e9, "poisson_ratio": 0.3}},
    "bodies": [{"name": "prism", "material": "m",
                "shape": {"type": "polygon", "vertices": [[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1]], "z_range": [0.01, 0.03]}}],
    "run": {"end_time": 1e-3}
  })");
  const auto sim = fc::build_simulation<3>(parse_scene(s.dump()));
  EXPECT_EQ(sim->particles().size(), 10u * 10u * 2u * 8u);
  s["bodies"][0]["shape"].erase("z_range");
  EXPECT_THAT(scene_error(s), StartsWith("bodies[0].shape.z_range: required key missing"));
}

TEST(SceneOverrides, SetValuesBeforeValidation) {
  const std::vector<fc::SceneOverride> set{fc::parse_override("solver.cfl=0.25"),
                                           fc::parse_override("bodies[0].velocity=[3, 0]"),
                                           fc::parse_override("output.file=run.h5"),
                                           fc::parse_override("bodies[0].name=slab")};
  const fc::Scene s = parse_scene(good_scene().dump(), "<test>", ".", "scene", set);
  EXPECT_DOUBLE_EQ(s.options.cfl, 0.25);
  EXPECT_DOUBLE_EQ(s.bodies[0].velocity[0], 3.0);
  EXPECT_EQ(s.output.file, "run.h5");
  EXPECT_EQ(s.bodies[0].name, "slab");
  EXPECT_EQ(s.overrides.size(), 4u);
  try {
    parse_scene(good_scene().dump(), "<test>", ".", "scene", {fc::parse_override("solver.cfl=1.5")});
    FAIL();
  } catch (const fc::SceneError& e) {
    EXPECT_THAT(e.what(), StartsWith("solver.cfl: expected a number in (0, 1], got 1.5"));
  }
  EXPECT_THROW(fc::parse_override("solver.cfl"), fc::SceneError);
  EXPECT_THROW(parse_scene(good_scene().dump(), "<test>", ".", "scene", {fc::parse_override("dimension.x=1")}),
               fc::SceneError);
  EXPECT_THROW(parse_scene(good_scene().dump(), "<test>", ".", "scene", {fc::parse_override("bodies[x]=1")}),
               fc::SceneError);
}

TEST(SceneOverrides, NullRemovesAKey) {
  // The default CFL factor comes back when the scene's value is removed.
  const fc::Scene base = parse_scene(good_scene().dump(), "<test>", ".", "scene", {fc::parse_override("solver.cfl=0.25")});
  ASSERT_DOUBLE_EQ(base.options.cfl, 0.25);
  const fc::Scene s = parse_scene(good_scene().dump(), "<test>", ".", "scene",
                                  {fc::parse_override("solver.cfl=0.25"), fc::parse_override("solver.cfl=null")});
  EXPECT_DOUBLE_EQ(s.options.cfl, frictherm::mechanics::SimulationOptions{}.cfl);
}
