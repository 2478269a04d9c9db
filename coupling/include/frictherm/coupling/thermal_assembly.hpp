#pragma once
// The nodal thermal system built from particles (Nairn et al. 2018 §2.11, eqs. 37–38; design §3–4):
//
//   M_i = Σ_p m_p C_v,p S_ip                      (J/K)         eq. 38
//   T_i = Σ_p m_p C_v,p T_p S_ip / M_i            (K)           eq. 38
//   K_ij = Σ_p V_p k_p G_ip · G_jp                (W/K)         conduction term of f_i^(cond), eq. 37
//
// V_p is the particle volume (in 2D area times thickness, so K is in W/K like M is in J/K).
// Only nodes with M_i > active_mass_fraction · max_j M_j become thermal unknowns (numbered
// compactly). A particle's gradient on a dropped node is lumped onto its kept nodes in
// proportion to S_ip (the dropped node's temperature is taken as the particle's interpolated one),
// so every particle still contributes V_p k_p |Σ_i G'_ip T_i|² (K stays symmetric PSD) and K·1 = 0.
// Nodal temperature changes go back incrementally, T_p += Σ_i S_ip ΔT_i (design §4), which
// conserves Σ_p m_p C_v,p T_p exactly: Σ_p m_p C_v,p ΔT_p = Σ_i M_i ΔT_i (partition of unity).
#include <frictherm/coupling/fixed_temperature.hpp>
#include <frictherm/mechanics/grid.hpp>
#include <frictherm/mechanics/particles.hpp>
#include <frictherm/mechanics/shape_functions.hpp>
#include <frictherm/thermal/problem.hpp>

#include <Eigen/Core>

#include <cstddef>
#include <utility>
#include <vector>

namespace frictherm::coupling {

/// Thermal properties of one material. A material without them (`conducts == false`, e.g. a rigid
/// driver) holds no heat: its particles are left out of M and K and keep their temperature.
struct ThermalProperties {
  bool conducts = false;
  double heat_capacity = 0.0;  // C_v (J/(kg K)), > 0 when conducts
  double conductivity = 0.0;   // k (W/(m K)), >= 0
};

struct AssemblyOptions {
  /// Nodes with M_i <= active_mass_fraction · max_j M_j are not thermal unknowns.
  double active_mass_fraction = 1e-9;
};

/// M, T and K on the thermal unknowns, and the maps between unknowns and grid nodes.
struct NodalThermalSystem {
  std::vector<int> grid_node;      // unknown -> grid node index
  std::vector<int> unknown;        // grid node -> unknown, -1 if the node is not one (size node_count)
  std::vector<double> grid_mass;   // M_i on every grid node, kept or not (J/K)
  Eigen::VectorXd mass;            // M on the unknowns (J/K)
  Eigen::VectorXd temperature;     // T from eq. 38 on the unknowns (K)
  thermal::SparseMatrix conductance;  // K on the unknowns (W/K), symmetric, zero row sums
  double particle_heat_capacity = 0.0;  // Σ_p m_p C_v,p (J/K)
  double dropped_mass = 0.0;            // Σ M_i over nodes that are not unknowns (J/K)
  double max_mass = 0.0;                // max_i M_i (J/K)

  std::size_t size() const { return grid_node.size(); }
  /// Exchanges the contents with `other` (Eigen 3.4's SparseMatrix has no move: assigning a returned
  /// system would copy K).
  void swap(NodalThermalSystem& other) noexcept {
    grid_node.swap(other.grid_node), unknown.swap(other.unknown), grid_mass.swap(other.grid_mass);
    mass.swap(other.mass), temperature.swap(other.temperature), conductance.swap(other.conductance);
    std::swap(particle_heat_capacity, other.particle_heat_capacity), std::swap(dropped_mass, other.dropped_mass);
    std::swap(max_mass, other.max_mass);
  }
  /// From grid_mass and Σ_p m_p C_v,p T_p S_ip per node (mct): the unknowns (nodes carrying more than
  /// active_mass_fraction of the largest nodal heat capacity), their M and their T (eq. 38); sets
  /// max_mass and dropped_mass.
  void select_unknowns(const std::vector<double>& mct, double active_mass_fraction);
  /// |Σ_i M_i(all nodes) − Σ_p m_p C_v,p| / Σ_p m_p C_v,p: partition of unity, round-off only.
  double mass_residual() const;
  /// max_i |(K·1)_i| / max_i K_ii: zero row sums, round-off only (0 without conduction).
  double row_sum_residual() const;  // row_sum_extremes(conductance, 0).residual()
  /// Σ_i M_i T_i over the unknowns (J).
  double energy(const Eigen::VectorXd& nodal_temperature) const;
};

/// The zero-row-sum check of K (K·1 = 0) on owned rows `rows` (global columns; row i's diagonal in
/// column first + i): the largest |Σ_j K_ij| and the largest |K_ii| over the rows. A decomposed run
/// reduces both over ranks (MPI_MAX) before residual(); a serial system is all rows, first 0.
struct RowSumExtremes {
  double sum = 0.0, diagonal = 0.0;
  double residual() const { return diagonal > 0.0 ? sum / diagonal : 0.0; }
};
RowSumExtremes row_sum_extremes(const thermal::SparseMatrix& rows, Eigen::Index first);

/// The thermal properties of material `id`; throws std::invalid_argument when it has none.
const ThermalProperties& thermal_properties_of(const std::vector<ThermalProperties>& materials, int id);

/// Builds the system from the current particle state. `materials` is indexed by material id.
/// `stencils`: the MPM step's stencils at the current positions (mechanics::Simulation::
/// current_stencils), read instead of evaluating them again (same numbers); empty: evaluated here.
/// Throws std::invalid_argument if a material id has no entry, or if no node carries heat capacity
/// (no particle of a conducting material).
template <int Dim>
NodalThermalSystem assemble_thermal(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles,
                                    mechanics::ShapeKind shape, const std::vector<ThermalProperties>& materials,
                                    const AssemblyOptions& options = {},
                                    const mechanics::StencilView<Dim>& stencils = {});

/// T_p += Σ_i S_ip ΔT_i for the particles of conducting materials (design §4); `delta` is on the
/// unknowns of `system`, which must have been assembled from the same particle positions.
///
/// Optional sub-grid relaxation (`relaxation` β in [0, 1], `end` the nodal temperatures after the
/// window): T_p ← (1 − β) (T_p + Σ_i S_ip ΔT_i) + β Σ_i S_ip T_i,end / Σ_i S_ip, a FLIP/PIC blend that
/// damps particle-scale structure the grid cannot see (it never decays with β = 0). A uniform β keeps
/// Σ_p m_p C_v,p T_p exact wherever every node of a particle is an unknown. `stencils` as for
/// assemble_thermal. `held`: held unknowns of a window that started from the gathered temperatures;
/// they pull their particles towards the face (FacePull, fixed_temperature.hpp). Returns the heat the
/// pull gave the particles (J; 0 without held unknowns).
template <int Dim>
double add_nodal_change_to_particles(const mechanics::Grid<Dim>& grid, mechanics::Particles<Dim>& particles,
                                   mechanics::ShapeKind shape, const std::vector<ThermalProperties>& materials,
                                   const NodalThermalSystem& system, const Eigen::VectorXd& delta,
                                   double relaxation = 0.0, const Eigen::VectorXd* end = nullptr,
                                   const mechanics::StencilView<Dim>& stencils = {},
                                   const std::vector<typename FacePull<Dim>::Held>* held = nullptr);

/// Σ_p m_p C_v,p T_p over the particles of conducting materials (J).
template <int Dim>
double particle_thermal_energy(const mechanics::Particles<Dim>& particles,
                               const std::vector<ThermalProperties>& materials);

extern template NodalThermalSystem assemble_thermal<2>(const mechanics::Grid<2>&, const mechanics::Particles<2>&,
                                                       mechanics::ShapeKind, const std::vector<ThermalProperties>&,
                                                       const AssemblyOptions&, const mechanics::StencilView<2>&);
extern template NodalThermalSystem assemble_thermal<3>(const mechanics::Grid<3>&, const mechanics::Particles<3>&,
                                                       mechanics::ShapeKind, const std::vector<ThermalProperties>&,
                                                       const AssemblyOptions&, const mechanics::StencilView<3>&);
extern template double add_nodal_change_to_particles<2>(const mechanics::Grid<2>&, mechanics::Particles<2>&,
                                                      mechanics::ShapeKind, const std::vector<ThermalProperties>&,
                                                      const NodalThermalSystem&, const Eigen::VectorXd&, double,
                                                      const Eigen::VectorXd*, const mechanics::StencilView<2>&,
                                                      const std::vector<FacePull<2>::Held>*);
extern template double add_nodal_change_to_particles<3>(const mechanics::Grid<3>&, mechanics::Particles<3>&,
                                                      mechanics::ShapeKind, const std::vector<ThermalProperties>&,
                                                      const NodalThermalSystem&, const Eigen::VectorXd&, double,
                                                      const Eigen::VectorXd*, const mechanics::StencilView<3>&,
                                                      const std::vector<FacePull<3>::Held>*);
extern template double particle_thermal_energy<2>(const mechanics::Particles<2>&,
                                                  const std::vector<ThermalProperties>&);
extern template double particle_thermal_energy<3>(const mechanics::Particles<3>&,
                                                  const std::vector<ThermalProperties>&);

}  // namespace frictherm::coupling
