#pragma once
// Resuming a decomposed checkpoint on another number of ranks (docs/checkpoints.md, "Decomposed
// runs"): rank r of K' takes the particles of the checkpoint's rank files j ≡ r (mod K'), every swarm
// field as written, then the swarm migrates each particle to its owner in the new decomposition; the
// mechanics' cumulative work books of file j go with its particles (their sum over ranks is kept);
// the heat's per-node state (pending work, M_i and T_i of the last gather) is copied node by node from
// the file whose rank owned the node (DMDA indices are the same for every K), M_i on the ghosted box
// from the new owners; so is the contact regularisation's lagged normal traction per node. The particles' order on a rank and the ranks' sums then differ from an
// uninterrupted K'-rank run: results agree to the round-off of reordered sums, not bit-for-bit.
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
  Redistribution(Mpm& mpm, bool heat) : mpm_(mpm), heat_(heat), mine_(mpm.owned_nodes()) {
    acc_ = mpm.checkpoint_state();  // the field names; emptied
    for (auto& r : acc_.reals) r.second.clear();
    for (auto& r : acc_.integers) r.second.clear();
    acc_.cumulative_first = acc_.cumulative_second = 0.0;
    acc_.external_work = acc_.damping_work = acc_.rigid_work = 0.0;
    acc_.contact_normal_work = acc_.boundary_stop_work = 0.0;
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
  }

  /// Collective: the particles into the swarm (migrated) and the per-node heat into `heat`.
  void finish(DecomposedHeat* heat) {
    if (regularized_) acc_.lagged_normal_traction = lagged_, acc_.lagged_normal_step = lagged_step_;
    mpm_.restore_checkpoint_state(acc_, true);
    if (!heat) return;
    std::vector<double> local_M;
    mpm_.owned_to_local(M_, 1, local_M);
    Assign a{pending_, M_, T_, local_M};
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

  // A visitor of DecomposedHeat::visit_state that sets only the per-node arrays.
  struct Assign {
    static constexpr bool reading = true;
    const std::vector<double>& pending;
    const std::vector<double>& M;
    const std::vector<double>& T;
    const std::vector<double>& local_M;
    void operator()(const char* name, std::vector<double>& v) const {
      const std::string n(name);
      if (n == "window/pending") v = pending;
      else if (n == "gather/M") v = M;
      else if (n == "gather/T") v = T;
      else if (n == "gather/local_M") v = local_M;
    }
    template <class T> void operator()(const char*, T&) const {}  // the rest: read from file 0 already
  };

  Mpm& mpm_;
  bool heat_;
  std::array<int, 2 * Dim> mine_;
  typename Mpm::CheckpointState acc_;
  std::vector<double> pending_, M_, T_;
  std::vector<double> lagged_, lagged_step_;  // the regularisation's, on this rank's owned nodes
  bool regularized_ = false;
};

}  // namespace frictherm::coupling::detail
