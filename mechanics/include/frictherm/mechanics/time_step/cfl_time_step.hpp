#pragma once
// The explicit step's time step (Nairn 2018 eq. 45 on the dilatational wave speed, with the particle
// speed added), written once for the serial Simulation (simulation_setup.cpp), the decomposed engine
// (distributed/decomposition.cpp) and the scene's cost estimate (coupling scene_cost.cpp).
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/mie_gruneisen.hpp>

#include <algorithm>
#include <limits>

namespace frictherm::mechanics {

/// Dilatational wave speed of a deformable particle of `mat` at volume ratio J and internal energy e
/// (m/s): Mie-Grüneisen from its equation of state, Neo-Hookean stiffening under compression
/// (Material::wave_speed), otherwise the reference P-wave speed. Before the first stress update;
/// afterwards the stress update returns it (constitutive/stress_update.hpp). Not for rigid materials.
inline double particle_wave_speed(const Material& mat, Analysis an, double J, double e) {
  if (mat.kind == MaterialKind::mie_gruneisen) return mie_gruneisen_wave_speed(mat.mie_gruneisen, J, e);
  if (mat.kind == MaterialKind::neo_hookean) return mat.wave_speed(an, J);
  return mat.p_wave_speed(an);
}

/// The largest of `speed` and the speeds at which rigid materials move through the grid at time t.
inline double with_rigid_speeds(double speed, const std::vector<Material>& materials, double t) {
  for (const Material& mat : materials)  // rigid bodies move material through the grid too
    if (mat.is_rigid()) speed = std::max(speed, mat.rigid_velocity_at(t).norm());
  return speed;
}

/// Nairn 2018 eq. 45: dt = C h_min / max_p (c_p + |v_p|), bounded by max_time_step; with no speed at
/// all, max_time_step.
inline double cfl_time_step(double cfl, double min_cell_size, double max_speed, double max_time_step) {
  if (max_speed <= 0.0) return max_time_step;
  return std::min(cfl * min_cell_size / max_speed, max_time_step);
}

/// Explicit damping −c p_i: c dt ≤ 0.5 (stable up to 2, accurate well below 1).
inline double damping_time_step_limit(double rate) { return 0.5 / rate; }

}  // namespace frictherm::mechanics
