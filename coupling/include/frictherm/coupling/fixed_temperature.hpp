#pragma once
// Fixed-temperature faces of the thermal grid (scene key thermal.fixed_temperature): which thermal
// unknowns they hold, written once for the serial Coupler (coupler.cpp: Dirichlet nodes of the
// assembled problem and of the matrix-free sub-steps) and the decomposed DecomposedHeat
// (decomposed_heat.cpp: the owned unknowns of each rank).
#include <array>
#include <cstddef>
#include <vector>

namespace frictherm::coupling {

/// A node held at a fixed temperature (an unknown on a fixed-temperature face).
struct FixedNode {
  int unknown = 0;
  double temperature = 0.0;  // K
};

/// A grid face held at a fixed temperature: every thermal unknown on it is a Dirichlet node.
struct FixedTemperatureFace {
  int axis = 0;
  bool upper = false;
  double temperature = 293.15;  // K
};

/// The nodes the faces hold among `count` nodes: node u lies on a face when its lattice index along
/// the face's axis (`lattice_along(u, axis)`, 0 at the grid's lower bound) is 0 for a lower face or
/// cells[axis] for an upper one. Calls emit(u, T) face by face in the faces' order, nodes in order
/// within a face: a node on two faces (an edge or a corner) is emitted for each, and the later face's
/// temperature holds where the caller overwrites in this order (Problem::set_dirichlet, the sub-steps'
/// reset, a per-node table).
template <class Cells, class LatticeAlong, class Emit>
void for_each_fixed_node(const std::vector<FixedTemperatureFace>& faces, const Cells& cells, std::size_t count,
                         LatticeAlong&& lattice_along, Emit&& emit) {
  for (const FixedTemperatureFace& f : faces) {
    const int face_index = f.upper ? static_cast<int>(cells[static_cast<std::size_t>(f.axis)]) : 0;
    for (std::size_t u = 0; u < count; ++u)
      if (lattice_along(u, f.axis) == face_index) emit(u, f.temperature);
  }
}

/// The map back at held nodes. The increment rule T_p += Σ_i S_ip ΔT_i (design §4) gives a held node
/// ΔT_i = T_face − T_i, with T_i = Σ_p m_p C_p S_ip T_p / M_i gathered from the particles: a one-sided
/// mean, taken about the particles' weighted centre, which lies inside the body and not on the face.
/// Every window re-adds that lag, so the particles next to the face settle beyond its temperature by
/// about half a cell of the gradient (310.5 K beside a 310 K face with 2 K per cell; 322.9 K beside a
/// 290/310 K corner). A held node instead pulls each of its particles towards the face's temperature
/// carried to the particle along the gradient normal to the face:
///
///   T_p += Σ_free S_ip ΔT_i + Σ_held S_ip (T_face + g_i·(x_p − x_i) − T_p),
///
/// g_i one-sided from the node one cell inward along each face through node i, after the window (0
/// where that node is no unknown, and along the face). A linear field is then a fixed point (the
/// particles on the exact profile gather exactly at free nodes and are not pulled at held ones), a
/// particle is pulled towards a value between the face's and its inward neighbour's, and the heat a
/// held node gives is M_i (T_face + g_i·(x̄_i − x_i) − T_i) with x̄_i its particles' weighted centre.
/// The heat the faces give the particles is booked with the nodal energy change in place of the held
/// nodes' M_i ΔT_i (the map backs return it). Valid where the window starts from the gathered T_i
/// (every loading window); the continuation's later intervals carry the nodal T_i and keep the
/// increment (0 at held nodes).
template <int Dim>
class FacePull {
 public:
  /// A held unknown: its face temperature, the gradient g (K/m) and the node's position x_i (m).
  struct Held {
    int unknown = 0;
    double temperature = 0.0;
    std::array<double, Dim> gradient{};
    std::array<double, Dim> position{};
  };
  /// A particle's sums over its held unknowns: Σ S_ip, Σ S_ip (T_face − g_i·x_i), Σ S_ip g_i.
  struct Sums {
    double weight = 0.0;
    double offset = 0.0;
    std::array<double, Dim> gradient{};
  };
  /// Off (the plain increment) without held nodes. `end`: the nodal end temperatures of the sub-grid
  /// blend (null without it).
  void build(const double* delta, const double* end, std::size_t count, const std::vector<Held>* held) {
    active_ = held && !held->empty();
    if (!active_) return;
    increment_.assign(delta, delta + count);
    if (end) end_.assign(end, end + count);
    offset_.assign(count, 0.0);
    held_.assign(count, 0);
    gradient_.assign(count * Dim, 0.0);
    for (const Held& h : *held) {
      const auto u = static_cast<std::size_t>(h.unknown);
      for (int a = 0; a < Dim; ++a) gradient_[u * Dim + static_cast<std::size_t>(a)] = h.gradient[static_cast<std::size_t>(a)];
      increment_[u] = 0.0;  // the pull replaces the increment
      if (end) end_[u] = 0.0;  // and the blend's target (blend_target)
      offset_[u] = offset(h);
      held_[u] = 1;
    }
  }
  /// T_face − g·x_i of a held unknown.
  static double offset(const Held& h) {
    double v = h.temperature;
    for (int a = 0; a < Dim; ++a) v -= h.gradient[static_cast<std::size_t>(a)] * h.position[static_cast<std::size_t>(a)];
    return v;
  }
  bool active() const { return active_; }
  /// The increments to weight with S_ip: ΔT_i, 0 at held unknowns when active.
  const double* increment(const double* delta) const { return active_ ? increment_.data() : delta; }
  /// The end temperatures of the sub-grid blend's Σ S_ip T_i, 0 at held unknowns when active: a held
  /// node's term is the pull's target T_f + g_i·(x_p − x_i) (blend_target), so the blend moves no
  /// heat where every node of a particle is an unknown (Σ_p m_p C_p of the flip and of the target
  /// agree, as without faces).
  const double* end(const double* end) const { return active_ ? end_.data() : end; }
  /// Σ_held S_ip (T_f + g_i·(x_p − x_i)) from the pull's change of T_p.
  static double blend_target(const Sums& q, double before, double change) { return change + q.weight * before; }
  bool held(std::size_t u) const { return held_[u] != 0; }
  void add(Sums& q, std::size_t u, double S) const {
    if (!held_[u]) return;
    q.weight += S;
    q.offset += S * offset_[u];
    for (int a = 0; a < Dim; ++a) q.gradient[static_cast<std::size_t>(a)] += S * gradient_[u * Dim + static_cast<std::size_t>(a)];
  }
  /// The pull's change of T_p: Σ_held S_ip (T_face + g_i·(x_p − x_i) − T_p).
  template <class Position>
  static double change(const Sums& q, double before, const Position& x) {
    double v = q.offset - q.weight * before;
    for (int a = 0; a < Dim; ++a) v += q.gradient[static_cast<std::size_t>(a)] * x[a];
    return v;
  }

 private:
  bool active_ = false;
  std::vector<double> increment_;
  std::vector<double> end_;
  std::vector<double> offset_;
  std::vector<unsigned char> held_;
  std::vector<double> gradient_;
};

/// The held unknowns of FacePull. Each (u, T) of for_each_fixed_node's faces: node u's gradient along
/// the face's axis from `inward(u, axis, upper, T_in, dx)` (false: no unknown there), which gives the
/// temperature T_in of the node one cell inward and its offset dx along the axis; later faces set T.
/// position(u, a): coordinate a of node u.
template <int Dim, class Cells, class LatticeAlong, class Inward, class Position>
void collect_face_pull_nodes(const std::vector<FixedTemperatureFace>& faces, const Cells& cells, std::size_t count,
                     LatticeAlong&& lattice_along, Inward&& inward, Position&& position,
                     std::vector<typename FacePull<Dim>::Held>& held) {
  held.clear();
  std::vector<int> slot(faces.empty() ? 0 : count, -1);
  for (const FixedTemperatureFace& f : faces) {
    const int face_index = f.upper ? static_cast<int>(cells[static_cast<std::size_t>(f.axis)]) : 0;
    for (std::size_t u = 0; u < count; ++u) {
      if (lattice_along(u, f.axis) != face_index) continue;
      if (slot[u] < 0) {
        slot[u] = static_cast<int>(held.size());
        typename FacePull<Dim>::Held h;
        h.unknown = static_cast<int>(u);
        for (int a = 0; a < Dim; ++a) h.position[static_cast<std::size_t>(a)] = position(u, a);
        held.push_back(h);
      }
      held[static_cast<std::size_t>(slot[u])].temperature = f.temperature;
    }
  }
  // Gradients once every node has its temperature (a corner takes the later face's).
  for (typename FacePull<Dim>::Held& h : held)
    for (const FixedTemperatureFace& f : faces) {
      const int face_index = f.upper ? static_cast<int>(cells[static_cast<std::size_t>(f.axis)]) : 0;
      const auto u = static_cast<std::size_t>(h.unknown);
      double t_in = 0.0, dx = 0.0;
      if (lattice_along(u, f.axis) == face_index && inward(u, f.axis, f.upper, t_in, dx) && dx != 0.0)
        h.gradient[static_cast<std::size_t>(f.axis)] = (t_in - h.temperature) / dx;
    }
}

}  // namespace frictherm::coupling
