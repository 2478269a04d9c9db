// The `microstructure` subcommand: writes the images of a scene's generated bodies (ellipse_packing)
// without running the scene.
#include "cli.hpp"

#include <frictherm/coupling/microstructure.hpp>
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/scene.hpp>

#include <iostream>

namespace frictherm::cli {

const char* const kMicrostructureHelp =
    "usage: frictherm microstructure SCENE [-o IMAGE.pgm] [--force] [--body NAME] [--set KEY=VALUE ...]\n"
    "\n"
    "Generates the grains of SCENE's ellipse_packing bodies (as `run` would) and writes each body's\n"
    "image as PGM, without running anything: grey 0 binder, grains by label (or 255, as the shape's\n"
    "image_grey says). Prints grains, achieved and target fractions.\n"
    "\n"
    "options:\n"
    "  -o, --output IMAGE.pgm  output image (default: the shape's write_image, else\n"
    "                          SCENE_NAME_BODY.pgm); needs one generated body or --body\n"
    "  -b, --body NAME         only this body\n"
    "  -f, --force             replace an existing image (never the scene or its input images)\n"
    "  -s, --set KEY=VALUE     change one scene value first (repeatable), e.g. --set 'bodies[0].shape.seed=7'\n"
    "  -h, --help              this help\n";

int microstructure_command(const std::vector<std::string>& args) {
  const ParsedArgs a = parse_args("microstructure", args,
                                  {{{"-o", "--output"}, true, "output"},
                                   {{"-b", "--body"}, true, "body"},
                                   {{"-s", "--set"}, true, "set", true},
                                   kForceOption});
  if (a.help) {
    std::cout << kMicrostructureHelp;
    return kOk;
  }
  const std::string& path = single_positional("microstructure", a, "SCENE");
  coupling::Scene scene;
  try {
    std::vector<coupling::SceneOverride> overrides;
    if (a.lists.count("set"))
      for (const auto& assignment : a.lists.at("set")) overrides.push_back(coupling::parse_override(assignment));
    scene = coupling::load_scene(path, overrides);
  } catch (const coupling::SceneError& e) {
    std::cerr << "frictherm: " << path << ": " << e.what() << '\n';
    return kUsage;
  }
  std::vector<std::size_t> bodies;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    if (scene.bodies[i].shape.generated && (!a.has("body") || scene.bodies[i].name == a.options.at("body")))
      bodies.push_back(i);
  if (bodies.empty())
    throw UsageError("microstructure", a.has("body") ? "no ellipse_packing body named '" + a.options.at("body") + "'"
                                                     : "the scene has no ellipse_packing body");
  if (a.has("output") && bodies.size() > 1)
    throw UsageError("microstructure", "-o needs one body; the scene has " + std::to_string(bodies.size()) +
                                           " ellipse_packing bodies (choose one with --body)");
  for (std::size_t i : bodies) {
    const coupling::BodySpec& b = scene.bodies[i];
    const std::string out =
        a.has("output") ? a.options.at("output") : coupling::generated_image_path(scene, i, scene.output.file);
    try {
      coupling::check_output_path(out, coupling::scene_input_files(scene), a.has("force") || scene.output.overwrite,
                                  "--force");
      coupling::write_generated_image(scene, i, out);
    } catch (const std::exception& e) {
      std::cerr << "frictherm: " << e.what() << '\n';
      return kUsage;
    }
    std::cout << "wrote " << out << ": body " << b.name << ", " << b.shape.image.width << " x " << b.shape.image.height
              << " pixels, " << b.shape.grain_count << " grains, fraction " << b.shape.fraction << " (target "
              << b.shape.target_fraction << ")\n";
  }
  return kOk;
}

}  // namespace frictherm::cli
