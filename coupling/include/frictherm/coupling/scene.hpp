#pragma once
// Scenes: a JSON description of one mechanics run (see docs/scenes.md for every key).
//
//   Scene s = load_scene("examples/bar_vibration.json");      // parse + validate, throws SceneError
//   auto sim = build_simulation<2>(s);                          // particles, loads, BCs; finalized
//
// All validation happens while parsing and building, before any step runs; every error is one
// SceneError whose message starts with the key path (e.g. `bodies[1].shape.radius: ...`).
#include <frictherm/coupling/json_reader.hpp>
#include <frictherm/coupling/scene_contact.hpp>
#include <frictherm/coupling/scene_cost.hpp>
#include <frictherm/coupling/scene_thermal.hpp>  // thermal + coupling sections
#include <frictherm/mechanics/geometry.hpp>
#include <frictherm/mechanics/image.hpp>
#include <frictherm/mechanics/loads.hpp>
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/microstructure.hpp>
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/time_function.hpp>

#include <array>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

namespace frictherm::coupling {

/// A vector of a scene; components past the scene's dimension are 0.
using SceneVec = std::array<double, 3>;

enum class ShapeType { box, ellipse, annulus, polygon, image };

struct ShapeSpec {
  ShapeType type = ShapeType::box;
  SceneVec lo{}, hi{};                             // box
  SceneVec center{}, semi_axes{};                  // ellipse (a disk has equal semi-axes), annulus
  double angle = 0.0;                              // ellipse, 2D only (rad)
  double inner_radius = 0.0, outer_radius = 0.0;   // annulus
  std::vector<std::array<double, 2>> vertices;     // polygon
  double z_lo = 0.0, z_hi = 0.0;                   // polygon and image extrusion (3D)
  std::string image_file;                          // image: path resolved against the scene's folder
  mechanics::GreyImage image;                      // image: the pixels, read while parsing
  std::array<double, 2> origin{};                  // image: lower-left corner (m)
  double pixel_size = 0.0;                         // image (m)
  std::vector<mechanics::GreyLevelMaterial> levels;  // image: grey ranges -> material ids
  mechanics::PixelMaterials pixel_materials;        // image: material per pixel when set (width > 0), e.g.
                                                    // every grain its own material (scene_grains.cpp)
  bool generated = false;                           // image made by "ellipse_packing" (scene_packing.cpp)
  std::string write_image;                          // generated: where a run writes it ("": beside the output)
  std::size_t grain_count = 0;                      // generated: grains placed
  double target_fraction = 0.0, fraction = 0.0;     // generated: asked and achieved grain area fraction
  SceneVec box_lo{}, box_hi{};                     // tight bounding box (checked against the grid)
};

struct BodySpec {
  std::string name;
  int material = -1;  // index into Scene::materials; -1 for image bodies (levels choose)
  ShapeSpec shape;
  int particles_per_cell = 2;  // per direction
  SceneVec velocity{};
  double temperature = 293.15;
};

struct PointLoadSpec {
  int body = -1;  // -1: any body
  bool use_box = false;
  SceneVec point{}, box_lo{}, box_hi{};
  SceneVec force{};
  mechanics::TimeFunction scale = mechanics::TimeFunction::constant(1.0);
};

struct TractionSpec {
  int body = 0;
  int axis = 0;
  bool upper = true;
  SceneVec traction{};
  mechanics::TimeFunction scale = mechanics::TimeFunction::constant(1.0);
};

struct OutputSpec {
  std::string file;                 // as written in the scene, or "<scene name>.h5"
  double snapshot_interval = 0.0;   // s (from snapshot_interval, or end_time / snapshot_count)
  double series_interval = 0.0;     // s; 0 writes a row every step
  std::vector<std::string> fields;  // snapshot fields, in the order they are written
  bool overwrite = false;           // replace an existing output file (else refused; --force does the same)
};

/// A change applied to the scene's JSON before validation (`frictherm run --set solver.cfl=0.3`):
/// `path` is a key path as in error messages (`bodies[0].velocity`), `value` JSON text (a bare word
/// that is not JSON counts as a string).
struct SceneOverride {
  std::string path;
  std::string value;
};

struct Scene {
  std::string text;    // the scene file as read (stored in the output's metadata)
  std::vector<SceneOverride> overrides;  // applied on top of `text`
  std::string json;    // the scene as run: `text` with the overrides, as plain JSON (no comments)
  std::string source;  // file path, or "<string>"
  std::string name;    // file name without folder and extension ("scene" for strings)
  std::string description;
  int dimension = 2;
  mechanics::SimulationOptions options;  // analysis, thickness, solver settings, gravity
  SceneVec grid_lo{}, grid_hi{}, cell_size{};
  std::array<int, 3> cells{{1, 1, 1}};
  std::vector<mechanics::Material> materials;  // ids are positions in this list (file order)
  std::vector<BodySpec> bodies;
  std::vector<mechanics::FixedFace> fixed_faces;
  std::vector<PointLoadSpec> point_loads;
  std::vector<TractionSpec> tractions;
  double end_time = 0.0;  // s
  long max_steps = 0;     // 0: no limit
  int threads = 0;        // 0: OpenMP's default
  double checkpoint_interval = 0.0;  // s of simulated time between checkpoints (checkpoint.hpp); 0: none
  double max_memory = 0.0;  // run.max_memory (bytes); 0: a share of the machine's memory (scene_cost.hpp)
  SceneCost cost;           // estimated while parsing, before anything large is built (scene_cost.hpp)
  OutputSpec output;
  ContactSpec contact;       // `contact` section (scene_contact.hpp); one shared velocity field when absent
  ThermalSceneSpec thermal;  // `thermal` and `coupling` sections (scene_thermal.hpp); disabled when absent
  // Settings the scene may run with but that are known to fail or mislead, each naming its key and
  // what to use instead; `frictherm validate` and `frictherm run` (unless --quiet) print them.
  std::vector<std::string> notes;
};

/// Reads and validates a scene file. Image files are looked up relative to the scene's folder.
/// Throws SceneError (prefixed with nothing: the caller adds the file name when it reports).
Scene load_scene(const std::string& path, const std::vector<SceneOverride>& overrides = {});
/// Parses and validates scene text; `base_dir` resolves relative image paths.
Scene parse_scene(const std::string& text, const std::string& source = "<string>",
                  const std::string& base_dir = ".", const std::string& name = "scene",
                  const std::vector<SceneOverride>& overrides = {});
/// Parses "KEY.PATH=VALUE" (what `--set` takes); throws SceneError when there is no '='.
SceneOverride parse_override(const std::string& assignment);

/// Builds and finalizes the simulation a scene describes (Dim must equal scene.dimension).
/// Throws SceneError naming the body or load a problem comes from (e.g. a body with no particles).
template <int Dim>
std::unique_ptr<mechanics::Simulation<Dim>> build_simulation(const Scene& scene);

/// A time function: a number (constant) or {"type": constant|ramp|sinusoid|table, ...}.
mechanics::TimeFunction parse_time_function(const JsonReader& value);

/// Every snapshot field the runner knows, in writing order (stress_zz only in 2D).
std::vector<std::string> snapshot_field_names(int dimension);

/// Names of the faces of a grid: x_min, x_max, y_min, y_max (, z_min, z_max).
std::vector<std::string> face_names(int dimension);

/// Human-readable summary of a scene and the simulation built from it (what `frictherm validate`
/// prints, without the final "ok"). Builds the simulation, so it validates everything.
void describe_scene(const Scene& scene, std::ostream& out);

extern template std::unique_ptr<mechanics::Simulation<2>> build_simulation<2>(const Scene&);
extern template std::unique_ptr<mechanics::Simulation<3>> build_simulation<3>(const Scene&);

}  // namespace frictherm::coupling
