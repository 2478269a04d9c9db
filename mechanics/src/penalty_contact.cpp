// Penalty node-to-segment contact (Kakouris et al. 2024 §3.5–3.6, App. A). See penalty_contact.hpp
// and docs/penalty_contact.md.
#include <frictherm/mechanics/penalty_contact.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

TangentialLaw tangential_law_from_string(const std::string& name) {
  if (name == "return_mapping") return TangentialLaw::return_mapping;
  if (name == "incremental") return TangentialLaw::incremental;
  throw std::invalid_argument("unknown tangential law '" + name + "' (expected \"return_mapping\" or \"incremental\")");
}

const char* to_string(TangentialLaw law) {
  return law == TangentialLaw::return_mapping ? "return_mapping" : "incremental";
}

ContactMethod contact_method_from_string(const std::string& name) {
  if (name == "multimaterial") return ContactMethod::multimaterial;
  if (name == "penalty") return ContactMethod::penalty;
  throw std::invalid_argument("unknown contact method '" + name + "' (expected \"multimaterial\" or \"penalty\")");
}

const char* to_string(ContactMethod m) { return m == ContactMethod::multimaterial ? "multimaterial" : "penalty"; }

double default_penalty(double E_master, double E_slave, double h) {
  if (!(h > 0.0) || !std::isfinite(h)) throw std::invalid_argument("default_penalty: cell size must be finite and > 0");
  const auto usable = [](double E) { return E > 0.0 && std::isfinite(E); };
  double E = std::numeric_limits<double>::infinity();
  if (usable(E_master)) E = E_master;
  if (usable(E_slave)) E = std::min(E, E_slave);
  if (!std::isfinite(E))
    throw std::invalid_argument("default_penalty: neither material has a finite Young's modulus > 0; set the penalty");
  return E / h;  // K·40
}

SegmentProjection project_onto_segment(const Vec<2>& xs, const Vec<2>& x1, const Vec<2>& x2) {
  SegmentProjection p;
  const Vec<2> d = x2 - x1;
  p.length = d.norm();
  if (!(p.length > 0.0)) {  // degenerate segment: a point
    p.distance = (xs - x1).norm();
    return p;
  }
  p.e_tan = d / p.length;
  p.e_nor = Vec<2>(p.e_tan[1], -p.e_tan[0]);  // outward for material on the left (counter-clockwise loop)
  const Vec<2> r = xs - x1;
  p.beta = r.dot(p.e_tan) / p.length;  // K·30
  p.gap = r.dot(p.e_nor);              // K·28: (x_s − x_s̄)·e_nor, x_s̄ = x1 + β l e_tan
  const double bc = std::clamp(p.beta, 0.0, 1.0);
  p.distance = (xs - (x1 + bc * d)).norm();
  return p;
}

TangentialUpdate update_tangential(TangentialLaw law, double t_old, double dg, double eps_t, double cap) {
  TangentialUpdate u;
  cap = std::max(cap, 0.0);
  if (law == TangentialLaw::return_mapping) {
    const double trial = t_old - eps_t * dg;  // elastic predictor
    if (std::fabs(trial) <= cap) {
      u.traction = trial;
      return u;
    }
    u.sliding = true;
    u.traction = std::copysign(cap, trial);          // return to the Coulomb cap
    u.slip = dg + (u.traction - t_old) / eps_t;      // Δg_T minus its elastic part −(t − t_old)/ε_T
    u.dissipation = std::max(0.0, -u.traction * u.slip);
    return u;
  }
  // K·32 as printed: the trial uses this step's increment only.
  const double trial = eps_t * std::fabs(dg);
  if (trial <= cap) {
    u.traction = -eps_t * dg;
  } else {
    u.sliding = true;
    u.traction = -std::copysign(cap, dg);
    u.slip = dg;
  }
  u.dissipation = -u.traction * dg;  // nothing is stored: all the tangential work is dissipated
  return u;
}

template <int Dim>
PenaltyContact<Dim>::PenaltyContact(const Grid<Dim>& grid, const PenaltyOptions& options) : grid_(grid), opt_(options) {
  if (!(options.thickness > 0.0) || !std::isfinite(options.thickness))
    throw std::invalid_argument("penalty contact: thickness must be finite and > 0");
}

template <int Dim>
int PenaltyContact<Dim>::add_pair(const PenaltyPairSettings& s) {
  if constexpr (Dim != 2) {
    (void)s;
    throw std::invalid_argument("penalty contact: 3D (triangulated surfaces) is not implemented");
  } else {
    const auto bad = [](const std::string& what) { throw std::invalid_argument("penalty contact pair: " + what); };
    if (s.master < 0 || s.slave < 0) bad("master and slave field ids must be >= 0");
    if (s.master == s.slave) bad("master and slave must be different fields (self-contact is not supported)");
    if (!(s.mu >= 0.0) || !std::isfinite(s.mu)) bad("mu must be finite and >= 0");
    if (!(s.normal_penalty > 0.0) || !std::isfinite(s.normal_penalty)) bad("normal_penalty must be finite and > 0 (N/m^3)");
    if (!(s.tangential_penalty >= 0.0) || !std::isfinite(s.tangential_penalty))
      bad("tangential_penalty must be finite and >= 0 (0: equal to normal_penalty)");
    if (!(s.search_radius >= 0.0) || !std::isfinite(s.search_radius)) bad("search_radius must be finite and >= 0");
    pairs_.push_back(s);
    if (pairs_.back().tangential_penalty == 0.0) pairs_.back().tangential_penalty = s.normal_penalty;
    if (pairs_.back().search_radius == 0.0) pairs_.back().search_radius = grid_.min_cell_size();
    history_.emplace_back();
    books_.emplace_back();
    return static_cast<int>(pairs_.size()) - 1;
  }
}

template <int Dim>
double PenaltyContact<Dim>::total_heat() const {
  double q = 0.0;
  for (const auto& b : books_) q += b.heat_total;
  return q;
}

template <int Dim>
void PenaltyContact<Dim>::reset_history() {
  for (auto& h : history_) {
    std::fill(h.segment.begin(), h.segment.end(), -1);
    std::fill(h.traction.begin(), h.traction.end(), 0.0);
  }
}

template <int Dim>
void PenaltyContact<Dim>::prepare(const BoundaryPoints<Dim>& points) {
  const std::size_t n = points.size();
  for (int i : touched_) {
    force_[static_cast<std::size_t>(i)].setZero();
    heat_[static_cast<std::size_t>(i)] = 0.0;
    touched_flag_[static_cast<std::size_t>(i)] = 0;
  }
  touched_.clear();
  force_.resize(n, Vec<Dim>::Zero());
  heat_.resize(n, 0.0);
  touched_flag_.resize(n, 0);
  for (auto& h : history_) {
    h.segment.resize(n, -1);
    h.beta.resize(n, 0.0);
    h.length.resize(n, 0.0);
    h.traction.resize(n, 0.0);
    h.stamp.resize(n, 0);
  }
  ++stamp_;
  records_.clear();
  for (auto& b : books_) {
    b.active = b.sliding = 0;
    b.normal_force = b.tangential_force = b.heat_step = 0.0;
    b.force_on_slave.setZero();
  }
  stored_energy_ = 0.0;
}

template <int Dim>
void PenaltyContact<Dim>::add_point_force(int i, const Vec<Dim>& f) {
  const auto k = static_cast<std::size_t>(i);
  if (!touched_flag_[k]) {
    touched_flag_[k] = 1;
    touched_.push_back(i);
  }
  force_[k] += f;
}

template <int Dim>
void PenaltyContact<Dim>::add_point_heat(int i, double q) {
  add_point_force(i, Vec<Dim>::Zero());  // marks it touched
  heat_[static_cast<std::size_t>(i)] += q;
}

namespace {
std::uint64_t bin_key(long ix, long iy) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(ix + (1L << 30))) << 32) |
         static_cast<std::uint32_t>(iy + (1L << 30));
}
}  // namespace

template <int Dim>
void PenaltyContact<Dim>::build_segment_bins(int master, const BoundaryPoints<Dim>& points, double radius) {
  bins_.clear();
  bin_size_ = radius;
  const Vec<Dim>& lo = grid_.lo();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points.field[i] != master) continue;
    const Vec<Dim>& a = points.position[i];
    const Vec<Dim>& b = points.position[static_cast<std::size_t>(points.next[i])];
    const long x0 = static_cast<long>(std::floor((std::min(a[0], b[0]) - radius - lo[0]) / bin_size_));
    const long x1 = static_cast<long>(std::floor((std::max(a[0], b[0]) + radius - lo[0]) / bin_size_));
    const long y0 = static_cast<long>(std::floor((std::min(a[1], b[1]) - radius - lo[1]) / bin_size_));
    const long y1 = static_cast<long>(std::floor((std::max(a[1], b[1]) + radius - lo[1]) / bin_size_));
    for (long ix = x0; ix <= x1; ++ix)
      for (long iy = y0; iy <= y1; ++iy) bins_.emplace_back(bin_key(ix, iy), static_cast<int>(i));
  }
  std::sort(bins_.begin(), bins_.end());
}

template <int Dim>
void PenaltyContact<Dim>::resolve_pair(std::size_t k, const BoundaryPoints<Dim>& points) {
  if constexpr (Dim != 2) {
    (void)k, (void)points;
  } else {
    const PenaltyPairSettings& P = pairs_[k];
    History& H = history_[k];
    PenaltyPairBooks& B = books_[k];
    const double radius = P.search_radius, eps_n = P.normal_penalty, eps_t = P.tangential_penalty;
    build_segment_bins(P.master, points, radius);
    const auto pos = [&](int i) -> const Vec<2>& { return points.position[static_cast<std::size_t>(i)]; };
    const Vec<2>& lo = grid_.lo();

    for (int s : candidates_) {
      const auto si = static_cast<std::size_t>(s);
      const Vec<2>& xs = pos(s);
      const std::uint64_t key = bin_key(static_cast<long>(std::floor((xs[0] - lo[0]) / bin_size_)),
                                        static_cast<long>(std::floor((xs[1] - lo[1]) / bin_size_)));
      const auto range = std::equal_range(bins_.begin(), bins_.end(), std::make_pair(key, std::numeric_limits<int>::min()),
                                           [](const auto& a, const auto& b) { return a.first < b.first; });
      // Step 2–3: the master segment nearest to the point (closest-point distance, β clamped to the
      // segment); contact if the point projects onto it (0 ≤ β ≤ 1, to a round-off tolerance) and
      // has penetrated it. Taking the nearest segment, penetrated or not, keeps a point lying on one
      // face of a convex master corner from "penetrating" the neighbouring face through its
      // extension, and the tolerance keeps a point level with a vertex between two collinear
      // segments (β = 1 + ε on one, −ε on the other) on the face.
      constexpr double beta_tol = 1e-6;
      int seg = -1;
      SegmentProjection best;
      double nearest = std::numeric_limits<double>::infinity();  // over every segment in reach
      for (auto it = range.first; it != range.second; ++it) {
        const int j = it->second;
        const SegmentProjection pr = project_onto_segment(xs, pos(j), pos(points.next[static_cast<std::size_t>(j)]));
        if (!(pr.distance < radius) || !(pr.length > 0.0)) continue;
        nearest = std::min(nearest, pr.distance);
        if (pr.beta < -beta_tol || pr.beta > 1.0 + beta_tol) continue;
        if (seg < 0 || pr.distance < best.distance) {
          seg = j;
          best = pr;
        }
      }
      const double projected_distance = seg >= 0 ? best.distance : std::numeric_limits<double>::infinity();
      // A face is the nearest feature unless a vertex (out-of-range projection) is nearer.
      if (seg >= 0 && (!(best.gap < 0.0) || best.distance > nearest + 1e-9 * radius)) seg = -1;
      if (seg >= 0) best.beta = std::clamp(best.beta, 0.0, 1.0);
      bool vertex = false;
      if (seg < 0) {
        // Reflex master vertex v: inside both neighbouring half-planes, beyond the end of the first
        // segment and before the start of the second: the closest master point is v itself.
        for (auto it = range.first; it != range.second && seg < 0; ++it) {
          const int j = it->second;
          const int v = points.next[static_cast<std::size_t>(j)];
          const SegmentProjection p1 = project_onto_segment(xs, pos(j), pos(v));
          if (!(p1.gap < 0.0 && p1.beta > 1.0 && p1.distance < radius)) continue;
          const SegmentProjection p2 = project_onto_segment(xs, pos(v), pos(points.next[static_cast<std::size_t>(v)]));
          if (!(p2.gap < 0.0 && p2.beta < 0.0)) continue;
          const Vec<2> r = pos(v) - xs;
          const double d = r.norm();
          if (!(d > 0.0) || !(d < projected_distance)) continue;
          seg = v;
          vertex = true;
          best = p2;
          best.beta = 0.0;
          best.gap = -d;
          best.e_nor = r / d;  // from x_s towards the vertex: out of the master
          best.e_tan = Vec<2>(-best.e_nor[1], best.e_nor[0]);
        }
      }
      if (seg < 0) continue;

      // Slip increment K·29, carried over to a neighbouring segment; a new contact starts at zero.
      double dg = 0.0, t_old = 0.0;
      const int old = H.segment[si];
      if (!vertex && old >= 0) {
        const double b_old = H.beta[si], l_old = H.length[si];
        bool known = true;
        if (old == seg)
          dg = l_old * (best.beta - b_old);
        else if (points.next[static_cast<std::size_t>(old)] == seg)
          dg = (1.0 - b_old) * l_old + best.beta * best.length;
        else if (points.next[static_cast<std::size_t>(seg)] == old)
          dg = -(b_old * l_old + (1.0 - best.beta) * best.length);
        else
          known = false;
        if (known) t_old = H.traction[si];
      }
      const double tN = eps_n * (-best.gap);  // K·31 (magnitude)
      const TangentialUpdate tu =
          vertex ? TangentialUpdate{} : update_tangential(P.law, t_old, dg, eps_t, P.mu * tN);

      const double A = points.tributary_length(si) * opt_.thickness;
      const double fN = tN * A, fT = tu.traction * A;
      const int a = seg, b = points.next[static_cast<std::size_t>(seg)];
      const double beta = best.beta;
      const Vec<2> fs = fN * best.e_nor + fT * best.e_tan;  // K·33–34 on the slave point
      Vec<2> fa = -(1.0 - beta) * fs, fb = -beta * fs;
      if (P.paper_correction_terms && best.length > 0.0) {  // K·51–52: (g/l) P and (Δg_T/l) Q
        const Vec<2> cn = (eps_n * best.gap * best.gap * A / best.length) * best.e_nor;
        const Vec<2> ct = (fT * dg / best.length) * best.e_tan;
        fa += -cn + ct;
        fb += cn - ct;
      }
      add_point_force(s, fs);
      add_point_force(a, fa);
      add_point_force(b, fb);

      const double q = tu.dissipation * A;
      if (q > 0.0) {  // half where the slave is, half on the segment (1−β) : β
        add_point_heat(s, 0.5 * q);
        add_point_heat(a, 0.5 * q * (1.0 - beta));
        add_point_heat(b, 0.5 * q * beta);
      }
      stored_energy_ += A * (0.5 * eps_n * best.gap * best.gap +
                             (P.law == TangentialLaw::return_mapping ? 0.5 * tu.traction * tu.traction / eps_t : 0.0));

      PenaltyContactRecord r;
      r.pair = static_cast<int>(k);
      r.slave = s;
      r.segment = seg;
      r.vertex = vertex;
      r.beta = beta;
      r.gap = best.gap;
      r.slip_increment = dg;
      r.slip = tu.slip;
      r.area = A;
      r.normal_force = fN;
      r.tangential_force = fT;
      r.heat = q;
      r.sliding = tu.sliding;
      r.e_nor = best.e_nor;
      r.e_tan = best.e_tan;
      records_.push_back(r);

      ++B.active;
      if (tu.sliding) ++B.sliding;
      B.normal_force += fN;
      B.tangential_force += fT;
      B.heat_step += q;
      B.force_on_slave += fs;

      H.segment[si] = vertex ? -2 : seg;  // −2: in contact at a vertex (history restarts)
      H.beta[si] = beta;
      H.length[si] = best.length;
      H.traction[si] = tu.traction;
      H.stamp[si] = stamp_;
    }
    B.heat_total += B.heat_step;
    // Slave points not in contact this step lose their history.
    for (std::size_t i = 0; i < points.size(); ++i)
      if (points.field[i] == P.slave && H.stamp[i] != stamp_) {
        H.segment[i] = -1;
        H.traction[i] = 0.0;
      }
  }
}

template class PenaltyContact<2>;
template class PenaltyContact<3>;

}  // namespace frictherm::mechanics
