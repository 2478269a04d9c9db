#pragma once
// Structured background grid. The physical region [lo, hi] is divided into `cells` cells of size h;
// one layer of ghost nodes surrounds it so that every shape function (linear, uGIMP with particle
// half-width <= h/2, quadratic B-spline) of a particle inside [lo, hi] finds all of its nodes.
#include <frictherm/mechanics/types.hpp>

#include <cstddef>
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

template <int Dim>
class Grid {
 public:
  static constexpr int ghost = 1;

  Grid() = default;
  Grid(const Vec<Dim>& lo, const Vec<Dim>& cell_size, const IVec<Dim>& cells) : lo_(lo), h_(cell_size), cells_(cells) {
    std::size_t n = 1;
    for (int d = 0; d < Dim; ++d) {
      if (!(cell_size[d] > 0.0)) throw std::invalid_argument("grid cell size must be > 0");
      if (cells[d] < 1) throw std::invalid_argument("grid must have at least one cell per direction");
      nodes_per_dim_[d] = cells[d] + 1 + 2 * ghost;
      stride_[d] = static_cast<int>(n);
      n *= static_cast<std::size_t>(nodes_per_dim_[d]);
      inv_h_[d] = 1.0 / cell_size[d];
    }
    node_count_ = n;
  }

  const Vec<Dim>& lo() const { return lo_; }
  Vec<Dim> hi() const {
    Vec<Dim> r;
    for (int d = 0; d < Dim; ++d) r[d] = lo_[d] + h_[d] * cells_[d];
    return r;
  }
  const Vec<Dim>& cell_size() const { return h_; }
  const Vec<Dim>& inverse_cell_size() const { return inv_h_; }
  const IVec<Dim>& cells() const { return cells_; }
  const IVec<Dim>& nodes_per_dim() const { return nodes_per_dim_; }
  const IVec<Dim>& strides() const { return stride_; }
  std::size_t node_count() const { return node_count_; }
  double min_cell_size() const { return h_.minCoeff(); }
  double cell_volume() const { return h_.prod(); }

  /// Flat index of node with lattice coordinates i (physical nodes run 0..cells[d], ghosts -1 and cells+1).
  int node_index(const IVec<Dim>& i) const {
    int k = 0;
    for (int d = 0; d < Dim; ++d) k += (i[d] + ghost) * stride_[d];
    return k;
  }
  IVec<Dim> node_lattice(int k) const {
    IVec<Dim> i{};
    for (int d = Dim - 1; d >= 0; --d) {
      i[d] = k / stride_[d] - ghost;
      k %= stride_[d];
    }
    return i;
  }
  Vec<Dim> node_position(int k) const {
    const IVec<Dim> i = node_lattice(k);
    Vec<Dim> x;
    for (int d = 0; d < Dim; ++d) x[d] = lo_[d] + h_[d] * i[d];
    return x;
  }
  bool contains(const Vec<Dim>& x) const {
    for (int d = 0; d < Dim; ++d)
      if (!(x[d] >= lo_[d] && x[d] <= lo_[d] + h_[d] * cells_[d])) return false;
    return true;
  }

 private:
  Vec<Dim> lo_ = Vec<Dim>::Zero();
  Vec<Dim> h_ = Vec<Dim>::Ones();
  Vec<Dim> inv_h_ = Vec<Dim>::Ones();
  IVec<Dim> cells_{};
  IVec<Dim> nodes_per_dim_{};
  IVec<Dim> stride_{};
  std::size_t node_count_ = 0;
};

}  // namespace frictherm::mechanics
