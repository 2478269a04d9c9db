#pragma once
// Images of generated microstructures (bodies with an "ellipse_packing" shape, docs/scenes.md):
// a run writes the image it used, so that the grains can be looked at and reused as an "image"
// body. `frictherm microstructure SCENE -o IMAGE.pgm` writes them without running.
#include <frictherm/coupling/scene.hpp>

#include <string>
#include <vector>

namespace frictherm::coupling {

/// Where the image of generated body `body` goes: the shape's `write_image` when given, else
/// "<output_file without extension>_<body name>.pgm" beside `output_file`.
std::string generated_image_path(const Scene& scene, std::size_t body, const std::string& output_file);

/// Writes the image of `body` (binary PGM, grains as the shape's `image_grey` says, a header comment
/// with the grain count and fractions) to `path`. Throws std::runtime_error if it cannot.
void write_generated_image(const Scene& scene, std::size_t body, const std::string& path);

/// Writes every generated body's image to generated_image_path(...); returns the paths written.
std::vector<std::string> write_generated_images(const Scene& scene, const std::string& output_file);

}  // namespace frictherm::coupling
