// Accumulating nodal work over a window and moving it onto the thermal unknowns without loss.
#include <frictherm/coupling/heat_handoff.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace frictherm::coupling {

void HeatAccumulator::add(const std::vector<double>& nodal_work) {
  if (nodal_work.empty()) return;
  if (nodal_work.size() != work_.size())
    throw std::invalid_argument("HeatAccumulator: " + std::to_string(nodal_work.size()) +
                                " nodal work values for a grid of " + std::to_string(work_.size()) + " nodes");
  // add(i, w) for every non-zero entry, in node order, with its checks hoisted (a step's pass over
  // the whole grid: most entries are zero).
  if (is_touched_.size() != work_.size()) is_touched_.assign(work_.size(), 0);
  for (std::size_t i = 0; i < nodal_work.size(); ++i) {
    const double joules = nodal_work[i];
    if (joules == 0.0) continue;
    if (!std::isfinite(joules)) throw std::invalid_argument("HeatAccumulator: non-finite work on node " + std::to_string(i));
    accumulate(i, joules);
  }
}

void HeatAccumulator::add(std::size_t node, double joules) {
  if (node >= work_.size())
    throw std::invalid_argument("HeatAccumulator: node " + std::to_string(node) + " outside the grid");
  if (!std::isfinite(joules))
    throw std::invalid_argument("HeatAccumulator: non-finite work on node " + std::to_string(node));
  if (is_touched_.size() != work_.size()) is_touched_.assign(work_.size(), 0);
  accumulate(node, joules);
}

void HeatAccumulator::clear() {
  for (std::size_t i : touched_) {
    work_[i] = 0.0;
    is_touched_[i] = 0;
  }
  touched_.clear();
  total_ = 0.0;
}

template <int Dim>
HeatDistribution distribute_heat(const mechanics::Grid<Dim>& grid, const NodalThermalSystem& sys,
                                 const std::vector<double>& work) {
  if (work.size() != grid.node_count() || sys.unknown.size() != grid.node_count())
    throw std::invalid_argument("distribute_heat: work, system and grid sizes differ");
  if (sys.size() == 0) throw std::invalid_argument("distribute_heat: the thermal system has no unknowns");
  HeatDistribution out;
  out.joules = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(sys.size()));
  const auto& npd = grid.nodes_per_dim();
  const auto& stride = grid.strides();
  constexpr int neighbours = Dim == 2 ? 9 : 27;
  for (std::size_t i = 0; i < work.size(); ++i) {
    const double w = work[i];
    if (w == 0.0) continue;
    out.total += w;
    const int u = sys.unknown[i];
    if (u >= 0) {
      out.joules[u] += w;
      continue;
    }
    out.relocated += w;
    // Lattice neighbours that are unknowns, weighted by their heat capacity.
    const mechanics::IVec<Dim> li = grid.node_lattice(static_cast<int>(i));
    int cand[neighbours];
    double weight[neighbours];
    int count = 0;
    double wsum = 0.0;
    for (int c = 0; c < neighbours; ++c) {
      int rem = c, j = 0;
      bool inside = true;
      for (int d = 0; d < Dim; ++d) {
        const int l = li[static_cast<std::size_t>(d)] + rem % 3 - 1 + mechanics::Grid<Dim>::ghost;
        rem /= 3;
        if (l < 0 || l >= npd[static_cast<std::size_t>(d)]) inside = false;
        j += l * stride[d];
      }
      if (!inside) continue;
      const int v = sys.unknown[static_cast<std::size_t>(j)];
      if (v < 0) continue;
      cand[count] = v;
      weight[count] = sys.mass[v];
      wsum += sys.mass[v];
      ++count;
    }
    if (count > 0) {
      // The last share takes the remainder, so the shares sum to w up to one rounding.
      double given = 0.0;
      for (int c = 0; c + 1 < count; ++c) {
        const double share = w * (weight[c] / wsum);
        out.joules[cand[c]] += share;
        given += share;
      }
      out.joules[cand[count - 1]] += w - given;
      continue;
    }
    // No unknown next to it: the nearest one takes it all.
    const mechanics::Vec<Dim> xi = grid.node_position(static_cast<int>(i));
    double best = std::numeric_limits<double>::infinity();
    Eigen::Index best_u = 0;
    for (std::size_t v = 0; v < sys.size(); ++v) {
      const double d2 = (grid.node_position(sys.grid_node[v]) - xi).squaredNorm();
      if (d2 < best) {
        best = d2;
        best_u = static_cast<Eigen::Index>(v);
      }
    }
    out.joules[best_u] += w;
  }
  return out;
}

template HeatDistribution distribute_heat<2>(const mechanics::Grid<2>&, const NodalThermalSystem&,
                                             const std::vector<double>&);
template HeatDistribution distribute_heat<3>(const mechanics::Grid<3>&, const NodalThermalSystem&,
                                             const std::vector<double>&);

}  // namespace frictherm::coupling
