#pragma once
// Multimaterial contact settings (Nairn, Bardenhagen & Smith 2018, §2.2–2.12).
//
// With contact enabled every material extrapolates its own velocity field (eqs. 1–6). Nodes that
// carry two or more materials resolve contact: one normal per node (eq. 7: maximum or average
// volume gradient, or a specified normal), contact when the materials approach and their
// separation is negative (eq. 8 positions with the 0.8 h⊥ correction, or eqs. 9–10 displacements),
// a contact area (eq. 11), the stick momentum change and reduced mass (eqs. 12–15), and a friction
// law that decides stick or slide (eqs. 16–25, 42–43). Contact is applied after the momentum
// extrapolation, after the momentum update (with forces kept consistent, eq. 19, and frictional
// work of first and second order, eqs. 27 and 29–36) and, for MUSL, after the momentum remap.
//
// A pair may instead use penalty contact on boundary material points (Kakouris et al. 2024, method
// = penalty; penalty_contact.hpp, docs/penalty_contact.md): its materials then meet only through
// penalty forces, and the node-based resolution above skips them.
//
// Sign convention: the normal n̂ points from material a to material b, so the materials approach
// when (v_b − v_a)·n̂ < 0 and the separation is δ = (x̄_b − x̄_a)·n̂ − 0.8 h⊥ (positions) or
// (Δx̄_b − Δx̄_a)·n̂ (displacements), or the gap between the particles' domains (extent, frictherm's
// own test, contact_extents.cpp); the paper prints these with the opposite orientation.
#include <frictherm/mechanics/friction.hpp>
#include <frictherm/mechanics/types.hpp>

#include <cstddef>
#include <string>

namespace frictherm::mechanics {

enum class NormalMethod { max_volume_gradient, average_volume_gradient, specified };
enum class SeparationMethod { position, displacement, velocity_only, extent };
/// The contact area A_c a friction law sees at a node: `domain`, eq. 11 of Nairn, Bardenhagen &
/// Smith 2018 (from the two materials' nodal domains Ω_{i,j}); `surface`, the surface integral of the
/// node's shape function over the contact surface, |g_{i,j}·n̂| = |∫_Ω ∇S_i dV · n̂| = ∫_Γ S_i dA
/// (divergence theorem), the smaller of the two materials'. The surface areas of an interface's nodes
/// sum to its true area for any offset from the grid lines and at the ends of a shorter body (partition
/// of unity); eq. 11 gives 0.61 h instead of 0.5 h at a node under a body's end.
enum class ContactAreaMethod { domain, surface };
enum class HeatingOrder { first, second };
enum class ContactMethod { multimaterial, penalty };
/// Penalty contact, tangential law: return mapping with a tangential spring (default) or Kakouris
/// 2024 eq. 32 as printed (increment only). See penalty_contact.hpp.
enum class TangentialLaw { return_mapping, incremental };

NormalMethod normal_method_from_string(const std::string& name);          // "mvg", "avg"
SeparationMethod separation_method_from_string(const std::string& name);  // "position", "displacement", "velocity_only", "extent"
HeatingOrder heating_order_from_string(const std::string& name);          // "first", "second"
ContactMethod contact_method_from_string(const std::string& name);        // "multimaterial", "penalty"
TangentialLaw tangential_law_from_string(const std::string& name);        // "return_mapping", "incremental"
const char* to_string(NormalMethod m);
const char* to_string(SeparationMethod m);
const char* to_string(HeatingOrder o);

/// The frictional work books per material pair (Simulation and DecomposedMpm): materials² entries,
/// the unordered pair {a, b} at min(a, b)·materials + max(a, b).
inline std::size_t pair_book_index(int a, int b, std::size_t materials) {
  return static_cast<std::size_t>(a < b ? a : b) * materials + static_cast<std::size_t>(a < b ? b : a);
}
const char* to_string(ContactMethod m);
const char* to_string(TangentialLaw law);

/// Penalty contact settings of a pair (method == penalty; Kakouris 2024 §3.5–3.6). The friction
/// coefficient is the pair's law: coulomb (μ) or frictionless (μ = 0).
struct PenaltySettings {
  double normal_penalty = 0.0;      // ε_N (N/m³); 0: normal_factor × E/Δh (eq. 40), E the smaller finite modulus
  double normal_factor = 1.0;       // multiple of E/Δh when normal_penalty is 0
  double tangential_penalty = 0.0;  // ε_T (N/m³); 0: equal to ε_N (eq. 40)
  TangentialLaw law = TangentialLaw::return_mapping;
  double search_radius = 0.0;       // distance check (m); 0: the smallest cell size Δh
  int master = -1;                  // material id of the master; -1: the rigid, else stiffer, else heavier body
  bool paper_correction_terms = false;  // the (g/l) P and (Δg_T/l) Q terms of eqs. 51–52
};

/// How one pair of materials interacts.
struct ContactPairSettings {
  FrictionLaw law = FrictionLaw::stick();
  NormalMethod normal = NormalMethod::max_volume_gradient;
  Vec<3> normal_vector = Vec<3>::UnitY();  // specified normal, from the pair's first material to its second
  ContactMethod method = ContactMethod::multimaterial;
  PenaltySettings penalty;                 // method == penalty
  /// Where these settings were given (e.g. the scene key "contact.pairs[0].law"), for messages only:
  /// a friction law that fails during a step is reported with it (Simulation::resolve_contact).
  std::string origin;
};

struct ContactOptions {
  ContactPairSettings default_pair;                   // pairs not set explicitly
  SeparationMethod separation = SeparationMethod::position;
  double position_correction = 0.8;                   // c in δ = (x̄_b − x̄_a)·n̂ − c h⊥ (eq. 8)
  /// Extent separation (contact_extents.cpp): in contact while the gap between the particle domains
  /// along n̂ is below this fraction of h⊥.
  double extent_tolerance = 0.0;
  /// A material whose mass at a node is below this fraction of the node's mass takes no part in
  /// contact there: its field is a numerical sliver, and its reduced mass would make the contact
  /// and heating terms ill-conditioned.
  double min_mass_fraction = 1e-6;
  /// A material whose mass at a node is below this fraction of the node's mass (but above
  /// min_mass_fraction) is a sliver there: contact stops it interpenetrating (normal change only)
  /// but applies no friction and makes no heat; a deformable sliver whose rigid partner holds the node
  /// and whose pair's law bonds the surfaces (stick, or adhesion with a tensile strength that holds)
  /// sticks to the rigid body. 0: none.
  double sliver_fraction = 0.0;
  /// Position and displacement separation: a material holding less than this fraction of a pair's
  /// mass at a node is in contact there whenever the pair approaches, normal contact only (its mass
  /// centroid, a cell from its surface, cannot show it touching). 0: off. Under MUSL 0.03 removes
  /// most of the energy an impact gains (docs/contact.md, "Where the frictionless impact creates
  /// energy"); it changes the paper's oscillating block's heat, hence off by default.
  double light_touch_fraction = 0.0;
  /// Extent detection with its companions (the scene defaults for `"separation": "extent"`): no
  /// material dropped, slivers below 1e-3 of the node's mass frictionless, gaps below 1 % of h⊥
  /// not resolved (docs/contact.md, "Contact detection").
  void use_extent_detection() {
    separation = SeparationMethod::extent;
    min_mass_fraction = 0.0;
    sliver_fraction = 1e-3;
    extent_tolerance = 0.01;
  }
  /// Normal-stress regularisation of friction (Prakash–Clifton type; Cochard & Rice 2000): the friction
  /// law sees a lagged normal traction σ̃ that follows the instantaneous one as
  /// dσ̃/dt = −(|v_slip|/L + 1/τ)(σ̃ − σ), not σ itself. Coulomb-type friction tied to the instantaneous
  /// normal traction makes sliding elastic bodies unstable at the grid scale (docs/contact.md,
  /// "Normal-stress regularisation"). 0 (either): off. Nodes with three or more materials use σ.
  /// The contact area of area laws (adhesion, S_a A_c): ContactAreaMethod.
  ContactAreaMethod area = ContactAreaMethod::surface;
  double regularization_slip_length = 0.0;  // L (m)
  double regularization_time = 0.0;         // τ (s)
  bool regularized() const { return regularization_slip_length > 0.0 && regularization_time > 0.0; }
  /// Penalty contact: spacing of the boundary points sampled on each body's region (m); 0: half
  /// the smallest cell size. Used when a body is added, so set it before add_body().
  double boundary_spacing = 0.0;
  /// The spacing the boundary points are sampled at on a grid whose smallest cell is `min_cell` (m).
  double boundary_point_spacing(double min_cell) const {
    return boundary_spacing > 0.0 ? boundary_spacing : 0.5 * min_cell;
  }
};

}  // namespace frictherm::mechanics
