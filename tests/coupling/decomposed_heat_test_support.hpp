#pragma once
// Shared by the decomposed heat tests (test_heat_distributed.cpp in 2D, test_heat_distributed_3d.cpp):
// the serial Coupler they compare with, the temperatures compared by particle id, and the heated
// sliding block run side by side with the serial one, with the checks both make of it.
// No ASSERT here: a rank that returned early from a collective call would leave the others waiting.
#include "frictherm/coupling/coupler.hpp"
#include "frictherm/coupling/decomposed_heat.hpp"
#include "frictherm/mechanics/distributed.hpp"
#include "frictherm/mechanics/simulation.hpp"

#include "../decomposed_test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace frictherm::test {

/// The serial reference's coupler: a window every step, forward_euler (taken matrix-free for windows
/// of ≤ 64 stable sub-steps), the gather every window (reuse_distance 0).
inline coupling::CouplerOptions serial_coupler_options(const std::vector<coupling::ThermalProperties>& materials) {
  coupling::CouplerOptions opt;
  opt.materials = materials;
  opt.integrator = "forward_euler";
  opt.window.kind = coupling::WindowPolicy::Kind::every_step;
  opt.reuse_distance = 0.0;
  return opt;
}

/// The decomposed run's heat: the materials' thermal properties, the frictional work of `order`.
inline coupling::DecomposedHeatOptions decomposed_heat_options(
    const std::vector<coupling::ThermalProperties>& materials,
    mechanics::HeatingOrder order = mechanics::HeatingOrder::second) {
  coupling::DecomposedHeatOptions ho;
  ho.materials = materials;
  ho.order = order;
  return ho;
}

/// Largest |T_p − T_p(serial)| over the gathered particles `a` (temperature their first scalar);
/// `same` is cleared unless a holds every serial particle, by id, each with `scalars` scalars.
template <class Particle, int Dim>
double temperature_difference(const std::vector<Particle>& a, const mechanics::Particles<Dim>& sp, std::size_t scalars,
                              bool& same) {
  double d = 0.0;
  same = same && a.size() == sp.size();
  for (std::size_t k = 0; same && k < a.size(); ++k) {
    same = a[k].id == static_cast<std::int64_t>(k) && a[k].scalars.size() == scalars;
    if (same) d = std::max(d, std::fabs(a[k].scalars[0] - sp.temperature[k]));
  }
  return d;
}

/// A heated sliding block run side by side: the largest differences over the steps and the end state.
template <int Dim>
struct HeatedBlockRun {
  double dhist = 0.0;  // |block mean x-velocity − serial| (m/s), largest over the steps
  double dw = 0.0;     // |cumulative second-order frictional work − serial| (J), largest over the steps
  double dT = 0.0;     // |T_p − T_p(serial)| (K), largest over the compared steps
  bool same = true;    // every particle kept, by id, with its scalars
  double time = 0.0;   // s
  double ws = 0.0;     // the serial run's cumulative second-order work at the end (J)
  double rise = 0.0;   // the serial run's largest temperature rise above T0 (K)
  double v_end = 0.0;  // the serial block's mean x-velocity at the end (m/s)
  std::vector<typename mechanics::DecomposedMpm<Dim>::Particle> last;  // gathered after the last step
};

/// `steps` steps of dt of the serial Simulation + Coupler and of the decomposed run + DecomposedHeat,
/// (second-order frictional work handed to the coupler); temperatures compared every `every` steps,
/// each decomposed particle carrying `scalars` scalars; `block` the block's material; T0 (K) the
/// serial particles' starting temperature.
template <int Dim>
HeatedBlockRun<Dim> run_heated_block(mechanics::Simulation<Dim>& serial, coupling::Coupler<Dim>& coupler,
                                     mechanics::DecomposedMpm<Dim>& split, coupling::DecomposedHeat& heat, double dt,
                                     int steps, int every, int block, std::size_t scalars, double T0) {
  HeatedBlockRun<Dim> r;
  mechanics::Particles<Dim>& sp = serial.particles();
  for (int s = 1; s <= steps; ++s) {
    serial.step(dt);
    r.time += dt;
    coupler.after_step(sp, serial.frictional_work(mechanics::HeatingOrder::second), r.time);
    split.step(dt);
    heat.after_step(dt);
    r.ws = serial.cumulative_frictional_work(mechanics::HeatingOrder::second);
    r.dw = std::max(r.dw, std::fabs(split.cumulative_frictional_work(mechanics::HeatingOrder::second) - r.ws));
    r.last = split.gather();
    r.dhist = std::max(r.dhist, std::fabs(mean_velocity_x(r.last, block) - mean_velocity_x(sp, block)));
    if (s % every == 0) r.dT = std::max(r.dT, temperature_difference(r.last, sp, scalars, r.same));
  }
  for (double T : sp.temperature) r.rise = std::max(r.rise, T - T0);
  r.v_end = mean_velocity_x(sp, block);
  return r;
}

/// The checks of both heated blocks against the serial run (the 1e-9 of the case's own scales:
/// v0, the final work, the largest temperature rise) and of the books summed over ranks: work received
/// = heat delivered = Σ_i M_i ΔT_i = Σ_p m_p C_p ΔT_p = the change of Σ_p m_p C_p T_p (`content`, J).
template <int Dim>
void expect_heated_block_as_serial(const HeatedBlockRun<Dim>& r, const coupling::DecomposedHeatBooks& b,
                                   const coupling::EnergyBooks& sb, double content, int steps, double v0) {
  const double ws = r.ws;
  EXPECT_TRUE(r.same);                       // every particle kept, with its temperature
  EXPECT_EQ(sb.matrix_free_windows, steps);  // the serial run took the matrix-free path every step
  EXPECT_EQ(b.windows, steps);
  EXPECT_EQ(b.substeps, sb.matrix_free_substeps);
  EXPECT_LT(r.v_end, v0 - 0.5);  // friction braked the block
  EXPECT_LE(r.dhist / v0, 1e-9);
  EXPECT_LE(r.dw / ws, 1e-9);
  EXPECT_LE(r.dT / r.rise, 1e-9);
  EXPECT_LE(std::fabs(b.work_received - ws) / ws, 1e-9);
  // Books over ranks: heat delivered = work received, and conduction creates no heat.
  EXPECT_LE(std::fabs(b.heat_delivered - b.work_received) / ws, 1e-9);
  EXPECT_LE(std::fabs(b.nodal_energy_change - b.work_received) / ws, 1e-9);
  EXPECT_LE(std::fabs(b.particle_energy_change - b.work_received) / ws, 1e-9);
  EXPECT_LE(std::fabs(content - b.work_received) / ws, 1e-9);
  EXPECT_LE(b.max_capacity_residual, 1e-12);  // Σ_i M_i = Σ_p m_p C_p (partition of unity)
}

}  // namespace frictherm::test
