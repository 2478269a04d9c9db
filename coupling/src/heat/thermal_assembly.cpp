// Nodal thermal mass, temperature and conductance from particles (Nairn et al. 2018 eq. 38), and
// the incremental particle update T_p += Σ_i S_ip ΔT_i (design §4).
#include <frictherm/coupling/thermal_assembly.hpp>
#include <frictherm/mechanics/energy/compensated_sum.hpp>
#include <frictherm/mechanics/parallel_region.hpp>

#include "conductance_rows.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
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

using assembly_detail::assembly_threads;
using assembly_detail::conductance_from_rows;
using assembly_detail::ConductancePattern;
using assembly_detail::NodeRange;

template <int Dim, class Kernel>
NodalThermalSystem assemble_with(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p,
                                 const std::vector<ThermalProperties>& materials, const AssemblyOptions& opt,
                                 const mechanics::StencilView<Dim>& view) {
  using Nodes = NodeList<Dim, Kernel>;
  const mechanics::Stencil<Dim, Kernel>* step_stencils = view.template as<Kernel>(p.size());
  const std::size_t n_nodes = grid.node_count();
  const std::size_t np = p.size();
  NodalThermalSystem sys;
  // Every particle's material checked (and the total heat capacity summed in particle order) before
  // the threaded passes, which must not throw.
  for (std::size_t k = 0; k < np; ++k) {
    const ThermalProperties& m = thermal_properties_of(materials, p.material[k]);
    if (m.conducts) sys.particle_heat_capacity += p.mass[k] * m.heat_capacity;
  }
  if (!(sys.particle_heat_capacity > 0.0))
    throw std::invalid_argument("thermal assembly: no particle of a material with thermal properties");
  auto props = [&](std::size_t k) -> const ThermalProperties& { return materials[static_cast<std::size_t>(p.material[k])]; };
  sys.grid_mass.resize(n_nodes);
  // Buffers kept between windows (no fresh pages every window), per calling thread; the passes'
  // threads reach them through these references (a thread_local named inside an OpenMP region would
  // be each thread's own).
  thread_local std::vector<double> mct_buffer, rows_buffer;
  thread_local std::vector<std::array<int, 2>> reach_buffer;
  std::vector<double>& mct = mct_buffer;
  std::vector<double>& rows = rows_buffer;
  // Per particle the lowest and highest node it reaches ({n_nodes, -1} if it does not conduct): a
  // thread skips the particles outside its range of nodes without reading their node lists.
  std::vector<std::array<int, 2>>& reach_of = reach_buffer;
  mct.resize(n_nodes);
  reach_of.resize(np);
  // The calling thread's cache, shared by the passes' threads (each writes its own particles' lists).
  StencilCache<Dim, Kernel>& cache = StencilCache<Dim, Kernel>::local();
  cache.reset(grid, np);
  const int threads = assembly_threads(np);
  int span_lo = static_cast<int>(n_nodes), span_hi = -1;  // the nodes the particles reach

  // Pass 1: M_i and M_i T_i (eq. 38). The node lists filled in parallel; then each thread sums into
  // its own range of nodes, in particle order (the sums of one thread are those of a serial pass).
  mechanics::parallel_region(threads, [&] {
    const NodeRange r = NodeRange::of_thread(0, static_cast<int>(n_nodes));  // cleared by this thread
    std::fill(sys.grid_mass.begin() + r.lo, sys.grid_mass.begin() + r.hi, 0.0);
    std::fill(mct.begin() + r.lo, mct.begin() + r.hi, 0.0);
    // The span as each thread's own min/max, combined below (a reduction clause on this orphaned loop
    // would name a variable the lambda captures, which clang refuses: "reduction variable must be shared").
    int my_lo = static_cast<int>(n_nodes), my_hi = -1;
#pragma omp for schedule(static)
    for (std::size_t k = 0; k < np; ++k) {
      std::array<int, 2>& reach = reach_of[k];
      reach = {static_cast<int>(n_nodes), -1};
      if (!props(k).conducts) {
        cache.lists[k].count = 0;  // no valid entry: not a node list of this assembly
        continue;
      }
      const Nodes& nl = cache.fill(grid, p, k, step_stencils);
      for (int a = 0; a < nl.count; ++a) reach[0] = std::min(reach[0], nl.node[a]), reach[1] = std::max(reach[1], nl.node[a]);
      my_lo = std::min(my_lo, reach[0]), my_hi = std::max(my_hi, reach[1]);
    }
#pragma omp critical(frictherm_assembly_span)
    span_lo = std::min(span_lo, my_lo), span_hi = std::max(span_hi, my_hi);
#pragma omp barrier
    // (every node is cleared and the span complete before any thread adds)
    const NodeRange mine = NodeRange::of_thread(span_lo, span_hi + 1);
    for (std::size_t k = 0; k < np; ++k) {
      if (!mine.meets(reach_of[k])) continue;
      const Nodes& nl = cache.lists[k];
      const double mc = p.mass[k] * props(k).heat_capacity;
      for (int a = 0; a < nl.count; ++a) {
        const int i = nl.node[a];
        if (!mine.holds(i)) continue;
        sys.grid_mass[static_cast<std::size_t>(i)] += mc * nl.S[a];
        mct[static_cast<std::size_t>(i)] += mc * p.temperature[k] * nl.S[a];
      }
    }
  });

  // Unknowns: nodes carrying more than a tiny fraction of the largest nodal heat capacity.
  sys.select_unknowns(mct, opt.active_mass_fraction);
  const auto n = static_cast<Eigen::Index>(sys.grid_node.size());

  // Pass 2: K_ij = Σ_p V_p k_p G'_ip·G'_jp, accumulated per unknown row in slots indexed by the lattice
  // offset of j from i (each component in [-(K-1), K-1]).
  constexpr int kw = ConductancePattern<Dim, Kernel>::kw;
  constexpr int slots = ConductancePattern<Dim, Kernel>::slots;
  rows.resize(static_cast<std::size_t>(n) * slots);
  // The slot of node j in row i from the flat index difference j - i through a table (no
  // node_lattice divisions per particle); the lattice is decoded instead if two offsets share a
  // difference (fewer than kw nodes along an axis).
  const auto& stride = grid.strides();
  int reach = 0;
  for (int d = 0; d < Dim; ++d) reach += (Kernel::K - 1) * stride[d];
  thread_local std::vector<int> slot_of_buffer;
  std::vector<int>& slot_of = slot_of_buffer;
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
  // Each thread adds into its own range of rows, in particle order, so every (row, slot) entry gets
  // the same terms in the same order as in a serial pass: K is the same for every thread count.
  mechanics::parallel_region(threads, [&] {
  const NodeRange mine = NodeRange::of_thread(0, static_cast<int>(n));  // rows
  std::fill(rows.begin() + static_cast<std::ptrdiff_t>(mine.lo) * slots, rows.begin() + static_cast<std::ptrdiff_t>(mine.hi) * slots, 0.0);
  // The grid nodes of these rows: a particle reaching none of them is skipped before its lumping.
  const NodeRange nodes = mine.lo < mine.hi ? NodeRange{sys.grid_node[static_cast<std::size_t>(mine.lo)],
                                                        sys.grid_node[static_cast<std::size_t>(mine.hi - 1)] + 1}
                                            : NodeRange{0, 0};
  mechanics::Vec<Dim> Gk[Nodes::capacity];
  mechanics::IVec<Dim> lat[Nodes::capacity];
  int row[Nodes::capacity], gnode[Nodes::capacity];
  for (std::size_t k = 0; k < np; ++k) {
    const ThermalProperties& m = props(k);
    if (!nodes.meets(reach_of[k]) || !(m.conductivity > 0.0)) continue;  // (meets: it conducts)
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
      const bool own_a = mine.holds(row[a]);
      double* r = &rows[static_cast<std::size_t>(row[a]) * slots];
      for (int b = a; b < kept; ++b) {
        const bool own_b = b != a && mine.holds(row[b]);
        if (!own_a && !own_b) continue;
        int slot = 0;
        if (use_table) {
          slot = slot_of[static_cast<std::size_t>(gnode[b] - gnode[a] + reach)];
        } else {
          for (int d = 0, scale = 1; d < Dim; ++d, scale *= kw)
            slot += (lat[b][static_cast<std::size_t>(d)] - lat[a][static_cast<std::size_t>(d)] + Kernel::K - 1) * scale;
        }
        const double kab = c * Gk[a].dot(Gk[b]);
        if (own_a) r[slot] += kab;
        if (own_b) rows[static_cast<std::size_t>(row[b]) * slots + static_cast<std::size_t>(slots - 1 - slot)] += kab;
      }
    }
  }
  });  // omp parallel

  // K in CSR, the diagonal minus the off-diagonal row sum (conductance_rows.hpp).
  conductance_from_rows<Dim, Kernel>(rows, sys.grid_node, sys.unknown, stride, threads,
                                     ConductancePattern<Dim, Kernel>::local(), sys.conductance);
  return sys;
}

template <int Dim, class Kernel>
double add_change_with(const mechanics::Grid<Dim>& grid, mechanics::Particles<Dim>& p,
                     const std::vector<ThermalProperties>& materials, const NodalThermalSystem& sys,
                     const Eigen::VectorXd& delta, const FacePull<Dim>& pull, double beta, const Eigen::VectorXd* end,
                     const mechanics::StencilView<Dim>& view) {
  const mechanics::Stencil<Dim, Kernel>* step_stencils = view.template as<Kernel>(p.size());
  const StencilCache<Dim, Kernel>& cache = StencilCache<Dim, Kernel>::local();  // the calling thread's
  for (std::size_t k = 0; k < p.size(); ++k) thermal_properties_of(materials, p.material[k]);  // throws here
  const bool pulls = pull.active();  // held nodes pull their particles towards the face (FacePull)
  const double* const increment = pull.increment(delta.data());
  const double* const target = end ? pull.end(end->data()) : nullptr;  // the blend's (FacePull::end)
  double face_heat = 0.0;
  // Each particle's temperature from its own nodes: the particles shared between threads.
#pragma omp parallel for num_threads(assembly_threads(p.size())) schedule(static) reduction(+ : face_heat)
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!materials[static_cast<std::size_t>(p.material[k])].conducts) continue;
    NodeList<Dim, Kernel> fresh;
    const NodeList<Dim, Kernel>* cached = cache.find(grid, p, k);  // the assembly's, when still exact
    if (!cached) fresh.fill(grid, p, k, step_stencils);
    const NodeList<Dim, Kernel>& nl = cached ? *cached : fresh;
    double dT = 0.0, pic = 0.0, s = 0.0;
    typename FacePull<Dim>::Sums q;
    for (int a = 0; a < nl.count; ++a) {
      const int u = sys.unknown[static_cast<std::size_t>(nl.node[a])];
      if (u < 0) continue;
      dT += nl.S[a] * increment[u];  // design §4: the increment, not the nodal value
      if (pulls) pull.add(q, static_cast<std::size_t>(u), nl.S[a]);
      if (end) {
        pic += nl.S[a] * target[u];
        s += nl.S[a];
      }
    }
    double flip = p.temperature[k] + dT;
    if (pulls && q.weight != 0.0) {  // the held nodes' pull (FacePull) and the heat it brings
      const double change = FacePull<Dim>::change(q, p.temperature[k], p.position[k]);
      flip = p.temperature[k] + (dT + change);
      face_heat += p.mass[k] * materials[static_cast<std::size_t>(p.material[k])].heat_capacity * change;
      if (end) pic += FacePull<Dim>::blend_target(q, p.temperature[k], change);
    }
    p.temperature[k] = (end && s > 0.0) ? flip - beta * (flip - pic / s) : flip;
  }
  return face_heat;
}

}  // namespace

double NodalThermalSystem::mass_residual() const {
  double total = 0.0;
  for (double m : grid_mass) total += m;
  return particle_heat_capacity > 0.0 ? std::fabs(total - particle_heat_capacity) / particle_heat_capacity : 0.0;
}

double NodalThermalSystem::row_sum_residual() const { return row_sum_extremes(conductance, 0).residual(); }

RowSumExtremes row_sum_extremes(const thermal::SparseMatrix& rows, Eigen::Index first) {
  RowSumExtremes e;
  if (rows.rows() == 0) return e;
  const Eigen::VectorXd r = rows * Eigen::VectorXd::Ones(rows.cols());
  e.sum = r.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < rows.rows(); ++i) e.diagonal = std::max(e.diagonal, std::fabs(rows.coeff(i, first + i)));
  return e;
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
double add_nodal_change_to_particles(const mechanics::Grid<Dim>& grid, mechanics::Particles<Dim>& particles,
                                   mechanics::ShapeKind shape, const std::vector<ThermalProperties>& materials,
                                   const NodalThermalSystem& system, const Eigen::VectorXd& delta,
                                   double relaxation, const Eigen::VectorXd* end,
                                   const mechanics::StencilView<Dim>& stencils,
                                   const std::vector<typename FacePull<Dim>::Held>* held) {
  const auto n = static_cast<Eigen::Index>(system.size());
  if (delta.size() != n || (end && end->size() != n))
    throw std::invalid_argument("add_nodal_change_to_particles: " + std::to_string(delta.size()) +
                                " nodal values for " + std::to_string(system.size()) + " unknowns");
  if (!(relaxation >= 0.0 && relaxation <= 1.0))
    throw std::invalid_argument("add_nodal_change_to_particles: relaxation must be in [0, 1]");
  const Eigen::VectorXd* pic = relaxation > 0.0 ? end : nullptr;
  FacePull<Dim> pull;
  pull.build(delta.data(), pic ? pic->data() : nullptr, system.size(), held);
  double face_heat = 0.0;
  mechanics::dispatch_shape(shape, [&](auto kernel) {
    face_heat = add_change_with<Dim, decltype(kernel)>(grid, particles, materials, system, delta, pull, relaxation,
                                                       pic, stencils);
  });
  return face_heat;
}

template <int Dim>
double particle_thermal_energy(const mechanics::Particles<Dim>& p, const std::vector<ThermalProperties>& materials) {
  mechanics::CompensatedSum e;  // the books difference two such sums (compensated_sum.hpp)
  for (std::size_t k = 0; k < p.size(); ++k) {
    const ThermalProperties& m = thermal_properties_of(materials, p.material[k]);
    if (m.conducts) e.add(p.mass[k] * m.heat_capacity * p.temperature[k]);
  }
  return e.value();
}

#define FRICTHERM_INSTANTIATE_ASSEMBLY(D)                                                                       \
  template NodalThermalSystem assemble_thermal<D>(const mechanics::Grid<D>&, const mechanics::Particles<D>&,   \
                                                  mechanics::ShapeKind, const std::vector<ThermalProperties>&, \
                                                  const AssemblyOptions&, const mechanics::StencilView<D>&);   \
  template double add_nodal_change_to_particles<D>(const mechanics::Grid<D>&, mechanics::Particles<D>&,          \
                                                 mechanics::ShapeKind, const std::vector<ThermalProperties>&,  \
                                                 const NodalThermalSystem&, const Eigen::VectorXd&, double,    \
                                                 const Eigen::VectorXd*, const mechanics::StencilView<D>&,     \
                                                 const std::vector<FacePull<D>::Held>*);                       \
  template double particle_thermal_energy<D>(const mechanics::Particles<D>&, const std::vector<ThermalProperties>&);
FRICTHERM_INSTANTIATE_ASSEMBLY(2)
FRICTHERM_INSTANTIATE_ASSEMBLY(3)
#undef FRICTHERM_INSTANTIATE_ASSEMBLY

}  // namespace frictherm::coupling
