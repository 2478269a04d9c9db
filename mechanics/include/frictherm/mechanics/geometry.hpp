#pragma once
// Regions that bodies fill with particles. Setup-time only (virtual calls are fine here).
#include <frictherm/mechanics/image.hpp>
#include <frictherm/mechanics/types.hpp>

#include <memory>
#include <vector>

namespace frictherm::mechanics {

/// A region of space; `material_at` returns the material of point x, or -1 if x is outside.
template <int Dim>
class Region {
 public:
  virtual ~Region() = default;
  virtual int material_at(const Vec<Dim>& x) const = 0;
  virtual Vec<Dim> box_lo() const = 0;  // axis-aligned bounding box
  virtual Vec<Dim> box_hi() const = 0;
  /// 2D: the region's boundary as closed loops sampled with points at most `spacing` apart, material
  /// on the left (outer loops counter-clockwise, holes clockwise), for penalty contact
  /// (boundary_points.hpp). Empty when the region has none (images, 3D).
  virtual std::vector<std::vector<Vec<2>>> boundary_loops(double /*spacing*/) const { return {}; }
};

/// Rectangle (2D) or box (3D) [lo, hi].
template <int Dim>
std::unique_ptr<Region<Dim>> make_box(const Vec<Dim>& lo, const Vec<Dim>& hi, int material);
/// Ellipse (2D) or ellipsoid (3D) with semi-axes; a disk or sphere when they are equal; rotated by
/// `angle` (radians, 2D only).
template <int Dim>
std::unique_ptr<Region<Dim>> make_ellipse(const Vec<Dim>& center, const Vec<Dim>& semi_axes, double angle,
                                          int material);
/// Annulus (2D) or spherical shell (3D): inner_radius <= |x - c| <= outer_radius.
template <int Dim>
std::unique_ptr<Region<Dim>> make_annulus(const Vec<Dim>& center, double inner_radius, double outer_radius,
                                          int material);
/// Simple polygon (even-odd rule) in the x-y plane; in 3D extruded over [z_lo, z_hi].
template <int Dim>
std::unique_ptr<Region<Dim>> make_polygon(const std::vector<Vec<2>>& vertices, double z_lo, double z_hi,
                                          int material);
/// Grey-scale image placed with its lower-left corner at `origin` and square pixels of `pixel_size`;
/// grey levels map to materials through `levels`; in 3D extruded over [z_lo, z_hi].
template <int Dim>
std::unique_ptr<Region<Dim>> make_image_region(GreyImage image, Vec<2> origin, double pixel_size,
                                               std::vector<GreyLevelMaterial> levels, double z_lo, double z_hi);

}  // namespace frictherm::mechanics
