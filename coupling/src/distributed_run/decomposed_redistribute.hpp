#pragma once
// Resuming a decomposed checkpoint on another number of ranks (docs/checkpoints.md, "Decomposed
// runs"): rank r of K' takes the particles of the checkpoint's rank files j ≡ r (mod K'), every swarm
// field as written, then the swarm migrates each particle to its owner in the new decomposition; the
// mechanics' cumulative work books of file j go with its particles (their sum over ranks is kept);
// the heat's per-node state (pending work, M_i and T_i of the last gather) is copied node by node from
// the file whose rank owned the node (DMDA indices are the same for every K), M_i on the ghosted box
// from the new owners; so is the contact regularisation's lagged normal traction per node. The
// interface temperature's flux histories (InterfaceTemperature::visit_state: one slot per heated
// node, named by its serial grid node, with the bins' boundaries and levels the same in every file)
// go slot by slot to the rank that now owns the slot's node; the heat they recorded goes with file
// j's particles (its sum over ranks is kept). The particles' order on a rank and the ranks' sums then
// differ from an uninterrupted K'-rank run: results agree to the round-off of reordered sums, not
// bit-for-bit.
#include "run/checkpoint_io.hpp"

#include <frictherm/coupling/decomposed_heat.hpp>
#include <frictherm/mechanics/distributed.hpp>

#include <array>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace frictherm::coupling::detail {

template <int Dim>
class Redistribution {
 public:
  using Mpm = mechanics::DecomposedMpm<Dim>;
  /// `interface`: the run keeps the interface temperature's flux histories (its checkpoint files
  /// hold /interface/…).
  Redistribution(Mpm& mpm, bool heat, bool interface)
      : mpm_(mpm), heat_(heat), interface_(interface), mine_(mpm.owned_nodes()) {
    acc_ = mpm.checkpoint_state();  // the field names; emptied
    for (auto& r : acc_.reals) r.second.clear();
    for (auto& r : acc_.integers) r.second.clear();
    acc_.cumulative_first = acc_.cumulative_second = 0.0;
    acc_.external_work = acc_.damping_work = acc_.rigid_work = 0.0;
    acc_.contact_normal_work = acc_.boundary_stop_work = acc_.stored_lead = acc_.stress_power = 0.0;
    acc_.stress_dt = 0.0;
    acc_.work_first.clear();
    acc_.work_second.clear();
    acc_.pair_first.clear();
    acc_.pair_second.clear();
    acc_.stats.assign(4, 0);
    std::size_t n = 1;
    for (int d = 0; d < Dim; ++d) n *= static_cast<std::size_t>(mine_[2 * d + 1] - mine_[2 * d]);
    pending_.assign(n, 0.0);
    M_.assign(n, 0.0);
    T_.assign(n, 0.0);
    acc_.lagged_normal_traction.clear();
    acc_.lagged_normal_step.clear();
    lagged_.assign(n, std::numeric_limits<double>::quiet_NaN());  // fresh, as resolve_contact starts them
    lagged_step_.assign(n, -2.0);
  }

  /// Rank file j of the checkpoint: its particles and books when `particles`, its nodes' heat.
  void take(const ckpt::Reader& r, int j, bool particles) {
    std::vector<long> box;
    r("mechanics/owned_nodes", box);
    if (box.size() != 2 * Dim) throw std::runtime_error("rank file " + std::to_string(j) + ": no owned node range");
    r("mechanics/time", acc_.time);
    r("mechanics/empty_node_mass", acc_.empty_node_mass);
    r("mechanics/initial_energy", acc_.initial_energy);  // the books' start: the same in every file
    r("mechanics/steps_taken", acc_.steps_taken);        // the regularisation's clock: the same too
    // The regularisation's lagged tractions of file j's owned nodes (empty: off, or no contact there yet).
    std::vector<double> lagged, lagged_step;
    r("mechanics/contact/lagged_normal_traction", lagged);
    r("mechanics/contact/lagged_normal_step", lagged_step);
    if (!lagged.empty()) {
      copy_nodes(box, lagged, lagged_);
      copy_nodes(box, lagged_step, lagged_step_);
      regularized_ = true;
    }
    if (particles) {
      for (auto& [name, values] : acc_.reals) {
        std::vector<double> v;
        r(("mechanics/" + name).c_str(), v);
        values.insert(values.end(), v.begin(), v.end());
      }
      for (auto& [name, values] : acc_.integers) {
        std::vector<long> v;
        r(("mechanics/" + name).c_str(), v);
        values.insert(values.end(), v.begin(), v.end());
      }
      double w = 0.0;
      r("mechanics/cumulative_work_first", w);
      acc_.cumulative_first += w;
      r("mechanics/cumulative_work_second", w);
      acc_.cumulative_second += w;
      r("mechanics/external_work", w);
      acc_.external_work += w;
      r("mechanics/damping_work", w);
      acc_.damping_work += w;
      r("mechanics/rigid_work", w);
      acc_.rigid_work += w;
      r("mechanics/contact_normal_work", w);
      acc_.contact_normal_work += w;
      r("mechanics/boundary_stop_work", w);
      acc_.boundary_stop_work += w;
      r("mechanics/stored_energy_lead", w);
      acc_.stored_lead += w;
      r("mechanics/stress_power", w);
      acc_.stress_power += w;
      r("mechanics/stress_dt", acc_.stress_dt);  // the step: the same in every file
      for (auto [name, sum] : {std::pair<const char*, std::vector<double>*>{"mechanics/pair_work_first", &acc_.pair_first},
                               {"mechanics/pair_work_second", &acc_.pair_second}}) {
        std::vector<double> pw;
        r(name, pw);
        if (sum->size() < pw.size()) sum->resize(pw.size(), 0.0);
        for (std::size_t k = 0; k < pw.size(); ++k) (*sum)[k] += pw[k];
      }
      std::vector<long> stats;
      r("mechanics/contact_stats", stats);
      for (std::size_t k = 0; k < 4 && k < stats.size(); ++k) acc_.stats[k] += stats[k];
    }
    if (!heat_) return;
    std::vector<double> pending, M, T;
    r("window/pending", pending);
    r("gather/M", M);
    r("gather/T", T);
    copy_nodes(box, pending, pending_);
    copy_nodes(box, M, M_);
    copy_nodes(box, T, T_);
    take_interface_histories(r, j, particles);
  }

  /// Collective: the particles into the swarm (migrated) and the per-node heat into `heat`.
  void finish(DecomposedHeat* heat) {
    if (regularized_) acc_.lagged_normal_traction = lagged_, acc_.lagged_normal_step = lagged_step_;
    mpm_.restore_checkpoint_state(acc_, true);
    if (!heat) return;
    std::vector<double> local_M;
    mpm_.owned_to_local(M_, 1, local_M);
    // The taken slots' histories, bin-major as BinnedHeatHistory::Flat holds them.
    std::vector<double> energy(iface_.levels.size() * iface_.nodes.size());
    for (std::size_t b = 0; b < iface_.levels.size(); ++b)
      for (std::size_t k = 0; k < iface_.nodes.size(); ++k) energy[b * iface_.nodes.size() + k] = iface_.columns[k][b];
    Assign a{pending_, M_, T_, local_M, iface_, energy};
    heat->visit_state(a);
  }

 private:
  // The values of file j's owned box (x fastest) at the nodes this rank owns.
  void copy_nodes(const std::vector<long>& box, const std::vector<double>& from, std::vector<double>& to) const {
    std::array<long, 3> lo{0, 0, 0}, hi{1, 1, 1}, blo{0, 0, 0}, bn{1, 1, 1}, mlo{0, 0, 0}, mn{1, 1, 1};
    std::size_t count = 1;
    for (int d = 0; d < Dim; ++d) {
      blo[d] = box[2 * d], bn[d] = box[2 * d + 1] - box[2 * d];
      mlo[d] = mine_[2 * d], mn[d] = mine_[2 * d + 1] - mine_[2 * d];
      lo[d] = std::max(blo[d], mlo[d]), hi[d] = std::min(box[2 * d + 1], static_cast<long>(mine_[2 * d + 1]));
      count *= static_cast<std::size_t>(bn[d]);
    }
    if (from.size() != count) throw std::runtime_error("checkpoint: per-node state of the wrong size");
    for (long k = lo[2]; k < hi[2]; ++k)
      for (long j = lo[1]; j < hi[1]; ++j)
        for (long i = lo[0]; i < hi[0]; ++i)
          to[static_cast<std::size_t>(((k - mlo[2]) * mn[1] + (j - mlo[1])) * mn[0] + (i - mlo[0]))] =
              from[static_cast<std::size_t>(((k - blo[2]) * bn[1] + (j - blo[1])) * bn[0] + (i - blo[0]))];
  }

  // The interface temperature's flux-history slots of the nodes this rank owns, gathered from every
  // rank file (InterfaceTemperature::visit_state's names).
  struct InterfaceSlots {
    bool present = false;
    std::vector<double> boundaries;           // the bins' time boundaries (the same in every file)
    std::vector<int> levels;                  // the bins' levels (the same too)
    std::vector<int> nodes;                   // slot -> serial grid node
    std::vector<double> open;                 // the open interval's heat per area, per slot
    std::vector<std::vector<double>> columns;  // per slot: its heat per area in each bin
    double heat_recorded = 0.0;               // of the files whose particles this rank takes
  };

  void take_interface_histories(const ckpt::Reader& r, int j, bool particles) {
    if (!interface_) return;
    std::vector<double> boundaries, energy, open;
    std::vector<int> levels, nodes;
    double recorded = 0.0;
    r("interface/boundaries", boundaries);
    if (boundaries.empty()) return;  // the model is off (or started after this checkpoint)
    r("interface/levels", levels);
    r("interface/energy", energy);
    r("interface/open", open);
    r("interface/nodes", nodes);
    r("interface/heat_recorded", recorded);
    const std::string file = "checkpoint rank file " + std::to_string(j) + ": interface/";
    if (!iface_.present) {
      iface_.present = true, iface_.boundaries = boundaries, iface_.levels = levels;
    } else if (boundaries != iface_.boundaries || levels != iface_.levels) {
      throw std::runtime_error(file + "boundaries and levels differ from rank file 0's (the flux histories' "
                               "bins must be the same on every rank)");
    }
    const std::size_t slots = nodes.size();
    if (open.size() != slots || energy.size() != levels.size() * slots || boundaries.size() != levels.size() + 1)
      throw std::runtime_error(file + "energy, open and nodes do not fit " + std::to_string(levels.size()) + " bins of " +
                               std::to_string(slots) + " slots");
    const mechanics::Grid<Dim>& grid = mpm_.grid();
    for (std::size_t k = 0; k < slots; ++k) {
      if (nodes[k] < 0 || static_cast<std::size_t>(nodes[k]) >= grid.node_count())
        throw std::runtime_error(file + "nodes names grid node " + std::to_string(nodes[k]) + " outside the grid");
      const mechanics::IVec<Dim> lattice = grid.node_lattice(nodes[k]);
      bool mine = true;  // DMDA index = lattice + ghost (DecomposedHeat::owned_grid_nodes)
      for (int d = 0; d < Dim; ++d) {
        const int i = lattice[d] + mechanics::Grid<Dim>::ghost;
        mine = mine && i >= mine_[2 * d] && i < mine_[2 * d + 1];
      }
      if (!mine) continue;
      iface_.nodes.push_back(nodes[k]);
      iface_.open.push_back(open[k]);
      std::vector<double> column(levels.size());
      for (std::size_t b = 0; b < levels.size(); ++b) column[b] = energy[b * slots + k];
      iface_.columns.push_back(std::move(column));
    }
    if (particles) iface_.heat_recorded += recorded;
  }

  // A visitor of DecomposedHeat::visit_state that sets only the per-node arrays and the interface
  // histories of this rank's nodes.
  struct Assign {
    static constexpr bool reading = true;
    const std::vector<double>& pending;
    const std::vector<double>& M;
    const std::vector<double>& T;
    const std::vector<double>& local_M;
    const InterfaceSlots& iface;
    const std::vector<double>& iface_energy;
    void operator()(const char* name, std::vector<double>& v) const {
      const std::string n(name);
      if (n == "window/pending") v = pending;
      else if (n == "gather/M") v = M;
      else if (n == "gather/T") v = T;
      else if (n == "gather/local_M") v = local_M;
      else if (iface.present && n == "interface/boundaries") v = iface.boundaries;
      else if (iface.present && n == "interface/energy") v = iface_energy;
      else if (iface.present && n == "interface/open") v = iface.open;
    }
    void operator()(const char* name, std::vector<int>& v) const {
      const std::string n(name);
      if (iface.present && n == "interface/levels") v = iface.levels;
      else if (iface.present && n == "interface/nodes") v = iface.nodes;
    }
    void operator()(const char* name, double& v) const {
      if (iface.present && std::string(name) == "interface/heat_recorded") v = iface.heat_recorded;
    }
    template <class T> void operator()(const char*, T&) const {}  // the rest: read from file 0 already
  };

  Mpm& mpm_;
  bool heat_;
  bool interface_;
  std::array<int, 2 * Dim> mine_;
  typename Mpm::CheckpointState acc_;
  std::vector<double> pending_, M_, T_;
  std::vector<double> lagged_, lagged_step_;  // the regularisation's, on this rank's owned nodes
  bool regularized_ = false;
  InterfaceSlots iface_;
};

}  // namespace frictherm::coupling::detail
