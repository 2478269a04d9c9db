#pragma once
// Image microstructures: connected-component labelling of grains in a grey-scale image, and a
// region whose material is given per pixel (every grain its own material, as in the PBX specimen
// of Nairn, Bardenhagen & Smith 2018, section 3). Random ellipse packings: ellipse_packing.hpp.
#include <frictherm/mechanics/geometry.hpp>
#include <frictherm/mechanics/image.hpp>

#include <cstddef>
#include <memory>
#include <vector>

namespace frictherm::mechanics {

/// Which neighbours join pixels into one grain: the 4 sharing an edge, or the 8 sharing an edge or
/// a corner.
enum class Connectivity { four, eight };

struct GrainLabels {
  int width = 0, height = 0;
  std::vector<int> label;                // per pixel, row-major as GreyImage: 0 = not a grain, 1..count
  std::vector<std::size_t> pixel_count;  // per label (index 0: pixels outside every grain); size count + 1
  int count() const { return static_cast<int>(pixel_count.size()) - 1; }
  int at(int column, int row) const { return label[static_cast<std::size_t>(row) * width + column]; }
};

/// Labels the connected groups of pixels whose grey level lies in [min_level, max_level]. Labels are
/// numbered 1, 2, ... in the order their first pixel is met scanning rows from the top, each row from
/// the left (deterministic).
GrainLabels label_grains(const GreyImage& image, int min_level, int max_level,
                         Connectivity connectivity = Connectivity::eight);

/// A material per pixel: row-major, row 0 at the top (as GreyImage); -1 leaves the pixel empty.
struct PixelMaterials {
  int width = 0, height = 0;
  std::vector<int> material;
};

/// The material of every pixel through grey-level ranges (the first range containing the level wins;
/// -1 where none does).
PixelMaterials materials_by_level(const GreyImage& image, const std::vector<GreyLevelMaterial>& levels);

/// A region defined pixel by pixel: lower-left corner at `origin`, square pixels of `pixel_size`; in 3D
/// extruded over [z_lo, z_hi].
template <int Dim>
std::unique_ptr<Region<Dim>> make_pixel_region(PixelMaterials map, Vec<2> origin, double pixel_size, double z_lo,
                                               double z_hi);

}  // namespace frictherm::mechanics
