#pragma once
// Private helpers shared by the scene parser's source files.
#include <frictherm/coupling/scene.hpp>

#include <string>
#include <vector>

namespace frictherm::coupling::detail {

/// What the parts of a scene need to know about the parts parsed before them.
struct ParseContext {
  int dim = 2;
  std::string base_dir = ".";
  std::vector<std::string> material_names;
  std::vector<std::string> body_names;

  /// A material name (a JSON string) -> its id; unknown names are errors naming the defined ones.
  int material_id(const JsonReader& name) const;
  /// A body name (a JSON string) -> its id.
  int body_id(const JsonReader& name) const;
};

/// An array of `dim` numbers as a SceneVec (zero-padded).
SceneVec read_vec(const JsonReader& value, int dim, const Range& range = Range::any());
/// "(x, y)" or "(x, y, z)".
std::string format_vec(const SceneVec& v, int dim);

/// bodies: [...]
void parse_bodies(const JsonReader& root, Scene& scene, ParseContext& ctx);
/// boundary: {...} and loads: {...}
void parse_boundary(const JsonReader& root, Scene& scene, const ParseContext& ctx);
void parse_loads(const JsonReader& root, Scene& scene, const ParseContext& ctx);

/// "x_min" -> axis 0, lower face; the name must come from face_names(dim).
void face_from_name(const std::string& name, int& axis, bool& upper);

}  // namespace frictherm::coupling::detail
