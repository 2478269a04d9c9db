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
  std::size_t declared_materials = 0;  // materials of the `materials` section; grain materials follow
  std::vector<int> grain_template;     // per material: the declared material a grain copy was made from, or -1

  /// A material name (a JSON string) -> its id; unknown names are errors naming the defined ones.
  int material_id(const JsonReader& name) const;
  /// A body name (a JSON string) -> its id.
  int body_id(const JsonReader& name) const;
};

/// An array of `dim` numbers as a SceneVec (zero-padded).
SceneVec read_vec(const JsonReader& value, int dim, const Range& range = Range::any());
/// "(x, y)" or "(x, y, z)".
std::string format_vec(const SceneVec& v, int dim);
/// Material and body names label columns of the results (mean_temperature.<name>, ...), and HDF5
/// splits names at '/': fails at `where` ("material" or "body" names) for an empty name or a '/'.
void check_result_name(const JsonReader& where, const std::string& name, const char* what);
/// The first Dim components of a SceneVec (the serial scene build and the decomposed set-up).
template <int Dim>
mechanics::Vec<Dim> to_vec(const SceneVec& v) {
  mechanics::Vec<Dim> out;
  for (int d = 0; d < Dim; ++d) out[d] = v[static_cast<std::size_t>(d)];
  return out;
}

/// bodies: [...]
void parse_bodies(const JsonReader& root, Scene& scene, ParseContext& ctx);
/// boundary: {...} and loads: {...}
void parse_boundary(const JsonReader& root, Scene& scene, const ParseContext& ctx);
void parse_loads(const JsonReader& root, Scene& scene, const ParseContext& ctx);

/// Image microstructures (scene_grains.cpp): a copy of declared material `template_id` named `name`
/// for one grain (or grey level); returns its id. `where` is blamed if the name is taken.
int add_grain_material(Scene& scene, ParseContext& ctx, int template_id, const std::string& name,
                       const JsonReader& where);
/// An image level whose pixels become one material per connected grain or per grey level.
struct LevelSplit {
  std::size_t level = 0;  // index into ShapeSpec::levels
  bool by_grey_level = false;
  mechanics::Connectivity connectivity = mechanics::Connectivity::eight;
  JsonReader where;  // the level's reader, blamed for errors
};
/// Fills out.pixel_materials from out.image and out.levels, giving the split levels' pixels their
/// grain (or grey-level) materials.
void split_image_levels(const std::vector<LevelSplit>& splits, Scene& scene, ParseContext& ctx, ShapeSpec& out);
/// After `contact` is parsed: a pair naming a grain template applies to each of its grains.
void expand_grain_contact_pairs(Scene& scene, const ParseContext& ctx);
/// After `thermal` is parsed over the declared materials: grain materials get their template's properties.
void extend_grain_thermal(Scene& scene, const ParseContext& ctx);
/// The `ellipse_packing` shape (scene_packing.cpp): generates the grains and fills `out` as an image.
void parse_ellipse_packing(const JsonReader& shape, Scene& scene, ParseContext& ctx, ShapeSpec& out);
/// z_range of planar shapes (scene_bodies.cpp): required in 3D, refused in 2D.
void read_z_range(const JsonReader& shape, int dim, ShapeSpec& out);

/// "x_min" -> axis 0, lower face; the name must come from face_names(dim).
void face_from_name(const std::string& name, int& axis, bool& upper);

}  // namespace frictherm::coupling::detail
