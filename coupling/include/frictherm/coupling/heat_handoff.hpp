#pragma once
// Energy-exact heat handoff from the mechanics to the thermal side (design §4, thermal-notes §5):
// the nodal frictional work ΔW_i of every mechanics step (J, by grid node; Nairn et al. 2018
// eqs. 27/34/36) is accumulated over a coupling window — energy, not rates — and at the window's
// end delivered as the constant source q_i = W_i / Δt_window over the window, so ∫ q_i dt = W_i.
// Heat on a grid node that is not a thermal unknown (no or negligible heat capacity there) is
// moved to its neighbouring unknowns, or to the nearest one, without loss.
#include <frictherm/coupling/thermal_assembly.hpp>

#include <Eigen/Core>

#include <cstddef>
#include <type_traits>
#include <vector>

namespace frictherm::coupling {

/// Nodal work accumulated over one window (J by grid node).
class HeatAccumulator {
 public:
  explicit HeatAccumulator(std::size_t grid_nodes = 0) : work_(grid_nodes, 0.0) {}
  /// Adds one step's nodal work. An empty vector means no work; otherwise it must have one
  /// finite entry per grid node (throws std::invalid_argument).
  void add(const std::vector<double>& nodal_work);
  /// Adds work to one grid node.
  void add(std::size_t node, double joules);
  /// Σ of the pending work (J).
  double total() const { return total_; }
  const std::vector<double>& work() const { return work_; }
  std::size_t node_count() const { return work_.size(); }
  /// Forgets the pending work (after it was delivered).
  void clear();
  /// Checkpoints (state_visit.hpp): the nodal work and its running sum (kept, not re-summed, so a
  /// restored window delivers bit-for-bit the same heat).
  template <class V> void visit_state(V&& v) {
    v("pending/work", work_);
    v("pending/total", total_);
    if constexpr (std::decay_t<V>::reading) {
      touched_.clear();
      is_touched_.assign(work_.size(), 0);
      for (std::size_t i = 0; i < work_.size(); ++i)
        if (work_[i] != 0.0) is_touched_[i] = 1, touched_.push_back(i);
    }
  }

 private:
  /// work_[node] += joules and the running sum; node marked as touched (is_touched_ sized).
  void accumulate(std::size_t node, double joules) {
    if (!is_touched_[node]) is_touched_[node] = 1, touched_.push_back(node);
    work_[node] += joules;
    total_ += joules;
  }
  std::vector<double> work_;
  std::vector<std::size_t> touched_;  // nodes with work, so clear() is cheap
  std::vector<unsigned char> is_touched_;
  double total_ = 0.0;
};

/// Heat on the unknowns of a system, from heat on grid nodes.
struct HeatDistribution {
  Eigen::VectorXd joules;  // on the unknowns (J)
  double total = 0.0;      // Σ of the grid-node heat handed in (J)
  double relocated = 0.0;  // part of it that sat on nodes that are not unknowns (J)
};

/// Heat on a node that is an unknown stays there. Heat on any other node goes to the unknowns
/// among its lattice neighbours (at most one node away in every direction) in proportion to their
/// M_i, or, when there is none, all to the nearest unknown (Euclidean distance between nodes).
/// Σ joules = Σ work to round-off.
template <int Dim>
HeatDistribution distribute_heat(const mechanics::Grid<Dim>& grid, const NodalThermalSystem& system,
                                 const std::vector<double>& work);

extern template HeatDistribution distribute_heat<2>(const mechanics::Grid<2>&, const NodalThermalSystem&,
                                                    const std::vector<double>&);
extern template HeatDistribution distribute_heat<3>(const mechanics::Grid<3>&, const NodalThermalSystem&,
                                                    const std::vector<double>&);

}  // namespace frictherm::coupling
