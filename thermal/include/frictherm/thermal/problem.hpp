// Semi-discrete heat equation on a set of nodes (design §3, Nairn et al. 2018 eq. 37–38):
//
//   M dT/dt = −K T + q(t) + f + hA ⊙ (T_inf − T),      T_d fixed on Dirichlet nodes d,
//
// with M the diagonal (lumped) heat capacity [J/K], K the symmetric conductance matrix [W/K],
// q(t) nodal sources [W] (constant, or linear in time over a window), f prescribed nodal heat
// inputs [W] (flux boundaries) and hA ⊙ (T_inf − T) convective exchange [W]. An optional
// Arrhenius reaction adds Q_i (1 − λ_i) Z exp(−Θ/T_i) with a per-node progress λ (reaction.hpp).
// The module knows nothing about where M and K come from (MPM, FD or FE grids).
#pragma once

#include "frictherm/thermal/reaction.hpp"
#include "frictherm/thermal/source_ramp.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cstdint>
#include <vector>

namespace frictherm::thermal {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using Index = Eigen::Index;

/// Round-off allowed in an assembled K, relative to its largest |entry|: the asymmetry of a mirror
/// pair, and a diagonal below zero (a node only zero-conductivity particles reach sums to ±1e-35).
constexpr double kConductanceRoundOff = 1e-12;

class Problem {
 public:
  // Throws std::invalid_argument if M has a non-positive or non-finite entry, if K is not
  // square of the same size, not symmetric (|K_ij − K_ji| > symmetry_tol·max|K|), has a
  // non-finite entry or a diagonal below −symmetry_tol·max|K|. K is assumed positive semi-definite; only these
  // necessary conditions are checked.
  Problem(Eigen::VectorXd mass, SparseMatrix conductance, double symmetry_tol = kConductanceRoundOff);
  // The same as assigning Problem(mass, conductance, symmetry_tol), in this object's storage: a
  // coupled run's windows keep their sizes, so nothing is allocated. Same checks and throws; after a
  // throw only another reset or the destructor may be called.
  void reset(const Eigen::VectorXd& mass, const SparseMatrix& conductance, double symmetry_tol = kConductanceRoundOff);

  Index size() const { return mass_.size(); }
  const Eigen::VectorXd& mass() const { return mass_; }
  const SparseMatrix& conductance() const { return k_; }

  // ---- sources q(t) [W per node] ----
  // Constant in time.
  void set_source(Eigen::VectorXd q);
  // Linear over [t0, t1]: q(t) = q0 + (t − t0)/(t1 − t0)·(q1 − q0); held at q0 before t0 and
  // at q1 after t1. Requires t1 > t0.
  void set_source_ramp(Eigen::VectorXd q0, Eigen::VectorXd q1, double t0, double t1);
  void clear_source();
  bool has_source() const { return source_.active; }
  // q(t), the total source per node (zeros without a source).
  Eigen::VectorXd source(double t) const;

  // ---- boundaries ----
  // Fixes node's temperature [K]. Its equation becomes dT/dt = 0.
  void set_dirichlet(Index node, double temperature);
  void clear_dirichlet();
  bool is_dirichlet(Index node) const { return fixed_[static_cast<std::size_t>(node)] != 0; }
  const std::vector<Index>& dirichlet_nodes() const { return dirichlet_nodes_; }
  // Adds a prescribed heat input [W] to a node (a flux boundary times its nodal area).
  void add_flux(Index node, double watts);
  // Adds convective exchange hA [W/K] with an ambient at T_inf [K] to a node.
  void add_convection(Index node, double h_times_area, double t_inf);
  void clear_boundaries();  // fluxes and convection (not Dirichlet nodes)
  const Eigen::VectorXd& flux() const { return flux_; }
  const Eigen::VectorXd& convection_coefficients() const { return ha_; }

  // ---- reaction (reaction.hpp) ----
  // Throws std::invalid_argument unless heat has size() finite entries ≥ 0 and Z, Θ are
  // finite and > 0. Dirichlet nodes and nodes with Q_i = 0 never react.
  void set_reaction(Reaction reaction);
  void clear_reaction();
  bool has_reaction() const { return has_reaction_; }
  // True when the reaction depletes its reactant, so integrators need the progress λ.
  bool reaction_consumes() const { return has_reaction_ && reaction_.consume; }
  const Reaction& reaction() const { return reaction_; }  // empty heat without a reaction
  // p_i = Q_i (1 − λ_i) Z exp(−Θ/T_i) [W]; zero on Dirichlet nodes and without a reaction.
  // An empty progress means λ = 0 (fresh material).
  void reaction_power(const Eigen::Ref<const Eigen::VectorXd>& temperature,
                      const Eigen::Ref<const Eigen::VectorXd>& progress, Eigen::Ref<Eigen::VectorXd> p) const;
  // Σ_i Q_i λ_i [J]: heat released so far (0 without a reaction).
  double released_heat(const Eigen::VectorXd& progress) const;
  // Throws std::invalid_argument unless progress has size() finite entries in [0, 1].
  void check_progress(const Eigen::VectorXd& progress) const;

  // ---- evaluation ----
  // Nodal heat rate without the reaction, −K T + q(t) + f + hA ⊙ (T_inf − T) [W]; zero on
  // Dirichlet nodes.
  void transport_heat_rate(double t, const Eigen::Ref<const Eigen::VectorXd>& temperature,
                           Eigen::Ref<Eigen::VectorXd> w) const;
  // Full nodal heat rate w = transport + reaction power at progress λ [W] (empty progress:
  // λ = 0); zero on Dirichlet nodes.
  void heat_rate(double t, const Eigen::Ref<const Eigen::VectorXd>& temperature,
                 const Eigen::Ref<const Eigen::VectorXd>& progress, Eigen::Ref<Eigen::VectorXd> w) const;
  // Same with λ = 0 (fresh material; identical to transport_heat_rate without a reaction).
  void heat_rate(double t, const Eigen::Ref<const Eigen::VectorXd>& temperature,
                 Eigen::Ref<Eigen::VectorXd> w) const;
  // dT/dt = M⁻¹ w (λ = 0).
  void rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& temperature,
           Eigen::Ref<Eigen::VectorXd> dTdt) const;
  // Σ over free nodes of q(t) + f + hA ⊙ (T_inf − T) [W]: the power entering through sources
  // and boundaries (conduction only moves heat between nodes since K has zero row sums).
  double boundary_and_source_power(double t, const Eigen::VectorXd& temperature) const;
  // Σ_i M_i T_i [J] (thermal-notes §4 invariant).
  double thermal_energy(const Eigen::VectorXd& temperature) const;
  // Writes the Dirichlet values into T.
  void apply_dirichlet(Eigen::VectorXd& temperature) const;
  // Throws std::invalid_argument unless T has size() finite entries.
  void check_state(const Eigen::VectorXd& temperature) const;

  // Changes whenever M, K, a boundary or the reaction changes (not when sources change); integrators use it
  // to know when to rebuild Jacobians. Unique across all Problem objects.
  std::uint64_t revision() const { return revision_; }

 private:
  void add_reaction_power(const Eigen::Ref<const Eigen::VectorXd>& temperature,
                          const Eigen::Ref<const Eigen::VectorXd>& progress, Eigen::Ref<Eigen::VectorXd> p) const;
  void check_node(Index node, const char* what) const;
  void check_source_vector(const Eigen::VectorXd& q, const char* what) const;
  void touch();
  void check_and_clear(double symmetry_tol);

  Eigen::VectorXd mass_;
  SparseMatrix k_;
  SourceRamp source_;
  std::vector<unsigned char> fixed_;
  std::vector<Index> dirichlet_nodes_;
  Eigen::VectorXd fixed_value_;
  Eigen::VectorXd flux_, ha_, ha_tinf_;
  bool has_reaction_ = false;
  Reaction reaction_;
  std::uint64_t revision_ = 0;
};

}  // namespace frictherm::thermal
