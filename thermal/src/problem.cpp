#include "frictherm/thermal/problem.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace frictherm::thermal {
namespace {

std::uint64_t next_revision() {
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

[[noreturn]] void fail(const std::string& msg) { throw std::invalid_argument("thermal::Problem: " + msg); }

}  // namespace

Problem::Problem(Eigen::VectorXd mass, SparseMatrix conductance, double symmetry_tol)
    : mass_(std::move(mass)) {
  k_.swap(conductance);  // (Eigen 3.4's SparseMatrix has no move: a move would copy)
  check_and_clear(symmetry_tol);
}

void Problem::reset(const Eigen::VectorXd& mass, const SparseMatrix& conductance, double symmetry_tol) {
  mass_ = mass;       // Eigen keeps the storage of a vector of the same size
  k_ = conductance;   // and of a matrix of the same size with no more non-zeros
  check_and_clear(symmetry_tol);
}

// The constructor's checks of M and K, then no sources, boundaries or reaction and a new revision.
void Problem::check_and_clear(double symmetry_tol) {
  const Index n = mass_.size();
  if (n == 0) fail("the mass vector M is empty (need at least one node)");
  for (Index i = 0; i < n; ++i) {
    if (!std::isfinite(mass_[i]) || mass_[i] <= 0.0) {
      std::ostringstream os;
      os << "heat capacity M[" << i << "] = " << mass_[i]
         << " J/K must be finite and > 0 (remove empty nodes before building the problem)";
      fail(os.str());
    }
  }
  if (k_.rows() != n || k_.cols() != n) {
    std::ostringstream os;
    os << "size mismatch: M has " << n << " nodes but K is " << k_.rows() << "x" << k_.cols();
    fail(os.str());
  }
  k_.makeCompressed();
  double kmax = 0.0;
  for (Index r = 0; r < n; ++r) {
    for (SparseMatrix::InnerIterator it(k_, r); it; ++it) {
      if (!std::isfinite(it.value())) {
        std::ostringstream os;
        os << "K(" << r << "," << it.col() << ") is not finite";
        fail(os.str());
      }
      kmax = std::max(kmax, std::abs(it.value()));
    }
  }
  // Symmetry checked in place in one sweep, O(nnz) (no transpose, no search per entry: this runs once
  // per coupling window). Rows are visited in order and every row keeps a cursor into its own entries:
  // the upper entry K(r,c), c > r, meets its mirror K(c,r) at row c's cursor (columns are sorted), and
  // a lower entry the cursor passes without a mirror stands against a zero.
  const double tol = symmetry_tol * kmax;
  const auto* outer = k_.outerIndexPtr();
  const auto* inner = k_.innerIndexPtr();
  const double* value = k_.valuePtr();
  auto check = [&](Index r, Index c, double d) {
    if (std::abs(d) > tol) {
      std::ostringstream os;
      os << "K is not symmetric: K(" << r << "," << c << ") − K(" << c << "," << r << ") = " << d << " (tolerance "
         << tol << ")";
      fail(os.str());
    }
  };
  std::vector<Index> cursor(outer, outer + n);
  for (Index r = 0; r < n; ++r) {
    for (Index e = outer[r]; e < outer[r + 1]; ++e) {
      const Index c = inner[e];
      if (c <= r) continue;
      Index& q = cursor[static_cast<std::size_t>(c)];
      for (; q < outer[c + 1] && inner[q] < r; ++q) check(c, inner[q], value[q]);  // no mirror
      double mirror = 0.0;
      if (q < outer[c + 1] && inner[q] == r) mirror = value[q++];
      check(r, c, value[e] - mirror);
    }
  }
  for (Index c = 0; c < n; ++c)  // lower entries after the last mirror found
    for (Index q = cursor[static_cast<std::size_t>(c)]; q < outer[c + 1] && inner[q] < c; ++q) check(c, inner[q], value[q]);
  // A diagonal below zero by more than the round-off of the row sums it is built from (the same
  // tolerance as symmetry: a node whose particles all have conductivity 0 sums to ±1e-35 or so).
  for (Index r = 0; r < n; ++r) {
    if (k_.coeff(r, r) < -tol) {
      std::ostringstream os;
      os << "K(" << r << "," << r << ") = " << k_.coeff(r, r) << " < 0 (tolerance " << tol
         << "): K must be positive semi-definite";
      fail(os.str());
    }
  }
  clear_source();
  fixed_.assign(static_cast<std::size_t>(n), 0);
  dirichlet_nodes_.clear();
  fixed_value_.setZero(n);
  flux_.setZero(n);
  ha_.setZero(n);
  ha_tinf_.setZero(n);
  clear_reaction();  // and a new revision
}

void Problem::touch() { revision_ = next_revision(); }

void Problem::check_node(Index node, const char* what) const {
  if (node < 0 || node >= size()) {
    std::ostringstream os;
    os << what << ": node " << node << " out of range [0, " << size() << ")";
    fail(os.str());
  }
}

void Problem::check_source_vector(const Eigen::VectorXd& q, const char* what) const {
  if (q.size() != size()) {
    std::ostringstream os;
    os << what << ": size mismatch, source has " << q.size() << " entries for " << size() << " nodes";
    fail(os.str());
  }
  if (!q.allFinite()) fail(std::string(what) + ": source has a non-finite entry");
}

void Problem::set_source(Eigen::VectorXd q) {
  check_source_vector(q, "set_source");
  source_.set_constant(std::move(q));
}

void Problem::set_source_ramp(Eigen::VectorXd q0, Eigen::VectorXd q1, double t0, double t1) {
  check_source_vector(q0, "set_source_ramp (q0)");
  check_source_vector(q1, "set_source_ramp (q1)");
  if (!(std::isfinite(t0) && std::isfinite(t1) && t1 > t0)) {
    std::ostringstream os;
    os << "set_source_ramp: need finite t1 > t0, got [" << t0 << ", " << t1 << "]";
    fail(os.str());
  }
  source_.set_ramp(std::move(q0), std::move(q1), t0, t1);
}

void Problem::clear_source() {
  source_ = SourceRamp{};
}

Eigen::VectorXd Problem::source(double t) const {
  if (!source_.active) return Eigen::VectorXd::Zero(size());
  if (!source_.ramped()) return source_.q0;
  // Linear waveform over the window, clamped outside it.
  const double s = source_.fraction(t);
  return source_.q0 + s * (source_.q1 - source_.q0);
}

void Problem::set_dirichlet(Index node, double temperature) {
  check_node(node, "set_dirichlet");
  if (!std::isfinite(temperature)) fail("set_dirichlet: temperature must be finite");
  auto& flag = fixed_[static_cast<std::size_t>(node)];
  if (!flag) {
    flag = 1;
    dirichlet_nodes_.push_back(node);
  }
  fixed_value_[node] = temperature;
  touch();
}

void Problem::clear_dirichlet() {
  std::fill(fixed_.begin(), fixed_.end(), 0);
  dirichlet_nodes_.clear();
  fixed_value_.setZero();
  touch();
}

void Problem::add_flux(Index node, double watts) {
  check_node(node, "add_flux");
  if (!std::isfinite(watts)) fail("add_flux: heat input must be finite");
  flux_[node] += watts;
  touch();
}

void Problem::add_convection(Index node, double h_times_area, double t_inf) {
  check_node(node, "add_convection");
  if (!std::isfinite(h_times_area) || h_times_area < 0.0) {
    std::ostringstream os;
    os << "add_convection: hA = " << h_times_area << " W/K must be finite and >= 0";
    fail(os.str());
  }
  if (!std::isfinite(t_inf)) fail("add_convection: ambient temperature must be finite");
  ha_[node] += h_times_area;
  ha_tinf_[node] += h_times_area * t_inf;
  touch();
}

void Problem::clear_boundaries() {
  flux_.setZero();
  ha_.setZero();
  ha_tinf_.setZero();
  touch();
}

void Problem::set_reaction(Reaction reaction) {
  if (reaction.heat.size() != size()) {
    std::ostringstream os;
    os << "set_reaction: size mismatch, heat Q has " << reaction.heat.size() << " entries for " << size()
       << " nodes";
    fail(os.str());
  }
  for (Index i = 0; i < size(); ++i) {
    if (!std::isfinite(reaction.heat[i]) || reaction.heat[i] < 0.0) {
      std::ostringstream os;
      os << "set_reaction: heat of reaction Q[" << i << "] = " << reaction.heat[i] << " J must be finite and >= 0";
      fail(os.str());
    }
  }
  if (!(std::isfinite(reaction.prefactor) && reaction.prefactor > 0.0)) {
    fail("set_reaction: prefactor Z must be finite and > 0 (1/s)");
  }
  if (!(std::isfinite(reaction.activation_temperature) && reaction.activation_temperature > 0.0)) {
    fail("set_reaction: activation temperature E_a/R must be finite and > 0 (K)");
  }
  reaction_ = std::move(reaction);
  has_reaction_ = true;
  touch();
}

void Problem::clear_reaction() {
  reaction_ = Reaction{};
  has_reaction_ = false;
  touch();
}

void Problem::reaction_power(const Eigen::Ref<const Eigen::VectorXd>& temperature,
                             const Eigen::Ref<const Eigen::VectorXd>& progress,
                             Eigen::Ref<Eigen::VectorXd> p) const {
  p.setZero();
  add_reaction_power(temperature, progress, p);
}

// Q_i (1 − λ_i) Z exp(−Θ/T_i) added to p on reacting, non-Dirichlet nodes (λ = 0 when progress is empty).
void Problem::add_reaction_power(const Eigen::Ref<const Eigen::VectorXd>& temperature,
                                 const Eigen::Ref<const Eigen::VectorXd>& progress,
                                 Eigen::Ref<Eigen::VectorXd> p) const {
  if (!has_reaction_) return;
  const bool fresh = progress.size() == 0;
  for (Index i = 0; i < size(); ++i) {
    const double q = reaction_.heat[i];
    if (q == 0.0 || fixed_[static_cast<std::size_t>(i)]) continue;
    const double remaining = fresh ? 1.0 : 1.0 - progress[i];
    p[i] += q * remaining * reaction_.rate_constant(temperature[i]);
  }
}

double Problem::released_heat(const Eigen::VectorXd& progress) const {
  if (!has_reaction_) return 0.0;
  return reaction_.heat.dot(progress);
}

void Problem::check_progress(const Eigen::VectorXd& progress) const {
  if (progress.size() != size()) {
    std::ostringstream os;
    os << "size mismatch: reaction progress has " << progress.size() << " entries for " << size() << " nodes";
    fail(os.str());
  }
  for (Index i = 0; i < size(); ++i) {
    if (!(progress[i] >= 0.0 && progress[i] <= 1.0)) {  // also rejects NaN
      std::ostringstream os;
      os << "reaction progress[" << i << "] = " << progress[i] << " must be in [0, 1]";
      fail(os.str());
    }
  }
}

void Problem::transport_heat_rate(double t, const Eigen::Ref<const Eigen::VectorXd>& temperature,
                                  Eigen::Ref<Eigen::VectorXd> w) const {
  // w = −K T + q(t) + f + hA ⊙ (T_inf − T)   (eq. 37 right-hand side plus boundaries)
  w.noalias() = -(k_ * temperature);
  w += flux_ + ha_tinf_ - ha_.cwiseProduct(temperature);
  if (source_.ramped()) {
    const double s = source_.fraction(t);
    w += (1.0 - s) * source_.q0 + s * source_.q1;
  } else if (source_.active) {
    w += source_.q0;
  }
  for (Index d : dirichlet_nodes_) w[d] = 0.0;
}

void Problem::heat_rate(double t, const Eigen::Ref<const Eigen::VectorXd>& temperature,
                        const Eigen::Ref<const Eigen::VectorXd>& progress, Eigen::Ref<Eigen::VectorXd> w) const {
  transport_heat_rate(t, temperature, w);
  add_reaction_power(temperature, progress, w);
}

void Problem::heat_rate(double t, const Eigen::Ref<const Eigen::VectorXd>& temperature,
                        Eigen::Ref<Eigen::VectorXd> w) const {
  heat_rate(t, temperature, Eigen::VectorXd(), w);
}

void Problem::rhs(double t, const Eigen::Ref<const Eigen::VectorXd>& temperature,
                  Eigen::Ref<Eigen::VectorXd> dTdt) const {
  heat_rate(t, temperature, dTdt);
  dTdt.array() /= mass_.array();
}

double Problem::boundary_and_source_power(double t, const Eigen::VectorXd& temperature) const {
  Eigen::VectorXd p = source(t) + flux_ + ha_tinf_ - ha_.cwiseProduct(temperature);
  for (Index d : dirichlet_nodes_) p[d] = 0.0;
  return p.sum();
}

double Problem::thermal_energy(const Eigen::VectorXd& temperature) const {
  return mass_.dot(temperature);
}

void Problem::apply_dirichlet(Eigen::VectorXd& temperature) const {
  for (Index d : dirichlet_nodes_) temperature[d] = fixed_value_[d];
}

void Problem::check_state(const Eigen::VectorXd& temperature) const {
  if (temperature.size() != size()) {
    std::ostringstream os;
    os << "size mismatch: temperature vector has " << temperature.size() << " entries for " << size()
       << " nodes";
    fail(os.str());
  }
  if (!temperature.allFinite()) fail("temperature vector has a non-finite entry");
}

}  // namespace frictherm::thermal
