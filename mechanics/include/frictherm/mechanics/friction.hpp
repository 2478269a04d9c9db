#pragma once
// Friction laws and frictional work for multimaterial contact (Nairn, Bardenhagen & Smith 2018,
// §2.6–2.10 and eqs. 42–43). Everything is in impulse form: the contact algorithm gives, per contact
// node and material pair, the stick momentum change split into d_n and d_t (eq. 15), the reduced mass,
// the contact area and the time step; a law says stick or slide and, when sliding, the tangential
// impulse S_slide A_c dt (eq. 17). The law is evaluated at the FINAL sliding speed
// |Δv'| = (d_t − S_slide A_c dt)/m_red (eq. 21), so velocity-dependent laws are implicit in S_slide.
// See docs/contact.md, "Friction laws".
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace frictherm::mechanics {

/// One contact node, one material pair, in impulse form (Nairn 2018 eqs 12-15). Normal n̂ points from material a to b.
struct ContactImpulse {
  double normal = 0;        // d_n = Δp_a·n̂  (kg m/s), < 0 when in contact
  double tangential = 0;    // d_t = |Δp_a − d_n n̂| ≥ 0 (kg m/s), Δp_a the stick momentum change of eq 12
  double reduced_mass = 0;  // m_red (kg)
  double area = 0;          // A_c (m^2), eq 11
  double dt = 0;            // time step (s)
};

struct FrictionOutcome {
  bool stick = true;            // true: apply the full stick change Δp_a
  double slide_impulse = 0.0;   // S_slide A_c dt ≥ 0 when sliding (eq 17): Δp'_a = d_n n̂ + slide_impulse t̂
};

enum class FrictionKind { stick, frictionless, coulomb, linear_velocity, adhesion, static_dynamic, smooth_static_dynamic, composite, user };

/// Sliding traction S (Pa) as a function of normal traction N (Pa), contact area A_c (m^2) and final sliding speed |Δv'| (m/s).
using SlidingTraction = std::function<double(double normal_traction, double area, double sliding_speed)>;

/// A friction law: a small value type (a few doubles, plus a shared pointer for user laws), evaluated
/// once per contact node per step by a switch on its kind (no virtual calls). Factories validate
/// their parameters and throw std::invalid_argument naming the parameter and what was expected.
///
/// in_contact() expects a pair detected in contact, d_n ≤ 0; the normal load used is N* = max(0, −d_n)
/// = N A_c dt. When sliding, 0 ≤ slide_impulse < d_t.
class FrictionLaw {
 public:
  FrictionLaw() = default;  // stick
  static FrictionLaw stick();
  static FrictionLaw frictionless();
  static FrictionLaw coulomb(double mu);                                   // eq 20
  static FrictionLaw linear_velocity(double mu0, double k);                // mu = mu0 + k|Δv'|, eqs 22-23 (k ≥ 0, s/m)
  static FrictionLaw adhesion(double mu, double shear_strength,
                              double tensile_strength = std::numeric_limits<double>::infinity());  // eqs 24-25
  static FrictionLaw static_dynamic(double mu_static, double mu_dynamic);  // naive law of §2.8 (known to start sliding early)
  static FrictionLaw smooth_static_dynamic(double mu_static, double mu_dynamic, double v_half);   // eqs 42-43
  /// The generalized law of eq 21 with every term at once: S = N [μ(v) + k v] + S_a, μ(v) the smooth
  /// static → dynamic coefficient of eq 42 (μ_s at v = 0, → μ_d as v ≫ v½; v½ = +inf keeps μ_s), k ≥ 0
  /// (s/m) the velocity coefficient of eq 22, S_a the adhesion of eq 24 and N_a its tensile strength
  /// (eq 25, +inf for none). Sticks while d_t ≤ (μ_s N + S_a) A_c dt; the sliding impulse is the root
  /// of eq 21 (bracketed, TOMS 748).
  static FrictionLaw composite(double mu_static, double mu_dynamic, double v_half, double k, double shear_strength,
                               double tensile_strength = std::numeric_limits<double>::infinity());
  static FrictionLaw user(SlidingTraction S, std::string name = "user");   // generic law, solved by a bracketed root finder on eq 21
  /// mu(|Δv'|) piecewise linear through (speeds[i], mu[i]), held constant outside; a user law with
  /// S = mu(v) N (kind() == user). S A_c dt = mu(v) N* does not involve A_c, so needs_area() is false.
  static FrictionLaw tabulated(std::vector<double> speeds, std::vector<double> mu);

  FrictionKind kind() const { return kind_; }
  FrictionOutcome in_contact(const ContactImpulse& c) const;   // stick/slide decision and S_slide A_c dt
  /// Adhesion with a tensile strength, surfaces detected as separated: true if the interface still holds
  /// (elliptical criterion eq 25 NOT exceeded), so the pair sticks; false for every other law.
  /// Tractions in Pa: sliding_traction = S_stick = d_t/(A_c dt), normal_traction = N = −d_n/(A_c dt)
  /// (only their magnitudes matter).
  bool holds_when_separated(double sliding_traction, double normal_traction) const;
  bool needs_area() const;   // adhesion and user laws depend on A_c (tabulated laws do not)
  std::string describe() const;  // e.g. "coulomb(mu=0.2)"

  // Parameters (0 when the law has none of that name).
  double mu() const { return mu_; }             // coulomb, adhesion; mu0 of linear_velocity; mu_s of the static laws
  double mu_dynamic() const { return mu_d_; }   // static_dynamic, smooth_static_dynamic, composite
  double velocity_coefficient() const { return k_; }  // k of linear_velocity (s/m)
  double v_half() const { return v_half_; }     // smooth_static_dynamic (m/s)
  double shear_strength() const { return shear_strength_; }      // S_a of adhesion (Pa)
  double tensile_strength() const { return tensile_strength_; }  // N_a of adhesion (Pa), +inf when none

 private:
  struct Custom;  // user / tabulated data: name, S, table

  FrictionKind kind_ = FrictionKind::stick;
  double mu_ = 0, mu_d_ = 0, k_ = 0, v_half_ = 0, shear_strength_ = 0;
  double tensile_strength_ = std::numeric_limits<double>::infinity();
  std::shared_ptr<const Custom> custom_;
};

/// "stick","frictionless","coulomb","linear_velocity","adhesion","static_dynamic","smooth_static_dynamic",
/// "tabulated" (→ FrictionKind::user: the only user law a scene can give); throws std::invalid_argument
/// listing the valid names.
FrictionKind friction_kind_from_string(const std::string&);
const char* to_string(FrictionKind);

/// Nairn 2018 eq 27: W1 = s (d_t − s)/m_red, with s = slide_impulse.
/// Returns 0 for s ≤ 0, m_red ≤ 0, non-finite inputs or a non-finite result (a material barely present
/// at a node must never produce inf/NaN), and never a negative value.
double frictional_work_first_order(double slide_impulse, double tangential, double reduced_mass);
/// Nairn 2018 eqs 32-36: W2 = s (f_t dt − s)/m_red; W1 − W2/2 if W2 < W1 (sliding all step), else W1²/(2 W2) (sliding started inside the step at t_s = dt(1 − W1/W2)).
/// f_t = Δf_a·t̂ from eq 30. Same guards as the first order, and dt ≤ 0 gives 0.
double frictional_work_second_order(double slide_impulse, double tangential, double tangential_force, double reduced_mass, double dt);

}  // namespace frictherm::mechanics
