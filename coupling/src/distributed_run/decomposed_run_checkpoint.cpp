// Checkpoints of a decomposed run (decomposed_run_impl.hpp, decomposed_checkpoint.hpp): the state
// each rank writes and reads, the marks and run id as the serial run's, a checkpoint of another rank
// count redistributed (decomposed_redistribute.hpp); a resumed run rewrites OUT.h5 with the
// checkpoint's series rows, keeping the rank files' snapshots up to it.
#include "distributed_run/decomposed_run_impl.hpp"

namespace frictherm::coupling::decomposed {

template <int Dim>
void DecomposedRun<Dim>::checkpoint(bool end_of_loading) {
  const Clock::time_point c0 = Clock::now();
  CheckpointMarks m;
  m.end_of_loading = end_of_loading;
  m.step = step_;
  m.time = time_;
  m.series_rows = series_columns_ > 0 ? static_cast<long>(series_rows_.size()) / series_columns_ : 0;
  m.snapshots = snapshots_;
  m.run_id = run_id_;  // rank 0 writes the marks
  if (hot_) m.table_rows.emplace_back("hotspots", hot_->table_rows());
  xdmf_grids_ = detail::join_grids(snapshots_out_->xdmf_grids());
  xdmf_reference_grids_ = detail::join_grids(snapshots_out_->reference_grids());
  xdmf_node_grids_ = detail::join_grids(snapshots_out_->node_grids());
  try {
    detail::write_decomposed_checkpoint(
        comm_, checkpoint_file_, s_, Dim, ++generation_, m, [&](const ckpt::Writer& w) { visit_rank_state(w); },
        [&](const ckpt::Writer& w) { visit_global_state(w); });
  } catch (const std::runtime_error& e) {  // on every rank; the previous checkpoint is whole
    throw OutputError(e.what());
  }
  if (rank_ == 0 && redistributed_from_ > size_ && checkpoints_written_ == 0)  // the resumed generation's
    for (int j = size_; j < redistributed_from_; ++j)                          // files of ranks gone
      std::remove(detail::decomposed_rank_checkpoint(checkpoint_file_, generation_ - 1, j).c_str());
  last_checkpoint_ = Clock::now();
  ++checkpoints_written_;
  checkpoint_seconds_ += seconds_since(c0);
}

// Collective: what a rank file must fit (ckpt::check_rank_file), from the decomposition built from
// the scene; `ghosted` false for the files of another decomposition.
template <int Dim>
ckpt::RankSizes DecomposedRun<Dim>::rank_sizes(bool ghosted) const {
  ckpt::RankSizes z;
  z.particles = static_cast<long>(mpm_->global_particles());
  z.materials = static_cast<long>(s_.materials.size());
  for (const auto& m : s_.materials) z.rigid.push_back(m.is_rigid());
  const std::array<int, 2 * Dim> box = mpm_->ghosted_nodes();
  z.ghosted_nodes = ghosted ? 1 : -1;
  const typename Mpm::CheckpointState st = mpm_->checkpoint_state();  // the swarm's fields as built
  const auto local = static_cast<long>(mpm_->local_particles());
  std::vector<long> components;  // values per particle of each field (the largest over ranks: some may hold none)
  std::vector<double> largest(Dim, 0.0);  // the largest half size a built particle has
  for (const auto& [name, values] : st.reals) {
    components.push_back(local > 0 ? static_cast<long>(values.size()) / local : 0);
    if (name == "half_size")
      for (std::size_t k = 0; k < values.size(); ++k) largest[k % Dim] = std::max(largest[k % Dim], values[k]);
  }
  MPI_Allreduce(MPI_IN_PLACE, components.data(), static_cast<int>(components.size()), MPI_LONG, MPI_MAX, comm_);
  MPI_Allreduce(MPI_IN_PLACE, largest.data(), Dim, MPI_DOUBLE, MPI_MAX, comm_);
  for (std::size_t k = 0; k < st.reals.size(); ++k) z.fields.emplace_back(st.reals[k].first, components[k]);
  z.heat = heat_ != nullptr;
  for (int d = 0; d < Dim; ++d) {  // Grid::contains
    z.nodes.push_back(grid_->nodes_per_dim()[d]);
    if (ghosted) z.ghosted_nodes *= box[2 * d + 1] - box[2 * d];
    z.lo.push_back(grid_->lo()[d]);
    z.hi.push_back(grid_->lo()[d] + grid_->cell_size()[d] * grid_->cells()[d]);
    z.cell.push_back(grid_->cell_size()[d]);
    z.max_half.push_back(std::max(0.5 * grid_->cell_size()[d], largest[static_cast<std::size_t>(d)]));
  }
  return z;
}

template <int Dim>
void DecomposedRun<Dim>::restore() {
  if (const int old = checkpoint_ranks(o_.resume_checkpoint); old > 0 && old != size_) {
    redistribute(old);
    return;
  }
  const ckpt::RankSizes sizes = rank_sizes(true);
  try {  // read errors are agreed by every rank
    generation_ = detail::read_decomposed_checkpoint(
        comm_, o_.resume_checkpoint, Dim, sizes, [&](const ckpt::Reader& r) { visit_rank_state(r); },
        [&](const ckpt::Reader& r) { visit_global_state(r); });
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
  std::string error;
  try {
    mpm_->restore_checkpoint_state(restored_);
  } catch (const std::exception& e) {
    error = o_.resume_checkpoint + ": " + e.what();
  }
  if (const std::string why = detail::agreed_error(comm_, error); !why.empty()) throw OutputError(why);
  restored_ = {};
}

template <int Dim>
template <class V>
void DecomposedRun<Dim>::visit_rank_state(const V& v) {
  typename Mpm::CheckpointState st = mpm_->checkpoint_state();  // reading: the names and a template
  for (auto& [name, values] : st.reals) v(("mechanics/" + name).c_str(), values);
  for (auto& [name, values] : st.integers) v(("mechanics/" + name).c_str(), values);
  v("mechanics/time", st.time);
  v("mechanics/cumulative_work_first", st.cumulative_first);
  v("mechanics/cumulative_work_second", st.cumulative_second);
  v("mechanics/external_work", st.external_work);
  v("mechanics/damping_work", st.damping_work);
  v("mechanics/rigid_work", st.rigid_work);
  v("mechanics/contact_normal_work", st.contact_normal_work);
  v("mechanics/boundary_stop_work", st.boundary_stop_work);
  v("mechanics/stored_energy_lead", st.stored_lead);
  v("mechanics/stress_power", st.stress_power);
  v("mechanics/stress_dt", st.stress_dt);
  v("mechanics/initial_energy", st.initial_energy);
  v("mechanics/empty_node_mass", st.empty_node_mass);
  v("mechanics/work_first", st.work_first);
  v("mechanics/work_second", st.work_second);
  v("mechanics/pair_work_first", st.pair_first);  // this rank's part of the per-pair books
  v("mechanics/pair_work_second", st.pair_second);
  v("mechanics/contact_stats", st.stats);
  // The normal-stress regularisation's lagged tractions per owned node (the serial checkpoint's names;
  // empty when it is off) and its clock.
  v("mechanics/contact/lagged_normal_traction", st.lagged_normal_traction);
  v("mechanics/contact/lagged_normal_step", st.lagged_normal_step);
  v("mechanics/steps_taken", st.steps_taken);
  std::vector<long> owned;  // this rank's owned nodes (DMDA indices, [begin, end) per axis): redistribution
  if constexpr (!V::reading) for (int b : mpm_->owned_nodes()) owned.push_back(b);
  v("mechanics/owned_nodes", owned);
  if constexpr (V::reading) restored_ = std::move(st);
  if (heat_) heat_->visit_state(v);
}

namespace {

// A checkpoint visitor naming every member under penalty_contact/.
template <class V>
struct PenaltyState {
  static constexpr bool reading = V::reading;
  const V& v;
  template <class T>
  void operator()(const char* name, T& member) const {
    v(("penalty_contact/" + std::string(name)).c_str(), member);
  }
};

}  // namespace

template <int Dim>
template <class V>
void DecomposedRun<Dim>::visit_global_state(const V& v) {
  v("run/time", time_);
  v("run/step", step_);
  v("run/last_dt", last_dt_);
  v("run/snapshots", snapshots_);
  v("run/last_series_step", last_series_step_);
  v("run/last_snapshot_step", last_snapshot_step_);
  v("output/series_rows", series_rows_);
  v("output/series_columns", series_columns_);
  v("run/series_memory/time", series_memory_.time);  // the serial checkpoint's names
  v("run/series_memory/has_previous", series_memory_.has_previous);
  v("run/series_memory/work", series_memory_.work);
  v("output/xdmf_grids", xdmf_grids_);
  v("output/xdmf_reference_grids", xdmf_reference_grids_);
  v("output/xdmf_node_grids", xdmf_node_grids_);
  if (hot_) hot_->visit_state(v);
  // Penalty contact: the boundary points and PenaltyContact::visit_state (slip histories, books, the
  // frequency bound of the next step), the same on every rank, so once, in the global file that every
  // rank reads, under penalty_contact/ (the serial checkpoint's names below it).
  if (mechanics::PenaltyContact<Dim>* pc = mpm_->penalty_contact()) {
    const PenaltyState<V> p{v};
    mechanics::BoundaryPoints<Dim>& bp = mpm_->boundary_points();
    p("boundary/position", bp.position);
    p("boundary/velocity", bp.velocity);
    pc->visit_state(p);
    if constexpr (V::reading)
      if (bp.position.size() != bp.field.size() || bp.velocity.size() != bp.field.size())
        throw std::runtime_error("checkpoint: penalty_contact/boundary holds " + std::to_string(bp.position.size()) +
                                 " points, the scene has " + std::to_string(bp.field.size()));
  }
}

template <int Dim>
void DecomposedRun<Dim>::redistribute(int old) {
  detail::Redistribution<Dim> re(*mpm_, heat_ != nullptr, heat_ && heat_->interface_enabled());
  const ckpt::RankSizes sizes = rank_sizes(false);
  try {
    generation_ = detail::read_redistributed_checkpoint(
        comm_, o_.resume_checkpoint, Dim, sizes,
        [&](const ckpt::Reader& r, int j) {
          re.take(r, j, j % size_ == rank_);
          if (heat_ && j == 0) heat_->visit_state(r);  // books and window: the same in every file
        },
        [&](const ckpt::Reader& r) { visit_global_state(r); });
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
  re.finish(heat_.get());
  redistributed_from_ = old;
}

#define FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(D) \
  template void DecomposedRun<D>::checkpoint(bool); \
  template void DecomposedRun<D>::restore(); \
  template void DecomposedRun<D>::redistribute(int old);
FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(2)
FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(3)
#undef FRICTHERM_INSTANTIATE_DECOMPOSED_RUN

}  // namespace frictherm::coupling::decomposed
