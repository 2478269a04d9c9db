// The extended B-spline as a scene shape function: solver.shape_function "extended_bspline" (alias
// "ebs") with solver.ebs_occupation (C_c), its errors, a built simulation stepping with one basis
// per field, and the thermal assembly using the plain quadratic B-spline underneath (docs/ebs.md).
#include "test_scene_support.hpp"

#include <frictherm/coupling/thermal_assembly.hpp>

#include <gmock/gmock.h>

namespace fc = frictherm::coupling;
namespace fm = frictherm::mechanics;
using fc::Json;
using fc::parse_scene;
using fc::test::good_scene;
using fc::test::scene_error;
using ::testing::HasSubstr;

TEST(SceneEbs, ShapeFunctionAndOccupation) {
  Json j = good_scene();
  j["solver"] = Json::parse(R"({"shape_function": "extended_bspline", "ebs_occupation": 0.5})");
  const fc::Scene s = parse_scene(j.dump());
  EXPECT_EQ(s.options.shape, fm::ShapeKind::extended_bspline);
  EXPECT_DOUBLE_EQ(s.options.ebs_occupation, 0.5);
  j["solver"] = Json::parse(R"({"shape_function": "ebs"})");
  const fc::Scene d = parse_scene(j.dump());
  EXPECT_EQ(d.options.shape, fm::ShapeKind::extended_bspline);
  EXPECT_DOUBLE_EQ(d.options.ebs_occupation, 0.75);  // the default C_c

  auto sim = fc::build_simulation<2>(d);
  for (int k = 0; k < 3; ++k) sim->step();
  ASSERT_EQ(sim->extended_bases().size(), 1u);
  // The block (0.05..0.15 x 0.02..0.07 m, 2 particles per 0.01 m cell) cuts its boundary knot
  // spans in half: φ = 0.5 <= 0.75 there, so its rim nodes are degenerate.
  EXPECT_GT(sim->extended_bases()[0].degenerate_count(), 0);
}

TEST(SceneEbs, Errors) {
  Json j = good_scene();
  j["solver"] = Json::parse(R"({"shape_function": "quadratic_bspline", "ebs_occupation": 0.5})");
  EXPECT_THAT(scene_error(j), HasSubstr("solver.ebs_occupation: only with \"shape_function\": \"extended_bspline\""));
  j["solver"] = Json::parse(R"({"shape_function": "extended_bspline", "ebs_occupation": 1.5})");
  EXPECT_THAT(scene_error(j), HasSubstr("solver.ebs_occupation"));
  j["solver"] = Json::parse(R"({"shape_function": "cubic_bspline"})");
  EXPECT_THAT(scene_error(j), HasSubstr("extended_bspline"));  // listed among the expected values
}

// The thermal assembly is not part of the paper: with EBS mechanics it uses the quadratic B-spline.
TEST(SceneEbs, ThermalAssemblyUsesTheQuadraticBSpline) {
  const fc::Scene s = parse_scene(good_scene().dump());
  const auto sim = fc::build_simulation<2>(s);
  const std::vector<fc::ThermalProperties> mats{{true, 500.0, 50.0}};
  const auto e = fc::assemble_thermal<2>(sim->grid(), sim->particles(), fm::ShapeKind::extended_bspline, mats);
  const auto q = fc::assemble_thermal<2>(sim->grid(), sim->particles(), fm::ShapeKind::quadratic_bspline, mats);
  EXPECT_EQ(e.grid_mass, q.grid_mass);
  EXPECT_EQ(e.grid_node, q.grid_node);
}
