#include <frictherm/mechanics/microstructure.hpp>

#include <cmath>
#include <stdexcept>

namespace frictherm::mechanics {

GrainLabels label_grains(const GreyImage& image, int min_level, int max_level, Connectivity connectivity) {
  GrainLabels out;
  out.width = image.width;
  out.height = image.height;
  const std::size_t n = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  if (image.pixels.size() != n) throw std::invalid_argument("label_grains: image size does not match its pixels");
  out.label.assign(n, 0);
  out.pixel_count.assign(1, 0);
  auto in_range = [&](std::size_t k) { return image.pixels[k] >= min_level && image.pixels[k] <= max_level; };
  const int reach = connectivity == Connectivity::eight ? 1 : 0;  // diagonal neighbours too
  std::vector<std::size_t> stack;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (out.label[seed] != 0) continue;
    if (!in_range(seed)) {
      ++out.pixel_count[0];
      continue;
    }
    const int id = static_cast<int>(out.pixel_count.size());
    out.pixel_count.push_back(0);
    out.label[seed] = id;
    stack.assign(1, seed);
    while (!stack.empty()) {  // flood fill with an explicit stack
      const std::size_t k = stack.back();
      stack.pop_back();
      ++out.pixel_count[static_cast<std::size_t>(id)];
      const int r = static_cast<int>(k / static_cast<std::size_t>(image.width));
      const int c = static_cast<int>(k % static_cast<std::size_t>(image.width));
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          if ((dr == 0 && dc == 0) || (dr != 0 && dc != 0 && reach == 0)) continue;
          const int rr = r + dr, cc = c + dc;
          if (rr < 0 || rr >= image.height || cc < 0 || cc >= image.width) continue;
          const std::size_t q = static_cast<std::size_t>(rr) * static_cast<std::size_t>(image.width) +
                                static_cast<std::size_t>(cc);
          if (out.label[q] != 0 || !in_range(q)) continue;
          out.label[q] = id;
          stack.push_back(q);
        }
    }
  }
  return out;
}

PixelMaterials materials_by_level(const GreyImage& image, const std::vector<GreyLevelMaterial>& levels) {
  PixelMaterials out;
  out.width = image.width;
  out.height = image.height;
  out.material.assign(image.pixels.size(), -1);
  for (std::size_t k = 0; k < image.pixels.size(); ++k)
    for (const auto& l : levels)
      if (image.pixels[k] >= l.min_level && image.pixels[k] <= l.max_level) {
        out.material[k] = l.material;
        break;
      }
  return out;
}

namespace {

template <int Dim>
class PixelRegion final : public Region<Dim> {
 public:
  PixelRegion(PixelMaterials map, Vec<2> origin, double px, double z_lo, double z_hi)
      : map_(std::move(map)), origin_(origin), px_(px), z_lo_(z_lo), z_hi_(z_hi) {
    if (!(px > 0.0)) throw std::invalid_argument("pixel size must be > 0");
    if (map_.width <= 0 || map_.height <= 0 ||
        map_.material.size() != static_cast<std::size_t>(map_.width) * static_cast<std::size_t>(map_.height))
      throw std::invalid_argument("pixel material map is empty or its size does not match width x height");
    if (Dim == 3 && !(z_hi > z_lo)) throw std::invalid_argument("extruded region needs z_hi > z_lo");
  }
  int material_at(const Vec<Dim>& x) const override {
    if constexpr (Dim == 3)
      if (x[2] < z_lo_ || x[2] > z_hi_) return -1;
    const int col = static_cast<int>(std::floor((x[0] - origin_[0]) / px_));
    const int row_from_bottom = static_cast<int>(std::floor((x[1] - origin_[1]) / px_));
    if (col < 0 || col >= map_.width || row_from_bottom < 0 || row_from_bottom >= map_.height) return -1;
    const std::size_t row = static_cast<std::size_t>(map_.height - 1 - row_from_bottom);
    return map_.material[row * static_cast<std::size_t>(map_.width) + static_cast<std::size_t>(col)];
  }
  Vec<Dim> box_lo() const override { return corner(origin_, z_lo_); }
  Vec<Dim> box_hi() const override { return corner(origin_ + Vec<2>(map_.width * px_, map_.height * px_), z_hi_); }

 private:
  static Vec<Dim> corner(const Vec<2>& p, double z) {
    Vec<Dim> r;
    r[0] = p[0];
    r[1] = p[1];
    if constexpr (Dim == 3) r[2] = z;
    (void)z;
    return r;
  }
  PixelMaterials map_;
  Vec<2> origin_;
  double px_, z_lo_, z_hi_;
};

}  // namespace

template <int Dim>
std::unique_ptr<Region<Dim>> make_pixel_region(PixelMaterials map, Vec<2> origin, double pixel_size, double z_lo,
                                               double z_hi) {
  return std::make_unique<PixelRegion<Dim>>(std::move(map), origin, pixel_size, z_lo, z_hi);
}

template std::unique_ptr<Region<2>> make_pixel_region<2>(PixelMaterials, Vec<2>, double, double, double);
template std::unique_ptr<Region<3>> make_pixel_region<3>(PixelMaterials, Vec<2>, double, double, double);

}  // namespace frictherm::mechanics
