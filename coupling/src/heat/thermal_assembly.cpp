// Nodal thermal mass, temperature and conductance from particles (Nairn et al. 2018 eq. 38), and
// the incremental particle update T_p += Σ_i S_ip ΔT_i (design §4).
#include <frictherm/coupling/thermal_assembly.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace frictherm::coupling {

namespace {


/// One particle's nodes, weights S_ip and gradients G_ip, in the order the stencil visits them.
template <int Dim, class Kernel>
struct NodeList {
  static constexpr int capacity = mechanics::Stencil<Dim, Kernel>::node_count;
  int count = 0;
  int node[capacity];
  double S[capacity];
  mechanics::Vec<Dim> G[capacity];

  /// From the MPM step's stencils (`step`, when given: the same S_ip, G_ip at these positions) or a
  /// fresh evaluation.
  void fill(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p, std::size_t k,
            const mechanics::Stencil<Dim, Kernel>* step) {
    mechanics::Stencil<Dim, Kernel> own;
    const mechanics::Stencil<Dim, Kernel>& st = step ? step[k] : own;
    if (!step) own.evaluate(grid, p.position[k], p.half_size[k]);
    count = 0;
    st.for_each(grid, [&](int i, double w, const mechanics::Vec<Dim>& g) {
      node[count] = i;
      S[count] = w;
      G[count] = g;
      ++count;
    });
  }
};

/// The node lists of one assembly, kept (per dimension and kernel, per thread) so that pass 2 and the
/// map back to the particles after the integration do not evaluate the stencils again. An entry is
/// reused only for the same grid and a particle at the same position with the same half-size, so the
/// weights are the ones a fresh evaluation gives, bit for bit.
template <int Dim, class Kernel>
struct StencilCache {
  const mechanics::Grid<Dim>* grid = nullptr;
  mechanics::Vec<Dim> lo, h;
  mechanics::IVec<Dim> cells;
  std::vector<NodeList<Dim, Kernel>> lists;
  std::vector<mechanics::Vec<Dim>> position, half_size;

  static StencilCache& local() {
    thread_local StencilCache cache;
    return cache;
  }
  void reset(const mechanics::Grid<Dim>& g, std::size_t n) {
    grid = &g;
    lo = g.lo();
    h = g.cell_size();
    cells = g.cells();
    lists.resize(n);
    position.resize(n);
    half_size.resize(n);
  }
  const NodeList<Dim, Kernel>& fill(const mechanics::Grid<Dim>& g, const mechanics::Particles<Dim>& p, std::size_t k,
                                    const mechanics::Stencil<Dim, Kernel>* step) {
    lists[k].fill(g, p, k, step);
    position[k] = p.position[k];
    half_size[k] = p.half_size[k];
    return lists[k];
  }
  /// The cached list of particle k if it is still exact, else nullptr.
  const NodeList<Dim, Kernel>* find(const mechanics::Grid<Dim>& g, const mechanics::Particles<Dim>& p,
                                    std::size_t k) const {
    if (grid != &g || lo != g.lo() || h != g.cell_size() || cells != g.cells()) return nullptr;
    if (k >= lists.size() || lists[k].count == 0) return nullptr;
    if (position[k] != p.position[k] || half_size[k] != p.half_size[k]) return nullptr;
    return &lists[k];
  }
};

/// K's sparsity pattern of the last assembly (per dimension and kernel, per thread): the unknowns, the
/// CSR arrays and the row slot of every stored entry (the diagonal at the centre slot). A new assembly
/// with the same unknowns and the same slots holding non-zero products has the same pattern: only
/// the values are written (same numbers, same order as a fresh build).
template <int Dim, class Kernel>
struct ConductancePattern {
  std::vector<int> grid_node;
  std::vector<int> slot;  // by stored entry, CSR order
  thermal::SparseMatrix matrix;

  static ConductancePattern& local() {
    thread_local ConductancePattern pattern;
    return pattern;
  }
  /// True if `rows` (n rows of `slots` products) gives this pattern for these unknowns.
  bool matches(const std::vector<int>& unknowns, const std::vector<double>& rows, int slots, int centre) const {
    if (unknowns != grid_node || matrix.rows() != static_cast<Eigen::Index>(unknowns.size())) return false;
    const auto* outer = matrix.outerIndexPtr();
    for (std::size_t u = 0; u < unknowns.size(); ++u) {
      const double* r = &rows[u * static_cast<std::size_t>(slots)];
      int count = 0;
      for (int s = 0; s < slots; ++s) count += s != centre && r[s] != 0.0;
      if (count + 1 != outer[u + 1] - outer[u]) return false;
      for (auto e = outer[u]; e < outer[u + 1]; ++e)
        if (slot[static_cast<std::size_t>(e)] != centre && r[slot[static_cast<std::size_t>(e)]] == 0.0) return false;
    }
    return true;
  }
};

template <int Dim, class Kernel>
NodalThermalSystem assemble_with(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p,
                                 const std::vector<ThermalProperties>& materials, const AssemblyOptions& opt,
                                 const mechanics::StencilView<Dim>& view) {
  using Nodes = NodeList<Dim, Kernel>;
  const mechanics::Stencil<Dim, Kernel>* step_stencils = view.template as<Kernel>(p.size());
  const std::size_t n_nodes = grid.node_count();
  NodalThermalSystem sys;
  sys.grid_mass.assign(n_nodes, 0.0);
  thread_local std::vector<double> mct;
  mct.assign(n_nodes, 0.0);
  StencilCache<Dim, Kernel>& cache = StencilCache<Dim, Kernel>::local();
  cache.reset(grid, p.size());
  for (auto& l : cache.lists) l.count = 0;  // entries of non-conducting particles stay invalid

  // Pass 1: M_i and M_i T_i (eq. 38).
  for (std::size_t k = 0; k < p.size(); ++k) {
    const ThermalProperties& m = thermal_properties_of(materials, p.material[k]);
    if (!m.conducts) continue;
    const double mc = p.mass[k] * m.heat_capacity;
    sys.particle_heat_capacity += mc;
    const Nodes& nl = cache.fill(grid, p, k, step_stencils);
    for (int a = 0; a < nl.count; ++a) {
      const auto i = static_cast<std::size_t>(nl.node[a]);
      sys.grid_mass[i] += mc * nl.S[a];
      mct[i] += mc * p.temperature[k] * nl.S[a];
    }
  }
  if (!(sys.particle_heat_capacity > 0.0))
    throw std::invalid_argument("thermal assembly: no particle of a material with thermal properties");

  // Unknowns: nodes carrying more than a tiny fraction of the largest nodal heat capacity.
  sys.select_unknowns(mct, opt.active_mass_fraction);
  const auto n = static_cast<Eigen::Index>(sys.grid_node.size());

  // Pass 2: K_ij = Σ_p V_p k_p G'_ip·G'_jp, accumulated per unknown row in slots indexed by the lattice
  // offset of j from i (each component in [-(K-1), K-1]).
  constexpr int kw = 2 * Kernel::K - 1;
  constexpr int slots = Dim == 2 ? kw * kw : kw * kw * kw;
  thread_local std::vector<double> rows;  // kept between windows: no fresh pages every window
  rows.assign(static_cast<std::size_t>(n) * slots, 0.0);
  // The slot of node j in row i from the flat index difference j - i through a table (no
  // node_lattice divisions per particle); the lattice is decoded instead if two offsets share a
  // difference (fewer than kw nodes along an axis).
  const auto& stride = grid.strides();
  int reach = 0;
  for (int d = 0; d < Dim; ++d) reach += (Kernel::K - 1) * stride[d];
  thread_local std::vector<int> slot_of;
  slot_of.assign(static_cast<std::size_t>(2 * reach + 1), -1);
  bool use_table = true;
  for (int sl = 0; sl < slots; ++sl) {
    int rem = sl, diff = 0;
    for (int d = 0; d < Dim; ++d) {
      diff += (rem % kw - (Kernel::K - 1)) * stride[d];
      rem /= kw;
    }
    int& e = slot_of[static_cast<std::size_t>(diff + reach)];
    use_table = use_table && e < 0;
    e = sl;
  }
  mechanics::Vec<Dim> Gk[Nodes::capacity];
  mechanics::IVec<Dim> lat[Nodes::capacity];
  int row[Nodes::capacity], gnode[Nodes::capacity];
  for (std::size_t k = 0; k < p.size(); ++k) {
    const ThermalProperties& m = thermal_properties_of(materials, p.material[k]);
    if (!m.conducts || !(m.conductivity > 0.0)) continue;
    Nodes nl = cache.lists[k];  // filled by pass 1 (a copy: the lumping below reorders S)
    double s_kept = 0.0;
    mechanics::Vec<Dim> g_dropped = mechanics::Vec<Dim>::Zero();
    int kept = 0;
    for (int a = 0; a < nl.count; ++a) {
      const int u = sys.unknown[static_cast<std::size_t>(nl.node[a])];
      if (u >= 0) {
        s_kept += nl.S[a];
        row[kept] = u;
        Gk[kept] = nl.G[a];
        gnode[kept] = nl.node[a];
        if (!use_table) lat[kept] = grid.node_lattice(nl.node[a]);
        nl.S[kept] = nl.S[a];
        ++kept;
      } else {
        g_dropped += nl.G[a];
      }
    }
    if (kept == 0 || !(s_kept > 0.0)) continue;  // no heat capacity of its own reaches an unknown
    if (kept < nl.count)
      for (int a = 0; a < kept; ++a) Gk[a] += (nl.S[a] / s_kept) * g_dropped;  // lump dropped nodes
    const double c = p.volume[k] * m.conductivity;
    // K is symmetric: each product once, into row a at the offset of b and into row b at the mirrored
    // offset (slots - 1 - slot). Every (row, slot) entry still gets the same single term per particle,
    // in particle order, so the sums are bit-identical to the full double loop.
    for (int a = 0; a < kept; ++a) {
      double* r = &rows[static_cast<std::size_t>(row[a]) * slots];
      for (int b = a; b < kept; ++b) {
        int slot = 0;
        if (use_table) {
          slot = slot_of[static_cast<std::size_t>(gnode[b] - gnode[a] + reach)];
        } else {
          for (int d = 0, scale = 1; d < Dim; ++d, scale *= kw)
            slot += (lat[b][static_cast<std::size_t>(d)] - lat[a][static_cast<std::size_t>(d)] + Kernel::K - 1) * scale;
        }
        const double kab = c * Gk[a].dot(Gk[b]);
        r[slot] += kab;
        if (b != a) rows[static_cast<std::size_t>(row[b]) * slots + static_cast<std::size_t>(slots - 1 - slot)] += kab;
      }
    }
  }

  // CSR with the diagonal set to minus the off-diagonal row sum, so K·1 = 0 to the round-off of
  // that sum (the products above give it only approximately, and exact zero row sums make the
  // conduction part conserve Σ M_i T_i exactly). Rows are written in place (Eigen's sorted
  // startVec/insertBack fill): no triplet list, no temporary column-major copy.
  constexpr int centre = (slots - 1) / 2;
  ConductancePattern<Dim, Kernel>& pattern = ConductancePattern<Dim, Kernel>::local();
  if (pattern.matches(sys.grid_node, rows, slots, centre)) {  // same layout: refill the values
    sys.conductance = pattern.matrix;
    double* value = sys.conductance.valuePtr();
    const auto* outer = sys.conductance.outerIndexPtr();
    for (Eigen::Index u = 0; u < n; ++u) {
      const double* r = &rows[static_cast<std::size_t>(u) * slots];
      double off_sum = 0.0;  // in slot order, as the fresh build sums it
      for (int s = 0; s < slots; ++s)
        if (s != centre && r[s] != 0.0) off_sum += r[s];
      for (auto e = outer[u]; e < outer[u + 1]; ++e) {
        const int sl = pattern.slot[static_cast<std::size_t>(e)];
        value[e] = sl == centre ? -off_sum : r[sl];
      }
    }
    return sys;
  }
  std::size_t nnz = 0;
  for (double v : rows) nnz += v != 0.0;
  sys.conductance.resize(n, n);
  sys.conductance.reserve(static_cast<Eigen::Index>(nnz) + n);
  pattern.slot.clear();
  pattern.slot.reserve(nnz + static_cast<std::size_t>(n));
  int col[slots], slot_at[slots];
  double val[slots];
  for (Eigen::Index u = 0; u < n; ++u) {
    const double* r = &rows[static_cast<std::size_t>(u) * slots];
    const int node = sys.grid_node[static_cast<std::size_t>(u)];
    double off_sum = 0.0;
    int count = 0;
    for (int s = 0; s < slots; ++s) {
      if (s == centre || r[s] == 0.0) continue;
      int rem = s, j = node;
      for (int d = 0; d < Dim; ++d) {
        j += (rem % kw - (Kernel::K - 1)) * stride[d];
        rem /= kw;
      }
      col[count] = sys.unknown[static_cast<std::size_t>(j)];
      slot_at[count] = s;
      val[count++] = r[s];
      off_sum += r[s];
    }
    // Ascending columns: the slot order is the lattice order, in which unknown numbers increase
    // (they follow the flat node index) unless an axis has fewer than kw nodes; then sort. The
    // diagonal goes where its column falls.
    for (int a = 1; a < count; ++a)
      for (int b = a; b > 0 && col[b - 1] > col[b]; --b) {
        std::swap(col[b - 1], col[b]);
        std::swap(slot_at[b - 1], slot_at[b]);
        std::swap(val[b - 1], val[b]);
      }
    sys.conductance.startVec(u);
    bool diagonal = false;
    for (int a = 0; a < count; ++a) {
      if (!diagonal && col[a] > u) {
        sys.conductance.insertBack(u, u) = -off_sum;
        pattern.slot.push_back(centre);
        diagonal = true;
      }
      sys.conductance.insertBack(u, col[a]) = val[a];
      pattern.slot.push_back(slot_at[a]);
    }
    if (!diagonal) sys.conductance.insertBack(u, u) = -off_sum, pattern.slot.push_back(centre);
  }
  sys.conductance.finalize();
  pattern.grid_node = sys.grid_node;
  pattern.matrix = sys.conductance;
  return sys;
}

template <int Dim, class Kernel>
void add_change_with(const mechanics::Grid<Dim>& grid, mechanics::Particles<Dim>& p,
                     const std::vector<ThermalProperties>& materials, const NodalThermalSystem& sys,
                     const Eigen::VectorXd& delta, double beta, const Eigen::VectorXd* end,
                     const mechanics::StencilView<Dim>& view) {
  const mechanics::Stencil<Dim, Kernel>* step_stencils = view.template as<Kernel>(p.size());
  NodeList<Dim, Kernel> fresh;
  const StencilCache<Dim, Kernel>& cache = StencilCache<Dim, Kernel>::local();
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!thermal_properties_of(materials, p.material[k]).conducts) continue;
    const NodeList<Dim, Kernel>* cached = cache.find(grid, p, k);  // the assembly's, when still exact
    if (!cached) fresh.fill(grid, p, k, step_stencils);
    const NodeList<Dim, Kernel>& nl = cached ? *cached : fresh;
    double dT = 0.0, pic = 0.0, s = 0.0;
    for (int a = 0; a < nl.count; ++a) {
      const int u = sys.unknown[static_cast<std::size_t>(nl.node[a])];
      if (u < 0) continue;
      dT += nl.S[a] * delta[u];  // design §4: the increment, not the nodal value
      if (end) {
        pic += nl.S[a] * (*end)[u];
        s += nl.S[a];
      }
    }
    const double flip = p.temperature[k] + dT;
    p.temperature[k] = (end && s > 0.0) ? flip - beta * (flip - pic / s) : flip;
  }
}

}  // namespace

double NodalThermalSystem::mass_residual() const {
  double total = 0.0;
  for (double m : grid_mass) total += m;
  return particle_heat_capacity > 0.0 ? std::fabs(total - particle_heat_capacity) / particle_heat_capacity : 0.0;
}

double NodalThermalSystem::row_sum_residual() const {
  if (size() == 0) return 0.0;
  const Eigen::VectorXd r = conductance * Eigen::VectorXd::Ones(static_cast<Eigen::Index>(size()));
  const double kmax = conductance.diagonal().cwiseAbs().maxCoeff();
  return kmax > 0.0 ? r.cwiseAbs().maxCoeff() / kmax : 0.0;
}

double NodalThermalSystem::energy(const Eigen::VectorXd& nodal_temperature) const {
  return mass.dot(nodal_temperature);
}

void NodalThermalSystem::select_unknowns(const std::vector<double>& mct, double active_mass_fraction) {
  const std::size_t n_nodes = grid_mass.size();
  max_mass = *std::max_element(grid_mass.begin(), grid_mass.end());
  const double threshold = active_mass_fraction * max_mass;
  unknown.assign(n_nodes, -1);
  grid_node.clear();
  dropped_mass = 0.0;
  for (std::size_t i = 0; i < n_nodes; ++i) {
    if (grid_mass[i] > threshold && grid_mass[i] > 0.0) {
      unknown[i] = static_cast<int>(grid_node.size());
      grid_node.push_back(static_cast<int>(i));
    } else {
      dropped_mass += grid_mass[i];
    }
  }
  const auto n = static_cast<Eigen::Index>(grid_node.size());
  mass.resize(n);
  temperature.resize(n);
  for (Eigen::Index u = 0; u < n; ++u) {
    const auto i = static_cast<std::size_t>(grid_node[static_cast<std::size_t>(u)]);
    mass[u] = grid_mass[i];
    temperature[u] = mct[i] / grid_mass[i];
  }
}

const ThermalProperties& thermal_properties_of(const std::vector<ThermalProperties>& materials, int id) {
  if (id < 0 || static_cast<std::size_t>(id) >= materials.size())
    throw std::invalid_argument("thermal assembly: particle of material id " + std::to_string(id) + " but only " +
                                std::to_string(materials.size()) + " materials have thermal properties");
  return materials[static_cast<std::size_t>(id)];
}

template <int Dim>
NodalThermalSystem assemble_thermal(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles,
                                    mechanics::ShapeKind shape, const std::vector<ThermalProperties>& materials,
                                    const AssemblyOptions& options, const mechanics::StencilView<Dim>& stencils) {
  return mechanics::dispatch_shape(shape, [&](auto kernel) {
    return assemble_with<Dim, decltype(kernel)>(grid, particles, materials, options, stencils);
  });
}

template <int Dim>
void add_nodal_change_to_particles(const mechanics::Grid<Dim>& grid, mechanics::Particles<Dim>& particles,
                                   mechanics::ShapeKind shape, const std::vector<ThermalProperties>& materials,
                                   const NodalThermalSystem& system, const Eigen::VectorXd& delta,
                                   double relaxation, const Eigen::VectorXd* end,
                                   const mechanics::StencilView<Dim>& stencils) {
  const auto n = static_cast<Eigen::Index>(system.size());
  if (delta.size() != n || (end && end->size() != n))
    throw std::invalid_argument("add_nodal_change_to_particles: " + std::to_string(delta.size()) +
                                " nodal values for " + std::to_string(system.size()) + " unknowns");
  if (!(relaxation >= 0.0 && relaxation <= 1.0))
    throw std::invalid_argument("add_nodal_change_to_particles: relaxation must be in [0, 1]");
  const Eigen::VectorXd* pic = relaxation > 0.0 ? end : nullptr;
  mechanics::dispatch_shape(shape, [&](auto kernel) {
    add_change_with<Dim, decltype(kernel)>(grid, particles, materials, system, delta, relaxation, pic, stencils);
  });
}

template <int Dim>
double particle_thermal_energy(const mechanics::Particles<Dim>& p, const std::vector<ThermalProperties>& materials) {
  double e = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const ThermalProperties& m = thermal_properties_of(materials, p.material[k]);
    if (m.conducts) e += p.mass[k] * m.heat_capacity * p.temperature[k];
  }
  return e;
}

#define FRICTHERM_INSTANTIATE_ASSEMBLY(D)                                                                       \
  template NodalThermalSystem assemble_thermal<D>(const mechanics::Grid<D>&, const mechanics::Particles<D>&,   \
                                                  mechanics::ShapeKind, const std::vector<ThermalProperties>&, \
                                                  const AssemblyOptions&, const mechanics::StencilView<D>&);   \
  template void add_nodal_change_to_particles<D>(const mechanics::Grid<D>&, mechanics::Particles<D>&,          \
                                                 mechanics::ShapeKind, const std::vector<ThermalProperties>&,  \
                                                 const NodalThermalSystem&, const Eigen::VectorXd&, double,    \
                                                 const Eigen::VectorXd*, const mechanics::StencilView<D>&);    \
  template double particle_thermal_energy<D>(const mechanics::Particles<D>&, const std::vector<ThermalProperties>&);
FRICTHERM_INSTANTIATE_ASSEMBLY(2)
FRICTHERM_INSTANTIATE_ASSEMBLY(3)
#undef FRICTHERM_INSTANTIATE_ASSEMBLY

}  // namespace frictherm::coupling
