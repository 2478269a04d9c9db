// Sub-cell interface temperature: step responses and the binned heat history (interface_heating.hpp).
#include <frictherm/thermal/interface_heating.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace frictherm::thermal {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

double HalfSpace::effusivity() const { return std::sqrt(conductivity * volumetric_heat_capacity); }

double half_space_pair_step_response(double t, const HalfSpace& a, const HalfSpace& b) {
  if (!(t > 0.0)) return 0.0;
  return 2.0 * std::sqrt(t / kPi) / (a.effusivity() + b.effusivity());
}

namespace {

// Gauss–Legendre, 8 nodes on [−1, 1].
constexpr double kGaussX[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                               0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
constexpr double kGaussW[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                               0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};

// The quadrature's nodes and weights in φ, with cos φ and 1 − cos φ (= 2 sin²(φ/2), no cancellation),
// computed once: they do not depend on t, λ or f.
struct ChainQuadrature {
  std::vector<double> weight, cos_phi, one_minus_cos;
  ChainQuadrature() {
    double hi = kPi;
    for (int panel = 0; panel < 80 && hi > 1e-12; ++panel) {
      const double lo = panel == 79 ? 0.0 : 0.7 * hi;
      const double mid = 0.5 * (hi + lo), half = 0.5 * (hi - lo);
      for (int i = 0; i < 8; ++i) {
        const double phi = mid + half * kGaussX[i];
        weight.push_back(half * kGaussW[i]);
        cos_phi.push_back(std::cos(phi));
        one_minus_cos.push_back(2.0 * std::sin(0.5 * phi) * std::sin(0.5 * phi));
      }
      hi = lo;
    }
  }
};

// The unit-step response of node 0 of a uniform infinite chain (node mass m = h C, conductance k/h,
// λ = α/h²) fed at node 0, with source and conduction both passed through the projection stencil
// P̂(φ) = f + (1 − f) cos φ, in units of 1/m: (1/π) ∫₀^π P̂ (1 − e^{−s t})/s dφ, s = 2λ P̂ (1 − cos φ).
// Composite Gauss–Legendre (ChainQuadrature) on panels that shrink geometrically towards φ = 0, where the integrand
// concentrates at late times (φ ≲ 1/√(λt)).
double filtered_chain_step(double t, double lambda, double f) {
  static const ChainQuadrature q;
  double sum = 0.0;
  for (std::size_t j = 0; j < q.weight.size(); ++j) {
    const double filter = f + (1.0 - f) * q.cos_phi[j];
    const double s = 2.0 * lambda * filter * q.one_minus_cos[j];
    const double st = s * t;
    const double value = st < 1e-8 ? t * (1.0 - 0.5 * st) : -std::expm1(-st) / s;
    sum += q.weight[j] * filter * value;
  }
  return sum / kPi;
}

}  // namespace

double lumped_grid_step_response(double t, const HalfSpace& a, const HalfSpace& b, double h, double f) {
  if (!(t > 0.0)) return 0.0;
  const double ea = a.effusivity(), eb = b.effusivity(), e = ea + eb;
  auto side = [&](const HalfSpace& s, double es) {
    // Side s with its share e_s/Σe of the flux on a half chain: twice the full chain's node-0 response.
    return (es / e) * (2.0 / (h * s.volumetric_heat_capacity)) * filtered_chain_step(t, s.diffusivity() / (h * h), f);
  };
  return (ea / e) * side(a, ea) + (eb / e) * side(b, eb);
}

SubcellCorrection::SubcellCorrection(const HalfSpace& a, const HalfSpace& b, double h, double f)
    : a_(a), b_(b), h_(h), f_(f) {
  if (!(h > 0.0) || !(f > 0.0 && f <= 1.0) || !(a.conductivity > 0.0) || !(b.conductivity > 0.0) ||
      !(a.volumetric_heat_capacity > 0.0) || !(b.volumetric_heat_capacity > 0.0))
    throw std::invalid_argument("SubcellCorrection: needs h > 0, f in (0, 1] and conducting sides");
  const double tau_fast = h * h / std::max(a.diffusivity(), b.diffusivity());
  const double tau_slow = h * h / std::min(a.diffusivity(), b.diffusivity());
  constexpr double kPerDecade = 24.0;
  log_t0_ = std::log(1e-6 * tau_fast);
  dlog_ = std::log(10.0) / kPerDecade;
  const auto n = static_cast<std::size_t>(std::ceil((std::log(1e5 * tau_slow) - log_t0_) / dlog_)) + 1;
  ratio_.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    const double t = std::exp(log_t0_ + static_cast<double>(j) * dlog_);
    const double rc = half_space_pair_step_response(t, a, b);
    ratio_[j] = (rc - lumped_grid_step_response(t, a, b, h, f)) / rc;
  }
}

double SubcellCorrection::step_response(double t) const {
  if (!(t > 0.0)) return 0.0;
  const double rc = half_space_pair_step_response(t, a_, b_);
  const double x = (std::log(t) - log_t0_) / dlog_;
  if (x <= 0.0) {  // t ≪ h²/α: the grid's interface node has only warmed by f q t / m₀
    return rc - 2.0 * f_ * t / (h_ * (a_.volumetric_heat_capacity + b_.volumetric_heat_capacity));
  }
  const auto last = ratio_.size() - 1;
  if (x >= static_cast<double>(last))  // the tail: R_x/R_c falls as 1/t (the lattice's next term)
    return rc * ratio_[last] * std::exp(-(x - static_cast<double>(last)) * dlog_);
  // Catmull–Rom cubic through the four nearest table points (ends: the end point repeated).
  const auto j = static_cast<std::size_t>(x);
  const double u = x - static_cast<double>(j);
  const double p0 = ratio_[j > 0 ? j - 1 : 0], p1 = ratio_[j], p2 = ratio_[j + 1], p3 = ratio_[std::min(j + 2, last)];
  const double ratio =
      p1 + 0.5 * u * (p2 - p0 + u * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + u * (3.0 * (p1 - p2) + p3 - p0)));
  return rc * ratio;
}

BinnedHeatHistory::BinnedHeatHistory(std::size_t bins_per_level) : per_level_(bins_per_level) {
  if (per_level_ < 2) throw std::invalid_argument("BinnedHeatHistory: bins_per_level must be at least 2");
  reset(0.0);
}

void BinnedHeatHistory::reset(double t0) {
  bins_.clear();
  boundaries_.assign(1, t0);
  open_.assign(slots_, 0.0);
}

std::size_t BinnedHeatHistory::add_slot() {
  open_.push_back(0.0);
  return slots_++;
}

void BinnedHeatHistory::close(double t) {
  if (!(t > boundaries_.back()))
    throw std::invalid_argument("BinnedHeatHistory::close: time " + std::to_string(t) +
                                " is not after the last boundary " + std::to_string(boundaries_.back()));
  Bin bin;
  bin.level = 0;
  bin.energy = std::move(open_);
  if (!pool_.empty()) {
    open_ = std::move(pool_.back());
    pool_.pop_back();
  } else {
    open_.clear();
  }
  open_.assign(slots_, 0.0);
  bins_.push_back(std::move(bin));
  boundaries_.push_back(t);
  merge_full_levels();
}

void BinnedHeatHistory::merge_full_levels() {
  // Levels are non-increasing from the oldest bin to the newest. For each level from 0 up: when it
  // holds more than per_level_ bins, its two oldest (adjacent in time) become one bin of the next
  // level, which lands at the newest end of that level's run.
  for (int level = 0;; ++level) {
    std::size_t first = bins_.size(), count = 0;
    for (std::size_t i = 0; i < bins_.size(); ++i) {
      if (bins_[i].level == level) {
        if (count == 0) first = i;
        ++count;
      }
    }
    if (count <= per_level_) {
      if (count == 0) return;
      continue;
    }
    Bin& older = bins_[first];
    Bin& newer = bins_[first + 1];
    if (newer.energy.size() > older.energy.size()) older.energy.resize(newer.energy.size(), 0.0);
    for (std::size_t s = 0; s < newer.energy.size(); ++s) older.energy[s] += newer.energy[s];
    older.level = level + 1;
    pool_.push_back(std::move(newer.energy));
    bins_.erase(bins_.begin() + static_cast<std::ptrdiff_t>(first) + 1);
    boundaries_.erase(boundaries_.begin() + static_cast<std::ptrdiff_t>(first) + 1);
  }
}

double BinnedHeatHistory::total_energy(std::size_t slot) const {
  double sum = slot < open_.size() ? open_[slot] : 0.0;
  for (std::size_t b = 0; b < bins_.size(); ++b) sum += energy(b, slot);
  return sum;
}

void BinnedHeatHistory::convolve(const std::vector<std::vector<double>>& responses,
                                 const std::vector<int>& group_of_slot, std::vector<double>& out) const {
  out.assign(slots_, 0.0);
  const std::size_t nb = bins_.size();
  for (const auto& r : responses)
    if (r.size() != nb + 1) throw std::invalid_argument("BinnedHeatHistory::convolve: one response per boundary");
  for (std::size_t b = 0; b < nb; ++b) {
    const double width = boundaries_[b + 1] - boundaries_[b];
    const auto& e = bins_[b].energy;
    const std::size_t n = std::min(e.size(), slots_);
    for (std::size_t s = 0; s < n; ++s) {
      if (e[s] == 0.0) continue;
      const auto& r = responses[static_cast<std::size_t>(group_of_slot[s])];
      out[s] += e[s] / width * (r[b] - r[b + 1]);  // constant flux E/w over the bin, superposed steps
    }
  }
}

BinnedHeatHistory::Flat BinnedHeatHistory::flatten() const {
  Flat f;
  f.boundaries = boundaries_;
  f.open = open_;
  f.levels.reserve(bins_.size());
  f.energy.assign(bins_.size() * slots_, 0.0);
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    f.levels.push_back(bins_[b].level);
    for (std::size_t s = 0; s < slots_; ++s) f.energy[b * slots_ + s] = energy(b, s);
  }
  return f;
}

void BinnedHeatHistory::restore(const Flat& f) {
  const std::size_t nb = f.levels.size();
  if (f.boundaries.size() != nb + 1)
    throw std::invalid_argument("interface heat history: " + std::to_string(f.boundaries.size()) +
                                " boundaries for " + std::to_string(nb) + " bins (expected bins + 1)");
  const std::size_t slots = f.open.size();
  if (f.energy.size() != nb * slots)
    throw std::invalid_argument("interface heat history: " + std::to_string(f.energy.size()) +
                                " energies for " + std::to_string(nb) + " bins of " + std::to_string(slots) +
                                " slots");
  for (std::size_t b = 0; b + 1 < f.boundaries.size(); ++b)
    if (!(f.boundaries[b + 1] > f.boundaries[b]))
      throw std::invalid_argument("interface heat history: boundaries not increasing");
  for (double e : f.energy)
    if (!std::isfinite(e)) throw std::invalid_argument("interface heat history: a non-finite energy");
  slots_ = slots;
  open_ = f.open;
  boundaries_ = f.boundaries;
  bins_.assign(nb, Bin{});
  for (std::size_t b = 0; b < nb; ++b) {
    bins_[b].level = f.levels[b];
    bins_[b].energy.assign(f.energy.begin() + static_cast<std::ptrdiff_t>(b * slots),
                           f.energy.begin() + static_cast<std::ptrdiff_t>((b + 1) * slots));
  }
}

}  // namespace frictherm::thermal
