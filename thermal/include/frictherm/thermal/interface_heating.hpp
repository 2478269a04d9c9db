#pragma once
// Sub-cell interface temperature (design §7, issue 31): the temperature at a rubbing interface that a
// grid of spacing h cannot resolve while the heat has diffused less than about a cell.
//
// Model. Heat generated at an interface enters two half-spaces a and b (conductivity k_s,
// volumetric heat capacity C_s = ρ_s c_s, diffusivity α_s = k_s/C_s, effusivity e_s = √(k_s C_s)) as a
// flux q(t) normal to the interface. Their common surface temperature rise is (Carslaw & Jaeger §2.9,
// two bodies in contact sharing a plane source)
//
//     θ_c(t) = 1/(e_a + e_b) ∫ q(τ) / √(π (t − τ)) dτ,        unit-step response  R_c = 2 √(t/π) / (e_a + e_b).
//
// A lumped grid resolves the same 1D problem as a chain of nodes of spacing h: the interface node
// holding h (C_a + C_b)/2 per unit area, the nodes beyond it h C_s, each side conducting k_s/h. In
// the MPM coupling the nodal temperatures are projected again from the particles every window (N·38)
// after the particles took the window's nodal change (T_p += Σ S_ip ΔT_i): every nodal increment, of
// the source and of conduction alike, is read back through P = M⁻¹ Sᵀ diag(m c) S, which on a uniform
// lattice is the stencil [(1−f)/2, f, (1−f)/2] per axis, f = Σ_p S_ip² m_p c_p / Σ_p S_ip m_p c_p
// (the projection factor: 0.625 for linear hats with two particles a cell, 1 for a plain grid). So
// the grid integrates dT/dt = P M⁻¹ (q − K T). On one side (its share e_s/(e_a+e_b) of the flux, the
// continuum's split, on a half chain) the interface node's unit-step response is, per unit area,
//
//     R_d,s(t) = (e_s/(e_a+e_b)) (2/(h C_s)) (1/π) ∫₀^π P̂ (1 − e^{−σt})/σ dφ,
//     P̂ = f + (1 − f) cos φ,  σ = 2 λ_s P̂ (1 − cos φ),  λ_s = α_s/h²
//
// (the lattice Green's function; f = 1 gives x e^{−x}(I₀(x) + I₁(x))/(2λ), x = 2λt). It reads f·Q/m₀
// of fresh heat and the continuum once the heat has spread over cells. The grid's interface
// temperature is taken as R_g = Σ_s (e_s/(e_a+e_b)) R_d,s: exact when the two sides' admittances are
// proportional to their effusivities (equal diffusivities, or times long against h²/α), an
// approximation otherwise (measured in tests/thermal/test_interface_heating.cpp).
//
// The sub-cell correction is what the continuum has and the grid lacks,
//
//     R_x(t) = R_c(t) − R_g(t):   ≈ 2 √(t/π)/(e_a+e_b) for t ≪ h²/α, → 0 as t^{−1/2}·h²/α for t ≫ h²/α,
//
// so the interface temperature is T_grid + (the node's flux history convolved with R_x): it relaxes
// to the grid temperature as the heat spreads over a cell, and the correction shrinks as h does.
// The correction is a reconstruction of the surface value of a profile whose energy the grid already
// holds (both 1D problems receive the same ∫ q dt); it carries no energy of its own.
//
// History. A node's flux history is kept in bins that widen with age (BinnedHeatHistory): at most
// `bins_per_level` bins of each width, the two oldest of a full level merged into one of the next (the
// merged bin's heat is exact; only its timing inside the bin is averaged). A bin of width w sits at a
// lag of at least bins_per_level·w/2, where R_x varies slowly, so the convolution costs
// O(bins_per_level × log₂(steps)) per node and its error falls as 1/bins_per_level².
#include <cstddef>
#include <vector>

namespace frictherm::thermal {

/// One side of a contact: conductivity (W/(m K)) and volumetric heat capacity ρ c (J/(m³ K)).
struct HalfSpace {
  double conductivity = 0.0;
  double volumetric_heat_capacity = 0.0;
  double diffusivity() const { return conductivity / volumetric_heat_capacity; }
  double effusivity() const;  // √(k ρ c), W s^½/(m² K)
};

/// Surface-temperature rise (K) of two half-spaces in contact at time t (s) after a unit flux
/// (1 W/m²) into their interface started: 2 √(t/π)/(e_a + e_b).
double half_space_pair_step_response(double t, const HalfSpace& a, const HalfSpace& b);
/// The interface node of the lumped chain of spacing h (m) between the two with projection factor f,
/// same flux (model above; quadrature to ~1e-10 relative).
double lumped_grid_step_response(double t, const HalfSpace& a, const HalfSpace& b, double h,
                                 double projection_factor = 1.0);

/// R_x = half_space_pair_step_response − lumped_grid_step_response, tabulated on a logarithmic time
/// axis from 1e-6 to 1e5 h²/α (24 points a decade, cubic interpolation of R_x/R_c; below: the
/// early asymptote R_c − 2 f t/(h (C_a + C_b)), above: R_x/R_c ∝ 1/t, the lattice's next term;
/// R_x/R_c is below 1e-5 there).
class SubcellCorrection {
 public:
  SubcellCorrection(const HalfSpace& a, const HalfSpace& b, double h, double projection_factor = 1.0);
  double step_response(double t) const;
  double cell() const { return h_; }

 private:
  HalfSpace a_, b_;
  double h_, f_;
  double log_t0_ = 0.0, dlog_ = 0.0;  // table axis: ln t_j = log_t0_ + j dlog_
  std::vector<double> ratio_;         // R_x / R_c at t_j
};

/// Heat per unit area received by many sources (slots), binned in time with widening bins.
/// Bins are kept oldest first; their boundaries are t_0 < t_1 < ... < t_B.
class BinnedHeatHistory {
 public:
  explicit BinnedHeatHistory(std::size_t bins_per_level = 8);

  /// Forgets everything; the history starts at time t0.
  void reset(double t0);
  /// A new source with no heat; returns its slot.
  std::size_t add_slot();
  std::size_t slot_count() const { return slots_; }
  /// Heat per unit area (J/m²) that `slot` received in the open interval (since the last close).
  void add(std::size_t slot, double energy_per_area) { open_[slot] += energy_per_area; }
  /// Ends the open interval at time t (> the last boundary); an interval with no heat at any slot
  /// still becomes a bin (the time axis stays contiguous).
  void close(double t);

  std::size_t bin_count() const { return bins_.size(); }
  /// t_0 … t_B (B = bin_count()); the last is the time of the last close.
  const std::vector<double>& boundaries() const { return boundaries_; }
  /// The heat per area of `slot` in bin b (0 for slots added after the bin closed).
  double energy(std::size_t bin, std::size_t slot) const {
    const auto& e = bins_[bin].energy;
    return slot < e.size() ? e[slot] : 0.0;
  }
  /// Σ over bins of each slot's heat per area (J/m²), plus the open interval's.
  double total_energy(std::size_t slot) const;

  /// For every slot s: Σ_b E_b,s / (t_{b+1} − t_b) · (R(t − t_b) − R(t − t_{b+1})), the response at
  /// time t ≥ the last boundary to the binned flux, with R(lag) = responses[group_of_slot[s]][j] at
  /// lag t − t_j (the caller evaluates its step responses at the boundaries, once per group).
  void convolve(const std::vector<std::vector<double>>& responses, const std::vector<int>& group_of_slot,
                std::vector<double>& out) const;

  std::size_t bins_per_level() const { return per_level_; }

  /// Checkpoint form: boundaries, levels, and the energies bin-major (bin_count × slot_count).
  struct Flat {
    std::vector<double> boundaries;
    std::vector<int> levels;
    std::vector<double> energy;
    std::vector<double> open;
  };
  Flat flatten() const;
  /// Restores flatten()'s output; throws std::invalid_argument when the sizes do not agree.
  void restore(const Flat& f);

 private:
  struct Bin {
    int level = 0;
    std::vector<double> energy;  // per slot
  };
  void merge_full_levels();

  std::size_t per_level_;
  std::size_t slots_ = 0;
  std::vector<Bin> bins_;            // oldest first; levels non-increasing from oldest to newest
  std::vector<double> boundaries_;   // bins_.size() + 1 entries
  std::vector<double> open_;         // the open interval, per slot
  std::vector<std::vector<double>> pool_;  // recycled energy vectors (no allocation per step)
};

}  // namespace frictherm::thermal
