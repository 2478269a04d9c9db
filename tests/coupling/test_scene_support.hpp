#pragma once
// Shared helpers of the scene tests: a small valid scene to mutate, and error capture.
#include <frictherm/coupling/scene.hpp>

#include <gtest/gtest.h>

#include <string>

namespace frictherm::coupling::test {

/// A valid 2D scene: one 0.1 x 0.05 m steel block in a 0.2 x 0.1 m grid of 0.01 m cells.
inline Json good_scene() {
  return Json::parse(R"({
    "units": "SI",
    "dimension": 2,
    "grid": {"lo": [0, 0], "hi": [0.2, 0.1], "cell_size": 0.01},
    "materials": {"steel": {"type": "linear_elastic", "density": 7850, "youngs_modulus": 200e9,
                            "poisson_ratio": 0.3}},
    "bodies": [{"name": "block", "material": "steel",
                "shape": {"type": "rectangle", "lo": [0.05, 0.02], "hi": [0.15, 0.07]}}],
    "run": {"end_time": 1e-5}
  })");
}

/// The SceneError message of parsing (and building) `scene`; "" (and a test failure) if none.
inline std::string scene_error(const std::string& text, const std::string& base_dir = ".") {
  try {
    const Scene s = parse_scene(text, "<test>", base_dir);
    if (s.dimension == 2)
      build_simulation<2>(s);
    else
      build_simulation<3>(s);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a SceneError for:\n" << text;
  return "";
}
inline std::string scene_error(const Json& scene) { return scene_error(scene.dump(2)); }

}  // namespace frictherm::coupling::test
