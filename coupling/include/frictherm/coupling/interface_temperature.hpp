#pragma once
// The sub-cell interface temperature of rubbing contacts (design §7, issue 31; the model and its
// history: thermal/interface_heating.hpp).
//
// Every mechanics step, each grid node that receives frictional heat W_i adds W_i / A_i to its flux
// history (A_i = h^{Dim−1}, times the thickness in 2D: the contact area eq. 11 gives a node along an
// interface). After each coupling window the node's interface temperature is
//
//     T_int,i = T_i + Σ_bins (flux history ⊛ R_x),     R_x = two half-spaces − what the lumped grid resolves,
//
// with the two half-spaces the node's two heaviest materials (one material: the same on both sides),
// T_i the node's grid temperature at the end of the window. A particle's interface temperature is
// T_p plus the largest correction among the nodes its shape functions reach (the hottest interface it
// touches). The correction reconstructs the surface value of heat the grid already holds: it adds no
// energy and takes none (the energy books are those of the grid).
#include <frictherm/coupling/state_visit.hpp>
#include <frictherm/coupling/thermal_assembly.hpp>
#include <frictherm/thermal/interface_heating.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <map>
#include <cstddef>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace frictherm::coupling {

struct InterfaceTemperatureOptions {
  bool enabled = false;
  /// Bins of each width in the flux history (interface_heating.hpp): the convolution's error falls
  /// as 1/bins_per_level², its cost grows as bins_per_level.
  int bins_per_level = 8;
  /// Hot-spot size ℓ (m): when > 0, the interface temperature a node reports (and particles, hot
  /// spots and the interface Arrhenius verdict read) is that of a patch of the interface of diameter
  /// ℓ around it: the heat of the heated nodes within ℓ/2 spread over the patch's area (a length ℓ in
  /// 2D, π ℓ²/4 in 3D) on their mean grid temperature; a node at distance d counts with the share of
  /// its cell inside the patch, clamp((ℓ/2 − d)/h + 1/2, 0, 1), so that a uniform flux on a straight
  /// interface gives the node's own value. The patch is at least two cells across
  /// (ℓ_eff = max(ℓ, 2h)). 0: each node's own value.
  double patch_length = 0.0;
};

template <int Dim>
class InterfaceTemperature {
 public:
  /// Per-material conductivity and volumetric heat capacity from the particles (ρ = Σ m / Σ V).
  void start(const mechanics::Grid<Dim>& grid, double thickness, const mechanics::Particles<Dim>& particles,
             const std::vector<ThermalProperties>& materials, const InterfaceTemperatureOptions& options,
             double time);
  /// start() with the per-material sums Σ m_p and Σ V_p given (a decomposed run reduces them over
  /// ranks); the particles' interface temperatures are left to the caller (T_p until the first update).
  void start_sides(const mechanics::Grid<Dim>& grid, double thickness, const std::vector<double>& mass,
                   const std::vector<double>& volume, const std::vector<ThermalProperties>& materials,
                   const InterfaceTemperatureOptions& options, double time);
  bool enabled() const { return enabled_; }
  /// One mechanics step's frictional heat (J by grid node), ending at `time`.
  void add_step(const std::vector<double>& nodal_work, double time);
  /// add_step's two halves for a caller holding some nodes only (a rank's owned nodes): the heat W
  /// (J) of grid node `node` in this step (nothing unless W > 0), then the step's end.
  void add_node_heat(int node, double w);
  void end_step(double time);

  // update()'s node-side pieces, for a caller that sums over its particles itself (a decomposed run:
  // the rows summed over ranks at the nodes' owners).
  /// Materials whose particles enter the passes (conducting, with a heat capacity).
  bool conducting(std::size_t m) const {
    return m < sides_.size() && sides_[m].volumetric_heat_capacity > 0.0 && sides_[m].conductivity > 0.0;
  }
  /// Values per row of pass 1: Σ S m per material, then Σ S m c and Σ S² m c.
  std::size_t row_size() const { return sides_.size() + 2; }
  /// Pass 1's term of a particle of (conducting) material m with mass `mass` and weight S > 0.
  void add_to_row(double* row, std::size_t m, double mass, double w) const {
    const std::size_t nm = sides_.size();
    const double mc = mass * heat_capacity_[m];
    row[m] += w * mass;
    row[nm] += w * mc;
    row[nm + 1] += w * w * mc;
  }
  /// From pass 1's rows (slots × row_size(), slot order of nodes()) and each slot's grid temperature
  /// T_i at the end of the window (NaN: not a thermal unknown now): the corrections, the nodes'
  /// interface temperatures and the maxima at `time`; with patch_length > 0 also the patches of this
  /// model's own heated nodes, unless `own_patches` is false (a decomposed run, whose patches reach
  /// nodes another rank owns: update_patches_from forms them once from the gathered nodes).
  void update_slots(const std::vector<double>& rows, const std::vector<double>& grid_temperature, double time,
                    bool own_patches = true);
  /// The correction a particle reads per slot after update_slots (the patch's when patch_length > 0).
  const std::vector<double>& slot_correction() const { return patch_area_ > 0.0 ? patch_correction_ : node_correction_; }
  /// After a window or continuation interval ending at the last add_step (or later, `time`):
  /// interface temperatures of the heated nodes and of the particles.
  void update(const mechanics::Particles<Dim>& particles, mechanics::ShapeKind shape,
              const mechanics::StencilView<Dim>& stencils, const NodalThermalSystem& system,
              const Eigen::VectorXd& nodal_temperature, double time);

  /// T_int,p of every particle (T_p where no heated node reaches it); empty before the first update.
  const std::vector<double>& particle_temperature() const { return particle_temperature_; }
  /// The heated nodes (grid indices), their corrections and interface temperatures at the last update.
  const std::vector<int>& nodes() const { return nodes_; }
  const std::vector<double>& node_correction() const { return node_correction_; }
  const std::vector<double>& node_temperature() const { return node_temperature_; }
  /// The hottest interface temperature at the last update: of a patch when patch_length > 0, else of
  /// a node (−∞ before any heat).
  double max_temperature() const { return max_temperature_; }
  /// The hottest single node's interface temperature at the last update (−∞ before any heat).
  double max_node_temperature() const { return max_node_temperature_; }
  /// Patch interface temperatures of the heated nodes (empty unless patch_length > 0).
  const std::vector<double>& patch_temperature() const { return patch_temperature_; }
  /// Whether the reported values are patches (patch_length > 0).
  bool patches() const { return patch_area_ > 0.0; }
  /// The patches of this model's heated nodes from the heated nodes of the whole run (grid indices,
  /// their node_correction() and node_temperature(); every rank's in a decomposed run, where a patch
  /// reaches nodes another rank owns): the sums update_slots makes from this model's own nodes, in the
  /// same order, so a rank's patches equal the serial run's. Sets max_temperature() to this model's
  /// hottest patch.
  void update_patches_from(const std::vector<int>& nodes, const std::vector<double>& correction,
                           const std::vector<double>& temperature);
  /// Σ over nodes of the heat per area times the area handed to the history (J): equals the
  /// frictional heat received (the books check it).
  double heat_recorded() const { return heat_recorded_; }

  template <class V> void visit_state(V&& v);

 private:
  std::optional<mechanics::Grid<Dim>> grid_;
  std::vector<thermal::HalfSpace> sides_;  // per material: k and ρ c (k = 0 for non-conducting)
  std::vector<double> heat_capacity_;      // per material: c (J/(kg K)), 0 for non-conducting
  /// R_x tables by (material a ≤ b, f in per cent), built on first use.
  std::map<std::array<int, 3>, thermal::SubcellCorrection> corrections_;
  const thermal::SubcellCorrection& correction(const std::array<int, 3>& key);
  double h_ = 0.0, area_ = 0.0;
  double patch_area_ = 0.0;                    // the patch's interface area (× thickness in 2D), 0: off
  std::vector<mechanics::IVec<Dim>> patch_offsets_;  // lattice offsets within the patch's radius
  std::vector<double> patch_weights_;                 // their weights: the share of the node inside
  /// Patch values of every slot from the heated nodes' corrections and interface temperatures,
  /// `index(grid node)` giving a node's entry in them (−1: not heated) (patch_length > 0).
  template <class Index>
  void update_patches(const Index& index, const std::vector<double>& correction, const std::vector<double>& temperature);
  std::vector<int> patch_index_;  // update_patches_from: grid node → entry of its arguments, −1 elsewhere
  bool enabled_ = false;
  thermal::BinnedHeatHistory history_{8};
  std::vector<int> slot_of_node_;  // grid node → slot, −1 for never heated
  std::vector<int> nodes_;         // slot → grid node
  std::vector<double> node_correction_, node_temperature_, particle_temperature_;
  std::vector<double> patch_correction_, patch_temperature_;
  std::vector<double> slot_material_mass_;  // slots × materials, scratch of update
  double max_temperature_ = -std::numeric_limits<double>::infinity();
  double max_node_temperature_ = -std::numeric_limits<double>::infinity();
  double heat_recorded_ = 0.0;
};

template <int Dim>
template <class V>
void InterfaceTemperature<Dim>::visit_state(V&& v) {
  constexpr bool reading = std::decay_t<V>::reading;
  thermal::BinnedHeatHistory::Flat f;
  if constexpr (!reading) f = history_.flatten();
  v("interface/boundaries", f.boundaries);
  v("interface/levels", f.levels);
  v("interface/energy", f.energy);
  v("interface/open", f.open);
  v("interface/nodes", nodes_);
  v("interface/heat_recorded", heat_recorded_);
  if constexpr (reading) {
    if (f.boundaries.empty()) return;  // a checkpoint written without the model: it starts now
    history_.restore(f);
    if (nodes_.size() != history_.slot_count())
      throw std::invalid_argument("checkpoint: interface/nodes has " + std::to_string(nodes_.size()) +
                                  " entries for " + std::to_string(history_.slot_count()) + " history slots");
    std::fill(slot_of_node_.begin(), slot_of_node_.end(), -1);
    for (std::size_t s = 0; s < nodes_.size(); ++s) {
      const int node = nodes_[s];
      if (node < 0 || static_cast<std::size_t>(node) >= slot_of_node_.size())
        throw std::invalid_argument("checkpoint: interface/nodes names grid node " + std::to_string(node) +
                                    " outside the grid");
      slot_of_node_[static_cast<std::size_t>(node)] = static_cast<int>(s);
    }
  }
}

extern template class InterfaceTemperature<2>;
extern template class InterfaceTemperature<3>;

}  // namespace frictherm::coupling
