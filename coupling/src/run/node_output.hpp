#pragma once
// The thermal grid's nodes of a snapshot (/nodes/<number>, RUN_nodes.xdmf "thermal_nodes"), written
// once for the serial run (runner_thermal.cpp: the Coupler's unknowns) and the decomposed run
// (distributed_run/decomposed_run_output.cpp: each rank's owned unknowns into its rank file, issue 32).
#include <frictherm/mechanics/grid.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frictherm::coupling::detail {

/// The nodes `grid_node` (grid node numbers of the thermal unknowns) with their temperatures T_i (K)
/// and heat capacities M_i = Σ_p m_p C_v,p S_ip (J/K, Nairn et al. 2018 eq. 38) as node fields
/// position (m), temperature, heat_capacity and lattice (the grid node's integer coordinates). `Out`
/// has node_field(name, const double*, n, components) and node_field(name, const std::int32_t*, n,
/// components) (H5Output, or a decomposed rank's collector).
template <int Dim, class Out>
void write_node_fields(Out& out, const mechanics::Grid<Dim>& grid, const std::vector<int>& grid_node,
                       const double* temperature, const double* heat_capacity) {
  const std::size_t n = grid_node.size();
  std::vector<double> x(n * Dim);
  std::vector<std::int32_t> lattice(n * Dim);
  for (std::size_t k = 0; k < n; ++k) {
    const mechanics::Vec<Dim> p = grid.node_position(grid_node[k]);
    const mechanics::IVec<Dim> i = grid.node_lattice(grid_node[k]);
    for (int d = 0; d < Dim; ++d) x[k * Dim + d] = p[d], lattice[k * Dim + d] = static_cast<std::int32_t>(i[d]);
  }
  out.node_field("position", x.data(), n, Dim);
  out.node_field("temperature", temperature, n, 1);
  out.node_field("heat_capacity", heat_capacity, n, 1);
  out.node_field("lattice", lattice.data(), n, Dim);
}

}  // namespace frictherm::coupling::detail
