// Plastic heating and the particle side of the reaction progress (heat_sources.hpp).
#include <frictherm/coupling/heat_sources.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace frictherm::coupling {

namespace {

/// Calls f(node, S_ip) for the non-zero weights of particle k.
template <int Dim, class Kernel, class F>
void for_each_weight(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p, std::size_t k, F&& f) {
  mechanics::Stencil<Dim, Kernel> st;
  st.evaluate(grid, p.position[k], p.half_size[k]);
  st.for_each(grid, [&](int i, double S, const mechanics::Vec<Dim>&) {
    if (S != 0.0) f(static_cast<std::size_t>(i), S);
  });
}

}  // namespace

template <int Dim>
PlasticHeatSource<Dim>::PlasticHeatSource(PlasticHeatingOptions options) : opt_(std::move(options)) {
  for (std::size_t m = 0; m < opt_.taylor_quinney.size(); ++m) {
    const double b = opt_.taylor_quinney[m];
    if (!(b >= 0.0 && b <= 1.0))
      throw std::invalid_argument("plastic heating: Taylor-Quinney fraction of material " + std::to_string(m) +
                                  " must be in [0, 1], got " + std::to_string(b));
  }
}

template <int Dim>
void PlasticHeatSource<Dim>::start(const mechanics::Particles<Dim>& p) {
  last_ = p.plastic_work;
}

template <int Dim>
double PlasticHeatSource<Dim>::collect(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p,
                                       mechanics::ShapeKind shape, HeatAccumulator& pending, double& plastic_work) {
  if (last_.size() != p.size()) last_.assign(p.size(), 0.0);
  const double before = pending.total();
  double work = 0.0;
  mechanics::dispatch_shape(shape, [&](auto kernel) {
    using Kernel = decltype(kernel);
    for (std::size_t k = 0; k < p.size(); ++k) {
      const double dw = p.plastic_work[k] - last_[k];
      if (dw == 0.0) continue;
      last_[k] = p.plastic_work[k];
      const auto m = static_cast<std::size_t>(p.material[k]);
      const double beta = m < opt_.taylor_quinney.size() ? opt_.taylor_quinney[m] : 0.0;
      if (beta == 0.0) continue;
      work += dw;
      const double heat = beta * dw;  // Taylor–Quinney: the stored part (1 − β) stays out
      for_each_weight<Dim, Kernel>(grid, p, k, [&](std::size_t i, double S) { pending.add(i, heat * S); });
    }
  });
  plastic_work = work;
  return pending.total() - before;
}

template <int Dim>
void scatter_to_grid(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p, mechanics::ShapeKind shape,
                     const std::vector<double>& values, std::vector<double>& out) {
  if (values.size() != p.size() || out.size() != grid.node_count())
    throw std::invalid_argument("scatter_to_grid: sizes of values, particles and grid differ");
  mechanics::dispatch_shape(shape, [&](auto kernel) {
    for (std::size_t k = 0; k < p.size(); ++k) {
      const double v = values[k];
      if (v == 0.0) continue;
      for_each_weight<Dim, decltype(kernel)>(grid, p, k, [&](std::size_t i, double S) { out[i] += v * S; });
    }
  });
}

template <int Dim>
NodalReaction gather_reaction(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p,
                              mechanics::ShapeKind shape, const ReactionOptions& rx, const NodalThermalSystem& sys,
                              const std::vector<double>& lambda) {
  if (lambda.size() != p.size()) throw std::invalid_argument("gather_reaction: one progress value per particle needed");
  std::vector<double> mass(p.size(), 0.0), unreacted(p.size(), 0.0);
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!rx.reacts(p.material[k])) continue;
    mass[k] = p.mass[k];
    unreacted[k] = p.mass[k] * (1.0 - lambda[k]);
  }
  std::vector<double> gm(grid.node_count(), 0.0), gu(grid.node_count(), 0.0);
  scatter_to_grid(grid, p, shape, mass, gm);
  scatter_to_grid(grid, p, shape, unreacted, gu);
  NodalReaction out;
  const auto n = static_cast<Eigen::Index>(sys.size());
  out.reacting_mass = Eigen::VectorXd::Zero(n);
  out.progress = Eigen::VectorXd::Zero(n);
  for (Eigen::Index u = 0; u < n; ++u) {
    const auto i = static_cast<std::size_t>(sys.grid_node[static_cast<std::size_t>(u)]);
    out.reacting_mass[u] = gm[i];
    if (gm[i] > 0.0) out.progress[u] = std::clamp(1.0 - gu[i] / gm[i], 0.0, 1.0);
  }
  return out;
}

template <int Dim>
void scatter_progress(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p, mechanics::ShapeKind shape,
                      const ReactionOptions& rx, const NodalThermalSystem& sys, const Eigen::VectorXd& nodal0,
                      const Eigen::VectorXd& nodal, const std::vector<double>& progress0,
                      std::vector<double>& progress) {
  const auto n = static_cast<Eigen::Index>(sys.size());
  if (nodal0.size() != n || nodal.size() != n || progress0.size() != p.size())
    throw std::invalid_argument("scatter_progress: sizes of the nodal or particle progress differ from the system");
  // R on every grid node: 1 except on unknowns whose unreacted part changed.
  std::vector<double> ratio(grid.node_count(), 1.0);
  for (Eigen::Index u = 0; u < n; ++u) {
    const double left0 = 1.0 - nodal0[u];
    if (!(left0 > 0.0)) continue;
    ratio[static_cast<std::size_t>(sys.grid_node[static_cast<std::size_t>(u)])] =
        std::clamp((1.0 - nodal[u]) / left0, 0.0, 1.0);
  }
  progress.resize(p.size());
  mechanics::dispatch_shape(shape, [&](auto kernel) {
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (!rx.reacts(p.material[k])) continue;
      double r = 0.0;
      for_each_weight<Dim, decltype(kernel)>(grid, p, k, [&](std::size_t i, double S) { r += S * ratio[i]; });
      progress[k] = std::clamp(1.0 - (1.0 - progress0[k]) * r, 0.0, 1.0);
    }
  });
}

template class PlasticHeatSource<2>;
template class PlasticHeatSource<3>;

#define FRICTHERM_INSTANTIATE_HEAT_SOURCES(D)                                                                      \
  template void scatter_to_grid<D>(const mechanics::Grid<D>&, const mechanics::Particles<D>&, mechanics::ShapeKind, \
                                   const std::vector<double>&, std::vector<double>&);                               \
  template NodalReaction gather_reaction<D>(const mechanics::Grid<D>&, const mechanics::Particles<D>&,              \
                                            mechanics::ShapeKind, const ReactionOptions&, const NodalThermalSystem&, \
                                            const std::vector<double>&);                                            \
  template void scatter_progress<D>(const mechanics::Grid<D>&, const mechanics::Particles<D>&, mechanics::ShapeKind, \
                                    const ReactionOptions&, const NodalThermalSystem&, const Eigen::VectorXd&,      \
                                    const Eigen::VectorXd&, const std::vector<double>&, std::vector<double>&);
FRICTHERM_INSTANTIATE_HEAT_SOURCES(2)
FRICTHERM_INSTANTIATE_HEAT_SOURCES(3)
#undef FRICTHERM_INSTANTIATE_HEAT_SOURCES

}  // namespace frictherm::coupling
