// The thermal-only continuation on the decomposed grid (DecomposedHeat::continue_thermal, issue 32):
// the serial Coupler::continue_thermal's intervals on the last window's problem, with the window's
// gather, assembly and map back (decomposed_heat.cpp, decomposed_sources.cpp).
#include <frictherm/coupling/decomposed_heat.hpp>

#include "distributed/decomposed_assembled.hpp"

#include <array>
#include <stdexcept>
#include <utility>
#include <vector>

namespace frictherm::coupling {

// As the serial reaction_starts: with a reaction the continuation assembles afresh (its Q_i, λ_i).
bool DecomposedHeat::continuation_regathers() const {
  return !last_assembled_ || !assembled_->assembled() || opt_.reaction.enabled;
}

void DecomposedHeat::continue_thermal(double time) {
  if (mpm3_) continue_on(*mpm3_, time);
  else continue_on(*mpm2_, time);
}

// Coupler::continue_thermal on the decomposed grid: no source, the mechanics frozen. The first interval
// takes a fresh integrator and, as the serial Coupler, the last window's problem and its end
// temperatures when that window was assembled; after a matrix-free window (or none) it gathers and
// assembles afresh (gather_window, the assembled path's numbering and K) and starts from the gathered
// T_i. Each interval integrates on that problem from where the last left off (the integrator keeps its
// history) and maps ΔT_i back to the particles (map_back, with the sub-grid relaxation).
template <int Dim>
void DecomposedHeat::continue_on(mechanics::DecomposedMpm<Dim>& mpm, double time) {
  if (pending_heat() != 0.0)
    throw std::logic_error("DecomposedHeat::continue_thermal: close the window with pending heat first");
  if (!(time > window_start_)) return;
  const MPI_Comm comm = mpm.communicator();
  bool gathered = false;  // this interval starts from the particles' temperatures (as the serial Coupler)
  if (!continuing_) {
    const bool regather = continuation_regathers();
    assembled_->restart_integrator();  // the continuation depends only on the end-of-loading state
    continuing_ = true;  // a reaction held back during loading is active from here (reaction_active)
    if (regather) {
      gathered = true;
      gather_window(mpm);
      number_unknowns(mpm);
      const std::array<int, 2 * Dim> box = mpm.ghosted_nodes();
      KeptEntries entries_of{Dim, {1, 1, 1}, &kept_first_, &kept_node_, &kept_G_, &conductance_};
      for (int d = 0; d < Dim; ++d) entries_of.box[static_cast<std::size_t>(d)] = box[2 * d + 1] - box[2 * d];
      assembled_->assemble(comm, *ids_, entries_of, M_, face_temperature_);
      books_.max_row_sum_residual = std::max(books_.max_row_sum_residual, assembled_->row_sum_residual());
      last_T_ = T0_;
      books_.exchanges += 4;  // M and Σ m C T, M back, the bounds, the ids
      if (reaction_active()) {
        reaction_gather(mpm);
        assembled_->set_reaction(*ids_, opt_.reaction.kinetics, reacting_mass_);
      }
    }
    // The interface reaction held back until the continuation (Coupler::continue_thermal).
    if (interface_enabled() && opt_.reaction.enabled && !interface_reaction_.started())
      interface_reaction_start(mpm, window_start_);
  }
  T0_ = last_T_;  // the interval's start: ΔT_i = T_i(t1) − T_i(t0)
  std::vector<double> Tn = last_T_;
  if (reaction_active()) {
    books_.reaction_heat_released += assembled_->integrate_reacting(*ids_, nullptr, Tn, nodal_progress_, window_start_, time);
    reaction_scatter(mpm);
  } else {
    assembled_->integrate(*ids_, nullptr, Tn, window_start_, time);
  }
  std::vector<double> T = mpm.particle_scalar(scalar_);
  double changes[2];
  map_back(mpm, Tn, time - window_start_, T, changes, gathered);
  mpm.set_particle_scalar(scalar_, T);
  last_T_ = std::move(Tn);
  MPI_Allreduce(MPI_IN_PLACE, changes, 2, MPI_DOUBLE, MPI_SUM, comm);
  books_.nodal_energy_change += changes[0];
  books_.particle_energy_change += changes[1];
  ++books_.continuation_intervals;
  ++books_.exchanges;  // ΔT_i to the ghosts
  time_ = window_start_ = time;
  window_steps_ = 0;
  interface_update(mpm);  // as the serial Coupler::continue_thermal
}

}  // namespace frictherm::coupling
