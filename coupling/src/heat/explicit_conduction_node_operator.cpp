// The node-level conduction operator of the matrix-free sub-steps while the stencils are kept
// (explicit_conduction.hpp, use_node_operator; issue 35): K_ij = Σ_p V_p k_p G'_ip·G'_jp (Nairn et al.
// 2018 eq. 37 summed over the particles once), f_i = −Σ_{j≠i} K_ij (T_j − T_i).
#include "explicit_conduction_detail.hpp"

namespace frictherm::coupling {

using namespace explicit_detail;

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::assemble_node_operator(const NodalThermalSystem& sys, int threads) {
  const std::size_t n = sys.size();
  node_k_.assign(n * offsets, 0.0);
  node_col_.resize(n * offsets);
  for (std::size_t u = 0; u < n; ++u)
    std::fill(node_col_.begin() + static_cast<std::ptrdiff_t>(u * offsets),
              node_col_.begin() + static_cast<std::ptrdiff_t>((u + 1) * offsets), static_cast<int>(u));
  const mechanics::Stencil<Dim, Kernel>* stencils = window_stencils<Kernel>();
  listed_.clear();
  in_node_k_.assign(holds_heat_.size(), 0);
  for (std::size_t k = 0; k < holds_heat_.size(); ++k)
    if (holds_heat_[k] && conductance_[k] != 0.0) {
      listed_.push_back(k);
      in_node_k_[k] = 1;
    }
  node_force_.setZero(static_cast<Eigen::Index>(n));
  // Each thread adds only into the rows of its grid nodes, over the particles in order: every K_ij
  // gets the same terms in the same order on any number of threads.
  scatter_by_node_ranges<Expanded>(threads, static_cast<int>(sys.unknown.size()), listed_,
                                   [&](std::size_t k, const NodeRange& r, Expanded& e) {
                                     const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
                                     if (!r.meets(node_span(st, indexer_))) return;
                                     add_to_node_operator(st, conductance_[k], sys.unknown, 1.0, e, &r);
                                   });
  node_operator_ready_ = true;
}

template <int Dim>
void ExplicitConduction<Dim>::node_operator_force(const NodalThermalSystem& sys, const Eigen::VectorXd& T, int threads) {
  const auto n = static_cast<std::ptrdiff_t>(T.size());
  const double* t = T.data();
  const double* k_all = node_k_.data();
  const int* col_all = node_col_.data();
  const int* before = changed_before_.data();
  const int* grid_node = sys.grid_node.data();
  const int nodes = static_cast<int>(sys.unknown.size());
  const mechanics::IVec<Dim>& sd = indexer_.stride;  // sd[0] = 1: x fastest (for_each_unknown_whole)
  // Whether a node within ±2 along each axis changed (changed_before_, by runs of 5 along x; a run
  // clipped at the ends of the numbering, a run across a grid edge taking in more: never fewer).
  const auto reached = [&](int g) {
    const auto run = [&](int c) {
      const int lo = std::max(c - 2, 0), hi = std::min(c + 3, nodes);
      return lo < hi && before[hi] != before[lo];
    };
    if constexpr (Dim == 2) {
      for (int dy = -2; dy <= 2; ++dy)
        if (run(g + dy * sd[1])) return true;
    } else {
      for (int dz = -2; dz <= 2; ++dz)
        for (int dy = -2; dy <= 2; ++dy)
          if (run(g + dz * sd[2] + dy * sd[1])) return true;
    }
    return false;
  };
  double* f = node_force_.data();
  const auto row = [&](std::ptrdiff_t u) {
    if (!reached(grid_node[u])) return;  // f_i of the last sub-step stands: the same K row and T_j
    const double ti = t[u], quiet = kQuietSpread * std::fabs(ti);
    const double* k_row = k_all + u * offsets;
    const int* col = col_all + u * offsets;
    double sum = 0.0;
    for (int s = 0; s < offsets; ++s) {
      const double d = t[col[s]] - ti;
      // a pair at temperatures equal to round-off (relative to T_i) carries no flux
      sum += std::fabs(d) <= quiet ? 0.0 : k_row[s] * d;
    }
    f[u] = -sum;  // f_i = −(K T)_i = −Σ_{j≠i} K_ij (T_j − T_i)
  };
  if (threads <= 1) {
    for (std::ptrdiff_t u = 0; u < n; ++u) row(u);
  } else {
    mechanics::parallel_region(threads, [&] {
#pragma omp for schedule(static)
      for (std::ptrdiff_t u = 0; u < n; ++u) row(u);
    });
  }
}

#define FRICTHERM_INSTANTIATE_NODE_OPERATOR(D)                                                                     \
  template void ExplicitConduction<D>::node_operator_force(const NodalThermalSystem&, const Eigen::VectorXd&, int); \
  template void ExplicitConduction<D>::assemble_node_operator<mechanics::LinearKernel>(const NodalThermalSystem&, int); \
  template void ExplicitConduction<D>::assemble_node_operator<mechanics::UGIMPKernel>(const NodalThermalSystem&, int);  \
  template void ExplicitConduction<D>::assemble_node_operator<mechanics::QuadraticBSplineKernel>(                  \
      const NodalThermalSystem&, int);
FRICTHERM_INSTANTIATE_NODE_OPERATOR(2)
FRICTHERM_INSTANTIATE_NODE_OPERATOR(3)
#undef FRICTHERM_INSTANTIATE_NODE_OPERATOR

}  // namespace frictherm::coupling
