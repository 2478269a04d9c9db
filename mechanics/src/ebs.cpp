// Extended B-splines: volume fractions, classification, extension coefficients and cell tables
// (Kakouris, Chatzis & Triantafyllou 2024 §3.3, Algorithm 2). See docs/ebs.md.
#include <frictherm/mechanics/ebs.hpp>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace frictherm::mechanics {

namespace {

/// Calls f(l) for every lattice point of the box lo..hi (inclusive), axis 0 fastest.
template <int Dim, class F>
void for_box(const IVec<Dim>& lo, const IVec<Dim>& hi, F&& f) {
  for (int d = 0; d < Dim; ++d)
    if (hi[d] < lo[d]) return;
  IVec<Dim> l = lo;
  for (;;) {
    f(l);
    int d = 0;
    for (; d < Dim; ++d) {
      if (++l[d] <= hi[d]) break;
      l[d] = lo[d];
    }
    if (d == Dim) return;
  }
}

template <int Dim>
IVec<Dim> shifted(const IVec<Dim>& l, int by) {
  IVec<Dim> r;
  for (int d = 0; d < Dim; ++d) r[d] = l[d] + by;
  return r;
}

}  // namespace

template <int Dim>
void EbsBasis<Dim>::rebuild(const Grid<Dim>& grid, const std::vector<Vec<Dim>>& position,
                            const std::vector<double>& volume, std::size_t begin, std::size_t end) {
  if (end < begin || end > position.size() || end > volume.size())
    throw std::out_of_range("EbsBasis::rebuild: particle range outside the particle arrays");
  rebuild_impl(grid, end - begin, [&](std::size_t i, double& V) -> const Vec<Dim>& {
    V = volume[begin + i];
    return position[begin + i];
  });
}

template <int Dim>
void EbsBasis<Dim>::rebuild(const Grid<Dim>& grid, const std::vector<Vec<Dim>>& position,
                            const std::vector<double>& volume, const std::vector<std::size_t>& particles) {
  for (std::size_t p : particles)
    if (p >= position.size() || p >= volume.size())
      throw std::out_of_range("EbsBasis::rebuild: particle index outside the particle arrays");
  rebuild_impl(grid, particles.size(), [&](std::size_t i, double& V) -> const Vec<Dim>& {
    V = volume[particles[i]];
    return position[particles[i]];
  });
}

template <int Dim>
void EbsBasis<Dim>::rebuild(const Grid<Dim>& grid, const std::vector<Vec<Dim>>& position,
                            const std::vector<double>& volume,
                            const std::vector<std::pair<std::size_t, std::size_t>>& ranges) {
  std::size_t n = 0;
  for (const auto& r : ranges) {
    if (r.second < r.first || r.second > position.size() || r.second > volume.size())
      throw std::out_of_range("EbsBasis::rebuild: particle range outside the particle arrays");
    n += r.second - r.first;
  }
  // rebuild_impl visits i = 0 .. n-1 in order, twice: follow the ranges with a cursor.
  std::size_t range = 0, start = 0;  // local index of the first particle of ranges[range]
  rebuild_impl(grid, n, [&](std::size_t i, double& V) -> const Vec<Dim>& {
    if (i < start) range = 0, start = 0;  // second pass: restart
    while (i >= start + (ranges[range].second - ranges[range].first)) {
      start += ranges[range].second - ranges[range].first;
      ++range;
    }
    const std::size_t p = ranges[range].first + (i - start);
    V = volume[p];
    return position[p];
  });
}

template <int Dim>
template <class Get>
void EbsBasis<Dim>::rebuild_impl(const Grid<Dim>& grid, std::size_t n, Get get) {
  if (!(opt_.occupation >= 0.0) || !std::isfinite(opt_.occupation))
    throw std::invalid_argument("EBS occupation parameter C_c must be finite and >= 0");
  if (!(opt_.out_of_plane > 0.0) || !std::isfinite(opt_.out_of_plane))
    throw std::invalid_argument("EBS out_of_plane (thickness / cross-section) must be finite and > 0");
  if (opt_.search_radius < 0) throw std::invalid_argument("EBS search_radius must be >= 0");
  if (kept_ && kept_->size() != grid.node_count())
    throw std::invalid_argument("EbsBasis::rebuild: the kept-node mask must have one entry per grid node");
  const IVec<Dim>& cells = grid.cells();

  // Pass 1: validate every particle; the cells its domain overlaps, the body's bounding box of them.
  // The domain of particle p is the cell's shape scaled to the particle's current volume, side
  // h_d (Ω_p/Ω_c)^(1/Dim) centred on x_p (the uGIMP domain with the current volume), clipped to the
  // grid's cells. Counting each particle whole in the cell that holds its position (eq. 19 read
  // literally) quantises φ_c in steps of 1/(particles per cell): with 2 × 2 particles per cell, a
  // cell inside a body reads φ_c = 0.5 whenever a column of particles sits on one of its faces, turns
  // "boundary" at C_c = 0.5, and the extension (3, -3, 1) then takes the mass of a full cell off a
  // stable node (docs/ebs.md, "Volume fraction").
  const double measure = grid.cell_volume() * (Dim < 3 ? opt_.out_of_plane : 1.0);
  auto domain_of = [&](const Vec<Dim>& x, double V, std::size_t i, Vec<Dim>& lower, Vec<Dim>& upper, IVec<Dim>& klo,
                       IVec<Dim>& khi) {
    const double a = 0.5 * std::pow(V / measure, 1.0 / Dim);  // half side, in cells
    for (int d = 0; d < Dim; ++d) {
      const double s = (x[d] - grid.lo()[d]) * grid.inverse_cell_size()[d];  // as QuadraticBSplineKernel
      if (!(s >= -0.5 && s < cells[d] + 0.5)) {
        std::ostringstream msg;
        msg << "EbsBasis::rebuild: particle " << i << " at " << x.transpose() << " is outside the grid";
        throw std::out_of_range(msg.str());
      }
      lower[d] = std::max(s - a, -0.5);
      upper[d] = std::min(s + a, cells[d] + 0.5);
      klo[d] = static_cast<int>(std::floor(lower[d] + 0.5));          // cells k with k + 1/2 > lower
      khi[d] = std::min(static_cast<int>(std::ceil(upper[d] + 0.5)) - 1, cells[d]);  // k - 1/2 < upper
    }
  };
  IVec<Dim> cmin, cmax;
  cmin.fill(INT_MAX);
  cmax.fill(INT_MIN);
  for (std::size_t i = 0; i < n; ++i) {
    double V = 0.0;
    const Vec<Dim>& x = get(i, V);
    if (!(V > 0.0) || !std::isfinite(V)) throw std::invalid_argument("EbsBasis::rebuild: particle volume must be finite and > 0");
    Vec<Dim> lower, upper;
    IVec<Dim> klo, khi;
    domain_of(x, V, i, lower, upper, klo, khi);
    for (int d = 0; d < Dim; ++d) {
      cmin[d] = std::min(cmin[d], klo[d]);
      cmax[d] = std::max(cmax[d], khi[d]);
    }
  }

  // Input is valid: from here on the object describes this body on this grid.
  grid_ = grid;
  cell_measure_ = measure;

  // Region = bounding box + 1: every node whose support meets a cell of the box.
  std::size_t total = 1;
  for (int d = 0; d < Dim; ++d) {
    if (n == 0) {
      org_[d] = 0;
      ext_[d] = 0;
    } else {
      org_[d] = cmin[d] - 1;  // >= -1 = first ghost node
      ext_[d] = cmax[d] + 1 - org_[d] + 1;
    }
    rstride_[d] = static_cast<int>(total);
    total *= static_cast<std::size_t>(ext_[d]);
  }
  volume_.assign(total, 0.0);
  cell_.assign(total, EbsCell::exterior);
  node_.assign(total, EbsNode::inactive);
  ext_id_.assign(total, -1);
  cell_table_.assign(total, EbsStencil<Dim>::empty);
  ext_node_.clear();
  ext_begin_.assign(1, 0);
  ext_I_.clear();
  ext_E_.clear();
  table_begin_.assign(1, 0);
  out_node_.clear();
  out_begin_.assign(1, 0);
  term_a_.clear();
  term_w_.clear();
  stable_count_ = degenerate_count_ = promoted_count_ = max_stencil_ = extended_cells_ = 0;
  if (n == 0) return;

  // Pass 2: the material volume in each cell (Kakouris 2024 eq. 19 numerator), Σ_p Ω_p |D_p ∩ c| / |D_p|
  // over the particles' domains D_p. For domains that tile the body this is the body's volume in the
  // cell, whatever the particles' positions.
  for (std::size_t i = 0; i < n; ++i) {
    double V = 0.0;
    const Vec<Dim>& x = get(i, V);
    Vec<Dim> lower, upper;
    IVec<Dim> klo, khi;
    domain_of(x, V, i, lower, upper, klo, khi);
    for_box<Dim>(klo, khi, [&](const IVec<Dim>& c) {
      double f = measure;  // Ω_p / |D_p| with |D_p| in cells^Dim is Ω_c
      for (int d = 0; d < Dim; ++d) {
        const double overlap = std::min(upper[d], c[d] + 0.5) - std::max(lower[d], c[d] - 0.5);
        if (overlap <= 1e-12) return;  // a domain ending on a face: round-off, not material
        f *= overlap;
      }
      volume_[static_cast<std::size_t>(local(c))] += f;
    });
  }

  // Cells: interior if φ_c > C_c, boundary if 0 < φ_c <= C_c, exterior if φ_c = 0 (eq. 20).
  for_box<Dim>(cmin, cmax, [&](const IVec<Dim>& c) {
    const auto k = static_cast<std::size_t>(local(c));
    const double phi = volume_[k] / cell_measure_;
    cell_[k] = phi > opt_.occupation ? EbsCell::interior : (volume_[k] > 0.0 ? EbsCell::boundary : EbsCell::exterior);
  });

  // Bases: stable if the support (cells J-1..J+1) holds an interior cell, degenerate if it holds
  // boundary cells only, inactive otherwise (§3.3.1 step 3). The 3^Dim-neighbourhood "any" is
  // computed as Dim separable passes over the region.
  constexpr std::uint8_t has_interior = 1, has_boundary = 2;
  flags_.resize(total);
  for (std::size_t k = 0; k < total; ++k)
    flags_[k] = cell_[k] == EbsCell::interior ? has_interior : (cell_[k] == EbsCell::boundary ? has_boundary : 0);
  dilate();
  for (std::size_t k = 0; k < total; ++k)
    node_[k] = (flags_[k] & has_interior) ? EbsNode::stable : (flags_[k] & has_boundary ? EbsNode::degenerate : EbsNode::inactive);

  // Extension of each degenerate J (eqs. 22-23): Q_J = the interior cell nearest to J (Euclidean
  // index distance, first in scan order on ties) within search_radius; the stencil is the 3^Dim
  // B-splines that are non-zero on Q_J, κ_J = Q_J - 1, all stable because their support holds Q_J.
  // Candidate offsets are probed by increasing distance; |off|_inf <= 1 is J's support, never interior.
  const IVec<Dim> nlo = shifted<Dim>(cmin, -1), nhi = shifted<Dim>(cmax, 1);  // all non-inactive nodes
  const int R = opt_.search_radius;
  offsets_.clear();
  for_box<Dim>(shifted<Dim>(IVec<Dim>{}, -R), shifted<Dim>(IVec<Dim>{}, R), [&](const IVec<Dim>& off) {
    int d2 = 0, inf = 0;
    for (int d = 0; d < Dim; ++d) {
      d2 += off[d] * off[d];
      inf = std::max(inf, std::abs(off[d]));
    }
    if (inf >= 2) offsets_.push_back({off, d2});
  });
  std::stable_sort(offsets_.begin(), offsets_.end(), [](const Offset& x, const Offset& y) { return x.d2 < y.d2; });
  for_box<Dim>(nlo, nhi, [&](const IVec<Dim>& J) {
    const auto kJ = static_cast<std::size_t>(local(J));
    if (node_[kJ] != EbsNode::degenerate) {
      if (node_[kJ] == EbsNode::stable) ++stable_count_;
      return;
    }
    int best = INT_MAX;
    IVec<Dim> Q{};
    const bool kept = kept_ && (*kept_)[static_cast<std::size_t>(grid_.node_index(J))];
    for (const Offset& o : offsets_) {
      if (kept) break;  // a node with a velocity condition keeps its own B-spline
      IVec<Dim> c;
      for (int d = 0; d < Dim; ++d) c[d] = J[d] + o.off[d];
      if (in_region(c) && cell_[static_cast<std::size_t>(local(c))] == EbsCell::interior) {
        best = o.d2;
        Q = c;
        break;
      }
    }
    if (best == INT_MAX) {  // kept, or no interior cell near: the plain B-spline (docs/ebs.md)
      node_[kJ] = EbsNode::stable;
      ++stable_count_;
      ++promoted_count_;
      return;
    }
    std::array<double, 3 * Dim> w;
    IVec<Dim> kappa;
    for (int d = 0; d < Dim; ++d) {
      kappa[d] = Q[d] - 1;
      const double t = J[d] - kappa[d];  // 1D Lagrange basis on {0,1,2} evaluated at t (eq. 23)
      w[static_cast<std::size_t>(3 * d + 0)] = 0.5 * (t - 1.0) * (t - 2.0);
      w[static_cast<std::size_t>(3 * d + 1)] = -t * (t - 2.0);
      w[static_cast<std::size_t>(3 * d + 2)] = 0.5 * t * (t - 1.0);
    }
    ext_id_[kJ] = static_cast<std::int32_t>(ext_node_.size());
    ext_node_.push_back(grid_.node_index(J));
    for (int b = 0; b < EbsStencil<Dim>::block; ++b) {  // E_IJ = Π_a L_{I_a - κ_a}(J_a - κ_a) (eq. 23)
      IVec<Dim> I;
      double E = 1.0;
      for (int d = 0, r = b; d < Dim; ++d, r /= 3) {
        I[d] = kappa[d] + r % 3;
        E *= w[static_cast<std::size_t>(3 * d + r % 3)];
      }
      if (E == 0.0) continue;  // J inside the stencil along some axis: (0, 1, 0) there
      ext_I_.push_back(grid_.node_index(I));
      ext_E_.push_back(E);
    }
    ext_begin_.push_back(static_cast<std::int32_t>(ext_E_.size()));
    ++degenerate_count_;
  });

  // Cell tables for the cells holding particles (where the basis lives): plain if the block of
  // 3^Dim nodes has no degenerate node (it has no inactive one: every support holds the cell),
  // a table otherwise. Other cells stay empty.
  constexpr std::uint8_t degenerate = 1;
  for (std::size_t k = 0; k < total; ++k) flags_[k] = node_[k] == EbsNode::degenerate ? degenerate : 0;
  dilate();
  for_box<Dim>(cmin, cmax, [&](const IVec<Dim>& c) {
    const auto k = static_cast<std::size_t>(local(c));
    if (cell_[k] == EbsCell::exterior) return;
    if (flags_[k] & degenerate) {
      ++extended_cells_;
      build_table(c);
    } else {
      cell_table_[k] = EbsStencil<Dim>::plain;
      max_stencil_ = std::max(max_stencil_, EbsStencil<Dim>::block);
    }
  });
}

// f[k] |= f[k ± stride_d] along every axis d: afterwards flags_[k] is the OR over the 3^Dim block
// around k (entries outside the region count as 0).
template <int Dim>
void EbsBasis<Dim>::dilate() {
  for (int d = 0; d < Dim; ++d) {
    flags_tmp_ = flags_;
    const int s = rstride_[d], n = ext_[d];
    for (std::size_t k = 0; k < flags_.size(); ++k) {
      const int c = (static_cast<int>(k) / s) % n;
      if (c > 0) flags_[k] |= flags_tmp_[k - static_cast<std::size_t>(s)];
      if (c < n - 1) flags_[k] |= flags_tmp_[k + static_cast<std::size_t>(s)];
    }
  }
}

// N^e_I(x) = N_I(x) + Σ_J E_IJ N_J(x) over the 3^Dim B-splines N_a non-zero in cell c (eq. 25):
// stable a contributes (a -> a, 1), degenerate a contributes (a -> I, E_Ia) for I in its stencil,
// inactive a nothing. Terms are grouped by output node.
template <int Dim>
void EbsBasis<Dim>::build_table(const IVec<Dim>& c) {
  scratch_.clear();
  for (int a = 0; a < EbsStencil<Dim>::block; ++a) {
    IVec<Dim> l;
    for (int d = 0, r = a; d < Dim; ++d, r /= 3) l[d] = c[d] - 1 + r % 3;
    const auto k = static_cast<std::size_t>(local(l));
    if (node_[k] == EbsNode::stable) {
      scratch_.push_back({grid_.node_index(l), a, 1.0});
    } else if (node_[k] == EbsNode::degenerate) {
      const auto e = static_cast<std::size_t>(ext_id_[k]);
      for (std::int32_t q = ext_begin_[e]; q < ext_begin_[e + 1]; ++q)
        scratch_.push_back({ext_I_[static_cast<std::size_t>(q)], a, ext_E_[static_cast<std::size_t>(q)]});
    }
  }
  std::sort(scratch_.begin(), scratch_.end(),
            [](const Term& x, const Term& y) { return x.node != y.node ? x.node < y.node : x.a < y.a; });
  const auto t = static_cast<std::int32_t>(table_begin_.size() - 1);
  int outputs = 0;
  for (std::size_t q = 0; q < scratch_.size(); ++q) {
    if (q == 0 || scratch_[q].node != scratch_[q - 1].node) {
      if (q != 0) out_begin_.push_back(static_cast<std::int32_t>(term_w_.size()));
      out_node_.push_back(scratch_[q].node);
      ++outputs;
    }
    term_a_.push_back(static_cast<std::uint8_t>(scratch_[q].a));
    term_w_.push_back(scratch_[q].w);
  }
  if (!scratch_.empty()) out_begin_.push_back(static_cast<std::int32_t>(term_w_.size()));
  table_begin_.push_back(static_cast<std::int32_t>(out_node_.size()));
  cell_table_[static_cast<std::size_t>(local(c))] = t;
  max_stencil_ = std::max(max_stencil_, outputs);
}

template <int Dim>
int EbsBasis<Dim>::local_of_node(int node) const {
  if (node < 0 || static_cast<std::size_t>(node) >= grid_.node_count()) return -1;
  const IVec<Dim> l = grid_.node_lattice(node);
  return in_region(l) ? local(l) : -1;
}

template <int Dim>
double EbsBasis<Dim>::volume_fraction(int node) const {
  const int k = local_of_node(node);
  return k < 0 ? 0.0 : volume_[static_cast<std::size_t>(k)] / cell_measure_;
}

template <int Dim>
EbsCell EbsBasis<Dim>::cell_state(int node) const {
  const int k = local_of_node(node);
  return k < 0 ? EbsCell::exterior : cell_[static_cast<std::size_t>(k)];
}

template <int Dim>
EbsNode EbsBasis<Dim>::node_state(int node) const {
  const int k = local_of_node(node);
  return k < 0 ? EbsNode::inactive : node_[static_cast<std::size_t>(k)];
}

template class EbsBasis<1>;
template class EbsBasis<2>;
template class EbsBasis<3>;

}  // namespace frictherm::mechanics
