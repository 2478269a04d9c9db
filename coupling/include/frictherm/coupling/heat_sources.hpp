#pragma once
// Heat sources besides friction (design §4, issue 5): plastic work with a Taylor–Quinney fraction,
// and the particle side of the Arrhenius reaction heat of the thermal module (reaction.hpp).
//
// * Plastic heating: a particle whose cumulative plastic work grew by Δw_p over a mechanics step
//   gives β_m Δw_p (β_m the Taylor–Quinney fraction of its material; docs/materials.md) to the grid
//   nodes with its shape weights, ΔW_i = Σ_p β Δw_p S_ip. Σ_i S_ip = 1, so the nodes receive exactly
//   Σ_p β Δw_p (to round-off).
// * Reaction progress λ_p lives on the particles (it moves with the material). At each assembly the
//   nodal reacting mass and progress are gathered, m_i = Σ_p m_p S_ip and
//   m_i (1 − λ_i) = Σ_p m_p S_ip (1 − λ_p) over the particles of reacting materials, so the nodal heat
//   of reaction is Q_i = q m_i. After integration the unreacted fraction goes back as a ratio,
//   (1 − λ_p) = (1 − λ_p,0) Σ_i S_ip R_i with R_i = (1 − λ_i(t)) / (1 − λ_i,0): λ_p stays in [0, 1]
//   and q Σ_p m_p (λ_p − λ_p,0) = Σ_i Q_i (λ_i(t) − λ_i,0) exactly (partition of unity), so the
//   particles carry the heat the nodes released.
#include <frictherm/coupling/heat_handoff.hpp>
#include <frictherm/coupling/thermal_assembly.hpp>
#include <frictherm/thermal/reaction.hpp>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace frictherm::coupling {

struct PlasticHeatingOptions {
  bool enabled = false;
  /// Taylor–Quinney fraction β by material id, in [0, 1] (0: the material's plastic work stays out).
  std::vector<double> taylor_quinney;
};

struct ReactionOptions {
  bool enabled = false;
  bool during_loading = true;           // false: the reaction starts with the thermal-only continuation
  thermal::ArrheniusKinetics kinetics;  // Z, Θ = E_a/R, q (J/kg)
  std::string kinetics_name;            // for the metadata ("hmx_rogers1975" or "explicit")
  std::vector<char> reacting;           // by material id: 1 if its particles react
  bool reacts(int material) const {
    return material >= 0 && static_cast<std::size_t>(material) < reacting.size() && reacting[static_cast<std::size_t>(material)];
  }
};

/// Plastic work → nodal heat, step by step.
template <int Dim>
class PlasticHeatSource {
 public:
  PlasticHeatSource() = default;
  /// Throws std::invalid_argument unless every β is in [0, 1].
  explicit PlasticHeatSource(PlasticHeatingOptions options);
  /// Remembers each particle's cumulative plastic work (the start of the books).
  void start(const mechanics::Particles<Dim>& particles);
  /// Adds Σ_p β Δw_p S_ip to `pending` for the plastic work done since the last call. Returns the
  /// heat added (the sum of the nodal shares, J); `plastic_work` gets Σ_p Δw_p over heated materials.
  double collect(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles,
                 mechanics::ShapeKind shape, HeatAccumulator& pending, double& plastic_work);
  const PlasticHeatingOptions& options() const { return opt_; }
  /// Checkpoints: each particle's plastic work at the last call.
  template <class V> void visit_state(V&& v) { v("plastic/last_work", last_); }

 private:
  PlasticHeatingOptions opt_;
  std::vector<double> last_;  // plastic work of each particle at the last call (J)
};

/// Σ_p v_p S_ip added to grid_values[i] (grid_values has one entry per grid node; v_p == 0 skipped).
template <int Dim>
void scatter_to_grid(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles,
                     mechanics::ShapeKind shape, const std::vector<double>& values, std::vector<double>& grid_values);

/// Nodal reaction state on the unknowns of `system`: reacting mass m_i (kg) and progress λ_i gathered
/// from the particles of reacting materials (see the header comment).
struct NodalReaction {
  Eigen::VectorXd reacting_mass;  // m_i on the unknowns (kg)
  Eigen::VectorXd progress;       // λ_i on the unknowns (0 where m_i = 0)
};

template <int Dim>
NodalReaction gather_reaction(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles,
                              mechanics::ShapeKind shape, const ReactionOptions& reaction,
                              const NodalThermalSystem& system, const std::vector<double>& particle_progress);

/// (1 − λ_p) = (1 − λ_p,0) Σ_i S_ip R_i for the particles of reacting materials, with
/// R_i = (1 − λ_i) / (1 − λ_i,0) on the unknowns (1 elsewhere, and where 1 − λ_i,0 = 0).
/// `progress0` are the particles' λ at the gather, `nodal0` the gathered λ_i,0, `nodal` the current λ_i.
template <int Dim>
void scatter_progress(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles,
                      mechanics::ShapeKind shape, const ReactionOptions& reaction, const NodalThermalSystem& system,
                      const Eigen::VectorXd& nodal0, const Eigen::VectorXd& nodal,
                      const std::vector<double>& progress0, std::vector<double>& progress);

extern template class PlasticHeatSource<2>;
extern template class PlasticHeatSource<3>;

}  // namespace frictherm::coupling
