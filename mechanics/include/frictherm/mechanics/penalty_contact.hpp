#pragma once
// Penalty node-to-segment contact on boundary material points (Kakouris, Chatzis & Triantafyllou 2024
// §3.5–3.6 and App. A, "K·k" = their eq. k; shared/seed002-digest.md §3–4; docs/penalty_contact.md).
//
// Per step and per field pair (master, slave), at the positions of the step's start:
//  1. shared nodes: only slave points whose own stencil touches a node where the master field has
//     material are candidates (K §3.5 step 1; the caller supplies the test, see compute());
//  2. distance check: master segments within search_radius (default Δh) of the slave point (step 2);
//  3. closest-point projection onto the segment (K·28, 30): β ∈ [0, 1], normal gap g_N, penetration
//     g_N < 0 (the normal is the master's OUTWARD normal, digest §4 erratum). Of several segments the
//     one with the smallest |g_N|; at a reflex master vertex (no segment projects) the vertex itself.
// Forces, per unit boundary area (tractions) times the slave point's tributary area A_s = l_trib t:
//  normal     t_N = ε_N ⟨−g_N⟩                                         (K·31)
//  tangential slip increment Δg_T = l_ms^old (β − β^old)                (K·29), continued across a
//             neighbouring segment, zero for a new contact;
//    return_mapping (default): trial t* = t_T^old − ε_T Δg_T, |t_T| ≤ μ t_N (elastic spring + Coulomb
//             cap, slip increment (|t*| − μ t_N)/ε_T);
//    incremental (K·32 as printed): t_T = −sign(Δg_T) min(μ t_N, ε_T |Δg_T|), no tangential spring.
//  point forces f_s = A_s (t_N e_N + t_T e_T) on the slave, −(1−β) f_s and −β f_s on the segment ends
//  (K·33–34 with the classical split; the (g/l) P and (Δg_T/l) Q terms of K·51–52 are optional);
//  frictional heat = work of t_T on the dissipative (slip) part of Δg_T, times A_s, per pair.
// The point forces are mapped to grid nodes through each point's own weights (K·36, scatter_forces).
#include <frictherm/mechanics/boundary_points.hpp>
#include <frictherm/mechanics/contact.hpp>  // TangentialLaw

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace frictherm::mechanics {

/// Default penalty (K·40): ε = E/Δh (N/m³). For two materials the smaller modulus (a rigid partner,
/// E = +inf or 0 meaning "unknown", does not count); throws std::invalid_argument if neither E is
/// finite and positive or Δh ≤ 0.
double default_penalty(double E_master, double E_slave, double h);

// ---- kinematics and the friction update (free functions: unit-testable) ---------------------------
/// Projection of slave point x_s onto master segment x1 → x2 (K·28, 30). β unclamped; gap measured
/// along the master's outward normal e_nor = (t_y, −t_x), negative when penetrated.
struct SegmentProjection {
  double beta = 0.0;
  double gap = 0.0;
  double length = 0.0;
  double distance = 0.0;  // from x_s to the closest point of the (closed) segment
  Vec<2> e_tan = Vec<2>::Zero();
  Vec<2> e_nor = Vec<2>::Zero();
};
SegmentProjection project_onto_segment(const Vec<2>& xs, const Vec<2>& x1, const Vec<2>& x2);

struct TangentialUpdate {
  double traction = 0.0;     // t_T along e_T (Pa); force on the slave point = A_s t_T e_T
  double slip = 0.0;         // dissipative (slip) part of Δg_T (m), same sign as Δg_T; 0 when sticking
  double dissipation = 0.0;  // −t_T × slip (J/m²) ≥ 0, or for `incremental` −t_T Δg_T
  bool sliding = false;
};
/// One step of the tangential law for slip increment dg (m), previous traction t_old (Pa), penalty
/// eps_t (N/m³) and Coulomb cap μ t_N (Pa). Stick exactly at the cap (|t*| ≤ cap).
TangentialUpdate update_tangential(TangentialLaw law, double t_old, double dg, double eps_t, double cap);

// ---- settings, records and books ----------------------------------------------------------------
struct PenaltyPairSettings {
  int master = -1, slave = -1;        // field ids; the slave's points are tested against the master's segments
  double mu = 0.0;                    // Coulomb coefficient μ_f (K·9, 32)
  double normal_penalty = 0.0;        // ε_N (N/m³); must be > 0 (use default_penalty, K·40)
  double tangential_penalty = 0.0;    // ε_T (N/m³); 0: equal to ε_N (K·40)
  TangentialLaw law = TangentialLaw::return_mapping;
  double search_radius = 0.0;         // step 2 distance (m); 0: the grid's smallest cell size Δh
  bool paper_correction_terms = false;  // add the (g_N/l) P and (Δg_T/l) Q terms of K·51–52
};

struct PenaltyOptions {
  double thickness = 1.0;  // 2D out-of-plane thickness t (m): A_s = l_trib t
};

/// One active slave point – master segment pair of the last compute().
struct PenaltyContactRecord {
  int pair = -1;
  int slave = -1;        // boundary point
  int segment = -1;      // master segment (starts at this point); −1 never
  bool vertex = false;   // reflex-vertex contact (frictionless), at the segment's first point
  double beta = 0.0;
  double gap = 0.0;      // g_N (m), < 0
  double slip_increment = 0.0;  // Δg_T (m)
  double slip = 0.0;     // dissipative part (m)
  double area = 0.0;     // A_s (m²)
  double normal_force = 0.0;      // A_s t_N ≥ 0 (N)
  double tangential_force = 0.0;  // A_s t_T (N), along e_tan
  double heat = 0.0;     // J
  bool sliding = false;
  Vec<2> e_nor = Vec<2>::Zero(), e_tan = Vec<2>::Zero();
};

struct PenaltyPairBooks {
  long active = 0, sliding = 0;         // last step
  double normal_force = 0.0;            // Σ A_s t_N, last step (N)
  double tangential_force = 0.0;        // Σ A_s t_T, last step (N, signed along each e_tan)
  double heat_step = 0.0;               // last step (J)
  double heat_total = 0.0;              // since the start (J)
  Vec<2> force_on_slave = Vec<2>::Zero();  // Σ of the forces on the slave field, last step (N)
};

/// Penalty contact between fields of one BoundaryPoints set. Keeps the per-pair slip history
/// (segment, β, l_ms, t_T per slave point) between steps; compute() allocates only while the point
/// count or the number of contacts grows.
template <int Dim>
class PenaltyContact {
 public:
  PenaltyContact(const Grid<Dim>& grid, const PenaltyOptions& options = {});

  /// Adds a master/slave field pair (one pass: slave points against master segments); returns its
  /// index. Throws std::invalid_argument naming the bad setting (equal or negative fields, μ < 0,
  /// ε_N ≤ 0, ε_T < 0, search radius < 0) and for Dim = 3 (not implemented).
  int add_pair(const PenaltyPairSettings& settings);
  std::size_t pair_count() const { return pairs_.size(); }
  const PenaltyPairSettings& pair(std::size_t k) const { return pairs_.at(k); }
  const PenaltyOptions& options() const { return opt_; }

  /// Detection and penalty forces at the current positions (call once per step: the slip increment
  /// is measured from the previous call). `is_candidate(pair, point)` is step 1 (see touches_field
  /// below). Fills point_force(), point_heat(), contacts() and the pair books.
  template <class Candidate>
  void compute(const BoundaryPoints<Dim>& points, Candidate&& is_candidate) {
    prepare(points);
    for (std::size_t k = 0; k < pairs_.size(); ++k) {
      candidates_.clear();
      const int slave = pairs_[k].slave;
      for (std::size_t i = 0; i < points.size(); ++i)
        if (points.field[i] == slave && is_candidate(static_cast<int>(k), static_cast<int>(i)))
          candidates_.push_back(static_cast<int>(i));
      resolve_pair(k, points);
    }
  }
  /// Same, every slave point a candidate (step 1 skipped: rigid bodies, standalone use).
  void compute(const BoundaryPoints<Dim>& points) {
    compute(points, [](int, int) { return true; });
  }

  /// Force on each boundary point from the last compute() (N); Σ = 0 to round-off.
  const std::vector<Vec<Dim>>& point_force() const { return force_; }
  /// Frictional heat assigned to each boundary point in the last compute() (J): half at the slave,
  /// half at the segment ends split (1−β) : β.
  const std::vector<double>& point_heat() const { return heat_; }
  const std::vector<PenaltyContactRecord>& contacts() const { return records_; }
  const PenaltyPairBooks& books(std::size_t k) const { return books_.at(k); }
  /// Σ over pairs of the heat since the start (J).
  double total_heat() const;
  /// Energy stored in the penalty springs now: Σ A_s (ε_N g_N²/2 + t_T²/(2 ε_T)) (J).
  double stored_energy() const { return stored_energy_; }
  /// Forgets all slip history (e.g. after the boundary points were rebuilt).
  void reset_history();

  /// Adds each point's force to the nodal force of its field: F_DI += S_I(x_k) f_k (K·36), with
  /// weights(field, x, half_size, visit(slot, node, S)) as in GridWeights.
  template <class Weights>
  void scatter_forces(const BoundaryPoints<Dim>& points, const Weights& weights,
                      std::vector<Vec<Dim>>& nodal_force) const {
    for (int i : touched_)
      weights(points.field[i], points.position[i], points.half_size[i],
              [&](int slot, int, double S) { nodal_force[static_cast<std::size_t>(slot)] += S * force_[i]; });
  }
  /// Gershgorin bound of the squared frequency of the penalty springs of the last compute() on the
  /// grid (docs/penalty_contact.md, "Stability"), stored for frequency_bound_squared():
  /// ω_p² ≤ max_I Σ_c k_c |B_cI| ‖B_c‖₁ / m_I. B_c maps nodal velocities to contact c's gap rate: the
  /// weights S_I of the slave point, −(1−β) S_I and −β S_I of the segment's ends, summed per node;
  /// k_c = A_s ε_N, or A_s max(ε_N, ε_T) while a return-mapping contact sticks on its tangential
  /// spring (the two springs are orthogonal, so the larger bounds the pair). m_I = slot_mass; nodes
  /// at or below min_mass get no velocity and are skipped. Same weights as scatter_forces.
  template <class Weights>
  double update_frequency_bound(const BoundaryPoints<Dim>& points, const Weights& weights,
                                const std::vector<double>& slot_mass, double min_mass) {
    node_load_.clear();
    for (const PenaltyContactRecord& r : records_) {
      const PenaltyPairSettings& P = pairs_[static_cast<std::size_t>(r.pair)];
      const bool spring = !r.vertex && !r.sliding && P.mu > 0.0 && P.law == TangentialLaw::return_mapping;
      const double k = r.area * (spring ? std::max(P.normal_penalty, P.tangential_penalty) : P.normal_penalty);
      row_.clear();
      const int ends[3] = {r.slave, r.segment, points.next[static_cast<std::size_t>(r.segment)]};
      const double scale[3] = {1.0, -(1.0 - r.beta), -r.beta};
      for (int e = 0; e < 3; ++e)
        if (scale[e] != 0.0)
          weights(points.field[static_cast<std::size_t>(ends[e])], points.position[static_cast<std::size_t>(ends[e])],
                  points.half_size[static_cast<std::size_t>(ends[e])],
                  [&](int slot, int, double S) { row_.emplace_back(slot, scale[e] * S); });
      std::sort(row_.begin(), row_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      std::size_t m = 0;  // merge the two ends' entries on shared nodes
      for (std::size_t q = 0; q < row_.size(); ++q) {
        if (m > 0 && row_[m - 1].first == row_[q].first) row_[m - 1].second += row_[q].second;
        else row_[m++] = row_[q];
      }
      row_.resize(m);
      double norm1 = 0.0;
      for (const auto& e : row_) norm1 += std::fabs(e.second);
      for (const auto& e : row_) node_load_.emplace_back(e.first, k * std::fabs(e.second) * norm1);
    }
    std::sort(node_load_.begin(), node_load_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    frequency_bound2_ = 0.0;
    for (std::size_t q = 0; q < node_load_.size();) {
      const int slot = node_load_[q].first;
      double load = 0.0;
      for (; q < node_load_.size() && node_load_[q].first == slot; ++q) load += node_load_[q].second;
      const double mI = slot_mass[static_cast<std::size_t>(slot)];
      if (mI > min_mass) frequency_bound2_ = std::max(frequency_bound2_, load / mI);
    }
    return frequency_bound2_;
  }
  /// Checkpoints (Simulation::visit_state): calls v(name, member) for what the next compute() and the
  /// next time step read: the per-pair slip histories (segment, β, l_ms, t_T, stamp per point), the
  /// call counter, the spring energy and the frequency bound; and what the series report of the last
  /// step (the pair books, the contact records). Visitors with `reading` true restore them (the pairs
  /// must have been added as when written).
  template <class Visitor>
  void visit_state(Visitor&& v) {
    constexpr bool reading = std::decay_t<Visitor>::reading;
    for (std::size_t k = 0; k < history_.size(); ++k) {
      const std::string p = "penalty/pair" + std::to_string(k) + "/";
      History& h = history_[k];
      v((p + "segment").c_str(), h.segment);
      v((p + "beta").c_str(), h.beta);
      v((p + "length").c_str(), h.length);
      v((p + "traction").c_str(), h.traction);
      v((p + "stamp").c_str(), h.stamp);
      PenaltyPairBooks& b = books_[k];
      std::vector<double> books{static_cast<double>(b.active), static_cast<double>(b.sliding), b.normal_force,
                                b.tangential_force, b.heat_step, b.heat_total, b.force_on_slave[0],
                                b.force_on_slave[1]};
      v((p + "books").c_str(), books);
      if constexpr (reading) {
        if (books.size() != 8) throw std::runtime_error("checkpoint: penalty books need 8 values");
        b.active = static_cast<long>(books[0]);
        b.sliding = static_cast<long>(books[1]);
        b.normal_force = books[2], b.tangential_force = books[3], b.heat_step = books[4], b.heat_total = books[5];
        b.force_on_slave = Vec<2>(books[6], books[7]);
      }
    }
    constexpr std::size_t R = 17;  // values per contact record
    std::vector<double> rec;
    if constexpr (!reading)
      for (const PenaltyContactRecord& r : records_)
        rec.insert(rec.end(), {double(r.pair), double(r.slave), double(r.segment), double(r.vertex), r.beta, r.gap,
                               r.slip_increment, r.slip, r.area, r.normal_force, r.tangential_force, r.heat,
                               double(r.sliding), r.e_nor[0], r.e_nor[1], r.e_tan[0], r.e_tan[1]});
    v("penalty/records", rec);
    if constexpr (reading) {
      if (rec.size() % R != 0) throw std::runtime_error("checkpoint: penalty records need 17 values each");
      records_.assign(rec.size() / R, PenaltyContactRecord{});
      for (std::size_t i = 0; i < records_.size(); ++i) {
        const double* x = &rec[i * R];
        PenaltyContactRecord& r = records_[i];
        r.pair = int(x[0]), r.slave = int(x[1]), r.segment = int(x[2]), r.vertex = x[3] != 0.0;
        r.beta = x[4], r.gap = x[5], r.slip_increment = x[6], r.slip = x[7], r.area = x[8];
        r.normal_force = x[9], r.tangential_force = x[10], r.heat = x[11], r.sliding = x[12] != 0.0;
        r.e_nor = Vec<2>(x[13], x[14]), r.e_tan = Vec<2>(x[15], x[16]);
      }
    }
    std::vector<std::uint64_t> stamp{stamp_};
    v("penalty/stamp", stamp);
    if constexpr (reading) stamp_ = stamp.at(0);
    v("penalty/stored_energy", stored_energy_);
    v("penalty/frequency_bound2", frequency_bound2_);
  }
  /// The bound of the last update_frequency_bound() (1/s²); 0 before any, or without contacts.
  double frequency_bound_squared() const { return frequency_bound2_; }

  /// Adds each point's heat to grid nodes (J per grid node), same weights.
  template <class Weights>
  void scatter_heat(const BoundaryPoints<Dim>& points, const Weights& weights, std::vector<double>& nodal_heat) const {
    for (int i : touched_)
      if (heat_[i] != 0.0)
        weights(points.field[i], points.position[i], points.half_size[i],
                [&](int, int node, double S) { nodal_heat[static_cast<std::size_t>(node)] += S * heat_[i]; });
  }

 private:
  struct History {  // per pair, per boundary point (only slave points used)
    std::vector<std::int32_t> segment;  // −1: not in contact last step
    std::vector<double> beta, length, traction;
    std::vector<std::uint64_t> stamp;   // compute() call that last found the point in contact
  };
  void prepare(const BoundaryPoints<Dim>& points);
  void resolve_pair(std::size_t k, const BoundaryPoints<Dim>& points);
  void build_segment_bins(int master, const BoundaryPoints<Dim>& points, double radius);
  void add_point_force(int i, const Vec<Dim>& f);
  void add_point_heat(int i, double q);

  Grid<Dim> grid_;
  PenaltyOptions opt_;
  std::vector<PenaltyPairSettings> pairs_;
  std::vector<History> history_;
  std::vector<PenaltyPairBooks> books_;
  std::vector<Vec<Dim>> force_;
  std::vector<double> heat_;
  std::vector<std::uint8_t> touched_flag_;
  std::vector<int> touched_;
  std::vector<int> candidates_;
  std::vector<PenaltyContactRecord> records_;
  std::vector<std::pair<std::uint64_t, int>> bins_;  // (cell key, master segment), sorted
  double bin_size_ = 1.0;
  double stored_energy_ = 0.0;
  std::uint64_t stamp_ = 0;
  std::vector<std::pair<int, double>> row_, node_load_;  // update_frequency_bound scratch: (slot, value)
  double frequency_bound2_ = 0.0;
};

/// Step 1 helper (K §3.5, eq. 27): true if any node of point i's own stencil (via `weights`) is one
/// where `present(field, grid_node)` says the pair's master field has material.
template <int Dim, class Weights, class Present>
bool touches_field(const BoundaryPoints<Dim>& points, int i, const Weights& weights, int master, Present&& present) {
  bool hit = false;
  weights(points.field[static_cast<std::size_t>(i)], points.position[static_cast<std::size_t>(i)],
          points.half_size[static_cast<std::size_t>(i)], [&](int, int node, double) {
            if (!hit && present(master, node)) hit = true;
          });
  return hit;
}

extern template class PenaltyContact<2>;
extern template class PenaltyContact<3>;

}  // namespace frictherm::mechanics
