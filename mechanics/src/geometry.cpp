#include <frictherm/mechanics/boundary_points.hpp>
#include <frictherm/mechanics/geometry.hpp>

#include <cmath>
#include <stdexcept>

namespace frictherm::mechanics {

namespace {

template <int Dim>
class Box final : public Region<Dim> {
 public:
  Box(const Vec<Dim>& lo, const Vec<Dim>& hi, int m) : lo_(lo), hi_(hi), material_(m) {
    for (int d = 0; d < Dim; ++d)
      if (!(hi[d] > lo[d])) throw std::invalid_argument("box needs hi > lo in every direction");
  }
  int material_at(const Vec<Dim>& x) const override {
    for (int d = 0; d < Dim; ++d)
      if (x[d] < lo_[d] || x[d] > hi_[d]) return -1;
    return material_;
  }
  Vec<Dim> box_lo() const override { return lo_; }
  Vec<Dim> box_hi() const override { return hi_; }
  std::vector<std::vector<Vec<2>>> boundary_loops(double spacing) const override {
    if constexpr (Dim != 2) return {};
    else return {sample_rectangle_boundary(lo_, hi_, spacing)};
  }

 private:
  Vec<Dim> lo_, hi_;
  int material_;
};

template <int Dim>
class Ellipse final : public Region<Dim> {
 public:
  Ellipse(const Vec<Dim>& c, const Vec<Dim>& a, double angle, int m)
      : c_(c), a_(a), cos_(std::cos(angle)), sin_(std::sin(angle)), material_(m) {
    for (int d = 0; d < Dim; ++d)
      if (!(a[d] > 0.0)) throw std::invalid_argument("ellipse semi-axes must be > 0");
  }
  int material_at(const Vec<Dim>& x) const override {
    Vec<Dim> r = x - c_;
    // rotate into the ellipse's axes (2D); 3D ellipsoids are axis-aligned
    const double rx = cos_ * r[0] + sin_ * r[1];
    const double ry = -sin_ * r[0] + cos_ * r[1];
    r[0] = rx;
    r[1] = ry;
    double s = 0.0;
    for (int d = 0; d < Dim; ++d) s += (r[d] / a_[d]) * (r[d] / a_[d]);
    return s <= 1.0 ? material_ : -1;
  }
  Vec<Dim> box_lo() const override { return c_ - Vec<Dim>::Constant(a_.maxCoeff()); }
  Vec<Dim> box_hi() const override { return c_ + Vec<Dim>::Constant(a_.maxCoeff()); }
  std::vector<std::vector<Vec<2>>> boundary_loops(double spacing) const override {
    if constexpr (Dim != 2) return {};
    else return {sample_ellipse_boundary(c_, a_, std::atan2(sin_, cos_), spacing)};
  }

 private:
  Vec<Dim> c_, a_;
  double cos_, sin_;
  int material_;
};

template <int Dim>
class Annulus final : public Region<Dim> {
 public:
  Annulus(const Vec<Dim>& c, double ri, double ro, int m) : c_(c), ri_(ri), ro_(ro), material_(m) {
    if (!(ri >= 0.0 && ro > ri)) throw std::invalid_argument("annulus needs 0 <= inner_radius < outer_radius");
  }
  int material_at(const Vec<Dim>& x) const override {
    const double r = (x - c_).norm();
    return (r >= ri_ && r <= ro_) ? material_ : -1;
  }
  Vec<Dim> box_lo() const override { return c_ - Vec<Dim>::Constant(ro_); }
  Vec<Dim> box_hi() const override { return c_ + Vec<Dim>::Constant(ro_); }
  std::vector<std::vector<Vec<2>>> boundary_loops(double spacing) const override {
    if constexpr (Dim != 2) return {};
    else if (ri_ > 0.0) return sample_annulus_boundary(c_, ri_, ro_, spacing);
    else return {sample_ellipse_boundary(c_, Vec<2>(ro_, ro_), 0.0, spacing)};
  }

 private:
  Vec<Dim> c_;
  double ri_, ro_;
  int material_;
};

// Planar footprint (polygon or image) extruded in z for 3D.
template <int Dim>
class Extruded : public Region<Dim> {
 public:
  Extruded(double z_lo, double z_hi) : z_lo_(z_lo), z_hi_(z_hi) {
    if (Dim == 3 && !(z_hi > z_lo)) throw std::invalid_argument("extruded region needs z_hi > z_lo");
  }
  int material_at(const Vec<Dim>& x) const override {
    if constexpr (Dim == 3)
      if (x[2] < z_lo_ || x[2] > z_hi_) return -1;
    return planar_material(x[0], x[1]);
  }
  Vec<Dim> box_lo() const override { return expand(planar_lo(), z_lo_); }
  Vec<Dim> box_hi() const override { return expand(planar_hi(), z_hi_); }

 protected:
  virtual int planar_material(double x, double y) const = 0;
  virtual Vec<2> planar_lo() const = 0;
  virtual Vec<2> planar_hi() const = 0;

 private:
  static Vec<Dim> expand(const Vec<2>& p, double z) {
    Vec<Dim> r;
    r[0] = p[0];
    r[1] = p[1];
    if constexpr (Dim == 3) r[2] = z;
    (void)z;
    return r;
  }
  double z_lo_, z_hi_;
};

template <int Dim>
class Polygon final : public Extruded<Dim> {
 public:
  Polygon(std::vector<Vec<2>> v, double z_lo, double z_hi, int m)
      : Extruded<Dim>(z_lo, z_hi), v_(std::move(v)), material_(m) {
    if (v_.size() < 3) throw std::invalid_argument("polygon needs at least 3 vertices");
    lo_ = hi_ = v_[0];
    for (const auto& p : v_) {
      lo_ = lo_.cwiseMin(p);
      hi_ = hi_.cwiseMax(p);
    }
  }

 protected:
  int planar_material(double x, double y) const override {
    bool inside = false;  // even-odd crossing rule
    for (std::size_t i = 0, j = v_.size() - 1; i < v_.size(); j = i++) {
      const Vec<2>& a = v_[i];
      const Vec<2>& b = v_[j];
      if ((a[1] > y) != (b[1] > y)) {
        const double xc = a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
        if (x < xc) inside = !inside;
      }
    }
    return inside ? material_ : -1;
  }
  Vec<2> planar_lo() const override { return lo_; }
  Vec<2> planar_hi() const override { return hi_; }

 public:
  std::vector<std::vector<Vec<2>>> boundary_loops(double spacing) const override {
    if constexpr (Dim != 2) return {};
    else return {sample_polygon_boundary(v_, spacing)};
  }

 private:
  std::vector<Vec<2>> v_;
  Vec<2> lo_, hi_;
  int material_;
};

template <int Dim>
class ImageRegion final : public Extruded<Dim> {
 public:
  ImageRegion(GreyImage img, Vec<2> origin, double px, std::vector<GreyLevelMaterial> levels, double z_lo,
              double z_hi)
      : Extruded<Dim>(z_lo, z_hi), img_(std::move(img)), origin_(origin), px_(px), levels_(std::move(levels)) {
    if (!(px > 0.0)) throw std::invalid_argument("image pixel size must be > 0");
  }

 protected:
  int planar_material(double x, double y) const override {
    const int col = static_cast<int>(std::floor((x - origin_[0]) / px_));
    const int row_from_bottom = static_cast<int>(std::floor((y - origin_[1]) / px_));
    if (col < 0 || col >= img_.width || row_from_bottom < 0 || row_from_bottom >= img_.height) return -1;
    const int grey = img_.at(col, img_.height - 1 - row_from_bottom);
    for (const auto& l : levels_)
      if (grey >= l.min_level && grey <= l.max_level) return l.material;
    return -1;
  }
  Vec<2> planar_lo() const override { return origin_; }
  Vec<2> planar_hi() const override { return origin_ + Vec<2>(img_.width * px_, img_.height * px_); }

 private:
  GreyImage img_;
  Vec<2> origin_;
  double px_;
  std::vector<GreyLevelMaterial> levels_;
};

}  // namespace

template <int Dim>
std::unique_ptr<Region<Dim>> make_box(const Vec<Dim>& lo, const Vec<Dim>& hi, int material) {
  return std::make_unique<Box<Dim>>(lo, hi, material);
}
template <int Dim>
std::unique_ptr<Region<Dim>> make_ellipse(const Vec<Dim>& c, const Vec<Dim>& a, double angle, int material) {
  return std::make_unique<Ellipse<Dim>>(c, a, angle, material);
}
template <int Dim>
std::unique_ptr<Region<Dim>> make_annulus(const Vec<Dim>& c, double ri, double ro, int material) {
  return std::make_unique<Annulus<Dim>>(c, ri, ro, material);
}
template <int Dim>
std::unique_ptr<Region<Dim>> make_polygon(const std::vector<Vec<2>>& v, double z_lo, double z_hi, int material) {
  return std::make_unique<Polygon<Dim>>(v, z_lo, z_hi, material);
}
template <int Dim>
std::unique_ptr<Region<Dim>> make_image_region(GreyImage image, Vec<2> origin, double pixel_size,
                                               std::vector<GreyLevelMaterial> levels, double z_lo, double z_hi) {
  return std::make_unique<ImageRegion<Dim>>(std::move(image), origin, pixel_size, std::move(levels), z_lo, z_hi);
}

#define FRICTHERM_INSTANTIATE_GEOMETRY(D)                                                                      \
  template std::unique_ptr<Region<D>> make_box<D>(const Vec<D>&, const Vec<D>&, int);                          \
  template std::unique_ptr<Region<D>> make_ellipse<D>(const Vec<D>&, const Vec<D>&, double, int);              \
  template std::unique_ptr<Region<D>> make_annulus<D>(const Vec<D>&, double, double, int);                     \
  template std::unique_ptr<Region<D>> make_polygon<D>(const std::vector<Vec<2>>&, double, double, int);        \
  template std::unique_ptr<Region<D>> make_image_region<D>(GreyImage, Vec<2>, double,                          \
                                                           std::vector<GreyLevelMaterial>, double, double);
FRICTHERM_INSTANTIATE_GEOMETRY(2)
FRICTHERM_INSTANTIATE_GEOMETRY(3)
#undef FRICTHERM_INSTANTIATE_GEOMETRY

}  // namespace frictherm::mechanics
