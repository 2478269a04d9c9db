// The penalty contact's kernels inside an MPM step, shared by the serial step (simulation_penalty.cpp)
// and the decomposed one (distributed/penalty_phases.cpp), so that each exists once (Kakouris, Chatzis
// & Triantafyllou 2024 §3.4–3.7, eqs. 27–36; docs/penalty_contact.md): the boundary points' weights
// (StepWeights), detection and forces into nodal slots (apply_penalty), the points' motion
// (move_points) and the time-step limits (penalty_wave_factor, penalty_time_step_limit). Internal header.
#pragma once

#include <frictherm/mechanics/simulation.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace frictherm::mechanics::penalty_kernels {

/// Slot of grid node `node` in a field's box, or −1 outside it.
template <int Dim>
int slot_of(const Grid<Dim>& grid, const FieldNodes<Dim>& F, int node) {
  const IVec<Dim> L = grid.node_lattice(node);
  int slot = F.index.shift;
  for (int d = 0; d < Dim; ++d) {
    const int l = L[d] + Grid<Dim>::ghost;
    if (l < F.lo[d] || l >= F.lo[d] + F.extent[d]) return -1;
    slot += l * F.index.stride[d];
  }
  return slot;
}

/// The boundary points' weights in the step: GridWeights (the step's kernel, renormalised over the
/// nodes where the field has mass), or with EBS the field's extended basis where it is defined.
template <int Dim>
struct StepWeights {
  GridWeights<Dim> plain;
  const std::vector<EbsBasis<Dim>>* ebs = nullptr;

  template <class Visit>
  void operator()(int field, const Vec<Dim>& x, const Vec<Dim>& half_size, Visit&& visit) const {
    if (ebs && try_extended(field, x, visit)) return;
    plain(field, x, half_size, visit);
  }

 private:
  static constexpr int kMax = 64;  // largest stencil taken from the extended basis (2D: 9 plain, ~16 extended)

  template <class Visit>
  bool try_extended(int field, const Vec<Dim>& x, Visit& visit) const {
    EbsStencil<Dim> s;
    (*ebs)[static_cast<std::size_t>(field)].evaluate(x, s);
    if (s.table == EbsStencil<Dim>::empty || s.size() > kMax) return false;
    const FieldNodes<Dim>& F = plain.fields[static_cast<std::size_t>(field)];
    int slot[kMax], node[kMax];
    double S[kMax];
    int m = 0;
    double sum = 0.0;
    s.for_each([&](int nd, double w, const Vec<Dim>&) {
      if (w == 0.0) return;
      const int sl = slot_of(*plain.grid, F, nd);
      if (sl < 0 || !plain.keeps(field, static_cast<std::size_t>(sl), w)) return;
      slot[m] = sl, node[m] = nd, S[m] = w;
      sum += w;
      ++m;
    });
    // N^e sums to one over the stable nodes, which all have mass; a sum far from one means the point
    // sits where the extension does not describe the field (fall back to the plain spline).
    if (m == 0 || !(sum > 0.5)) return false;
    const double inv = 1.0 / sum;
    for (int a = 0; a < m; ++a) visit(slot[a], node[a], S[a] * inv);
    return true;
  }
};

inline double modulus_for_penalty(const Material& m) {
  if (m.is_rigid()) return std::numeric_limits<double>::infinity();
  return m.youngs_modulus;  // mie_gruneisen: 0 unless given, then the partner's E (or set the penalty)
}

/// Detection and penalty forces at the points' positions (K·27–34), each point force added to its
/// field's slot through the point's own weights (K·36), the frictional heat to the grid nodes (both
/// orders: penalty heat has no first/second-order split) and the springs' frequency bound for the next
/// time step. `slot_mass` is indexed as the weights' slots; step 1 (K·27): a slave point is a candidate
/// if its stencil reaches a node where the master field has mass.
template <int Dim>
void apply_penalty(PenaltyContact<Dim>& pc, const BoundaryPoints<Dim>& points, const StepWeights<Dim>& w,
                   const std::vector<double>& slot_mass, double min_mass, std::vector<Vec<Dim>>& force,
                   std::vector<double>& heat_first, std::vector<double>& heat_second) {
  const auto master_has_mass = [&](int field, int node) {
    const int s = slot_of(*w.plain.grid, w.plain.fields[static_cast<std::size_t>(field)], node);
    return s >= 0 && slot_mass[static_cast<std::size_t>(s)] > min_mass;
  };
  pc.compute(points, [&](int k, int i) {
    return touches_field(points, i, w, pc.pair(static_cast<std::size_t>(k)).master, master_has_mass);
  });
  pc.scatter_forces(points, w, force);  // K·36; rigid fields drop theirs in the velocity conditions
  pc.scatter_heat(points, w, heat_first);
  pc.scatter_heat(points, w, heat_second);
  pc.update_frequency_bound(points, w, slot_mass, min_mass);  // for the next time step
}

/// The points' velocity and motion: a rigid field's points v = ½ (v_rigid(t) + v_rigid(t + Δt))
/// (`rigid(field, v)` returns true and sets it), the others v_b = Σ_I w_I v_I with `velocity(slot)` the
/// nodal velocity the stress update uses; x_b += Δt v_b. Returns the first point outside the grid
/// widened by a cell (boundary points may lie on its edge) or non-finite, or −1.
template <int Dim, class Rigid, class Velocity>
long move_points(BoundaryPoints<Dim>& bp, const StepWeights<Dim>& w, const Grid<Dim>& grid, double dt, Rigid&& rigid,
                 Velocity&& velocity) {
  for (std::size_t i = 0; i < bp.size(); ++i) {
    Vec<Dim> v = Vec<Dim>::Zero();
    if (!rigid(bp.field[i], v))
      w(bp.field[i], bp.position[i], bp.half_size[i], [&](int slot, int, double S) { v += S * velocity(slot); });
    bp.velocity[i] = v;
  }
  for (std::size_t i = 0; i < bp.size(); ++i) bp.position[i] += dt * bp.velocity[i];
  const Vec<Dim> lo = grid.lo() - grid.cell_size(), hi = grid.hi() + grid.cell_size();
  for (std::size_t i = 0; i < bp.size(); ++i)
    if (!bp.position[i].allFinite() || (bp.position[i].array() < lo.array()).any() ||
        (bp.position[i].array() > hi.array()).any())
      return static_cast<long>(i);
  return -1;
}

/// √(ε/(E/Δh)) of the stiffest penalty pair above K·40's ε = E/Δh (E the smaller finite modulus of the
/// pair), at least 1: the factor on the wave speed of the CFL step (docs/penalty_contact.md, "Stability").
template <int Dim>
double penalty_wave_factor(const PenaltyContact<Dim>& pc, const std::vector<PenaltyPairInfo>& pairs,
                           const std::vector<Material>& materials, double h) {
  double factor = 1.0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const PenaltyPairSettings& s = pc.pair(k);
    double E = std::numeric_limits<double>::infinity();
    for (int m : {pairs[k].master_material, pairs[k].slave_material}) {
      const double Em = modulus_for_penalty(materials[static_cast<std::size_t>(m)]);
      if (Em > 0.0) E = std::min(E, Em);
    }
    if (!std::isfinite(E)) continue;
    factor = std::max(factor, std::sqrt(std::max(s.normal_penalty, s.tangential_penalty) / (E / h)));
  }
  return factor;
}

/// Δt ≤ 2/√(ω_el² + ω_p²), ω_el = 2 c/Δh and ω_p² the last step's Gershgorin bound of the springs
/// (PenaltyContact::frequency_bound_squared); infinite without contacts.
inline double penalty_time_step_limit(double frequency_bound2, double wave_speed, double h) {
  if (!(frequency_bound2 > 0.0)) return std::numeric_limits<double>::infinity();
  const double wel = 2.0 * wave_speed / h;
  return 2.0 / std::sqrt(wel * wel + frequency_bound2);
}

}  // namespace frictherm::mechanics::penalty_kernels
