// The decomposed run's output (decomposed_run_impl.hpp): series and metadata on rank 0 (OUT.h5, the
// serial writer), particle snapshots and the thermal grid's owned nodes per rank (OUT.rank<r>.h5), and
// at the end OUT.h5 published with OUT.xdmf (and OUT_nodes.xdmf) joining the rank files (issue 34: the XDMF goes with its result, never before it).
#include "distributed_run/decomposed_run_impl.hpp"

#include "run/node_output.hpp"
#include "run/particle_output.hpp"

namespace frictherm::coupling::decomposed {

template <int Dim>
void DecomposedRun<Dim>::open_output() {
  std::string error;
  if (rank_ == 0) {
    try {
      H5OutputOptions options;
      options.write_xdmf = false;  // OUT.xdmf joins the rank files (DecomposedOutput), published with OUT.h5
      options.via_temporary = true;
      options.replace_existing = overwrite() || resuming_;  // a resume rewrites OUT.h5 (checkpoint's rows first)
      out_ = std::make_unique<H5Output>(r_.output, Dim, options);
      write_start_metadata();
      out_->declare_series(series_names());
      if (hot_) hot_->declare_table(*out_);
      if (hot_ && s_.thermal.continuation_duration > 0.0) out_->declare_table("hotspot_fates", hotspot_fate_columns());
      if (resuming_) rewrite_rows();
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  if (const std::string why = detail::agreed_error(comm_, error); !why.empty()) throw OutputError(why);
  try {  // OUT.xdmf is not written during the run: publish() writes it with OUT.h5 (issue 34)
    snapshots_out_ = resuming_ ? std::make_unique<DecomposedOutput>(comm_, output_base(r_.output), Dim, snapshots_,
                                                                    detail::split_grids(xdmf_grids_),
                                                                    redistributed_from_ > 0, false)
                               : std::make_unique<DecomposedOutput>(comm_, output_base(r_.output), Dim, overwrite(),
                                                                    false);
    if (resuming_) snapshots_out_->restore_reference_grids(detail::split_grids(xdmf_reference_grids_));
    if (resuming_) snapshots_out_->restore_node_grids(detail::split_grids(xdmf_node_grids_));
  } catch (const std::exception& e) {
    throw OutputError(e.what());
  }
}

template <int Dim>
void DecomposedRun<Dim>::write_start_metadata() {
  // The serial run's start metadata, by its code (runner_output.cpp), of the run's grid, the scene's
  // materials, bodies and options and the global particle count; threads: OpenMP threads per rank.
  detail::write_microstructure_images(*out_, s_, r_.output);
  detail::write_start_metadata<Dim>(*out_, s_, detail::RunLayout<Dim>{mpm_->grid(), s_.materials, body_names(),
                                                                        s_.options, r_.particles},
                                    o_);
  out_->write_metadata("run_id", run_id_);
  out_->write_metadata("engine", "decomposed");
  out_->write_metadata("ranks", size_);
  std::string grid;
  for (int p : mpm_->processes()) grid += (grid.empty() ? "" : " x ") + std::to_string(p);
  out_->write_metadata("process_grid", grid);
  out_->write_metadata("snapshots", xdmf_path_for(r_.output));
}

template <int Dim>
std::vector<std::string> DecomposedRun<Dim>::body_names() const {
  std::vector<std::string> names;  // the serial Simulation's bodies: the scene's, in order
  for (const BodySpec& b : s_.bodies) names.push_back(b.name);
  return names;
}

template <int Dim>
std::vector<std::pair<int, int>> DecomposedRun<Dim>::contact_pairs() const {
  std::vector<std::pair<int, int>> pairs;  // the serial Simulation::contact_pairs: the scene's, in order
  for (const ContactPairSpec& p : s_.contact.pairs) pairs.emplace_back(p.material_a, p.material_b);
  return pairs;
}

// Each body's mass-weighted sums over this rank's particles, then over the ranks (one reduction):
// the serial series_row's kernel (particle_output.hpp) on the local particles.
template <int Dim>
detail::BodySums<Dim> DecomposedRun<Dim>::body_sums(const mechanics::DecomposedLocalParticles& p) const {
  detail::BodySums<Dim> sums(s_.bodies.size());
  const std::vector<double> T = mpm_->particle_scalar(temperature_);
  const std::vector<double> body = mpm_->particle_scalar(mpm_->particle_scalar_index("body"));
  using V = mechanics::Vec<Dim>;
  for (std::size_t k = 0; k < p.mass.size(); ++k)
    sums.add(static_cast<std::size_t>(body[k]), p.mass[k], T[k], Eigen::Map<const V>(&p.position[Dim * k]),
             Eigen::Map<const V>(&p.initial_position[Dim * k]), Eigen::Map<const V>(&p.velocity[Dim * k]));
  std::vector<double> flat = sums.flat();
  MPI_Allreduce(MPI_IN_PLACE, flat.data(), static_cast<int>(flat.size()), MPI_DOUBLE, MPI_SUM, comm_);
  sums.assign(flat);
  return sums;
}

template <int Dim>
std::vector<std::string> DecomposedRun<Dim>::series_names() const {
  // The serial run's first columns, energy books included (detail::series_names, runner_output.cpp).
  std::vector<std::string> n = detail::series_names(Dim);
  // Then the serial run's per-body and contact columns in its order (issue 32).
  detail::append_body_series_names(n, body_names(), Dim);
  if (s_.contact.enabled) detail::append_contact_series_names(n, body_names(), s_.materials, contact_pairs(), Dim);
  if (const mechanics::PenaltyContact<Dim>* pc = mpm_->penalty_contact()) {  // the serial run's penalty columns
    std::vector<mechanics::PenaltyPairInfo> pairs;
    for (std::size_t k = 0; k < pc->pair_count(); ++k) pairs.push_back({pc->pair(k).master, pc->pair(k).slave});
    detail::append_penalty_series_names(n, pairs, s_.materials);  // decomposed fields are materials
  }
  if (heat_) {
    n.insert(n.end(), {"heat_delivered", "thermal_energy_change", "max_temperature"});
    for (const std::string& c : detail::DecomposedHotSpots<Dim>::series_names()) n.push_back(c);
    n.insert(n.end(), {"thermal_windows", "work_received", "nodal_energy_change"});
    if (s_.thermal.coupler.plastic.enabled) n.insert(n.end(), {"plastic_work", "plastic_heat"});
    if (heat_->reaction_enabled()) n.insert(n.end(), {"reaction_heat", "max_reaction_progress"});
    if (heat_->interface_enabled()) n.emplace_back("max_interface_temperature");  // the serial columns
    if (heat_->interface_patches()) n.emplace_back("max_node_interface_temperature");
    if (heat_->interface_enabled() && heat_->reaction_enabled()) n.emplace_back("max_interface_reaction_progress");
  }
  return n;
}

template <int Dim>
void DecomposedRun<Dim>::series(double time) {
  const Clock::time_point c0 = Clock::now();
  const double row_time = std::isnan(time) ? time_ : time;
  const mechanics::DecomposedLocalParticles p = mpm_->local_particle_data(true);
  // Momentum of the deformable particles, as Simulation::linear_momentum (a rigid wall's prescribed
  // motion is not part of the body's).
  double P[Dim] = {};
  for (std::size_t k = 0; k < p.mass.size(); ++k) {
    if (s_.materials[static_cast<std::size_t>(p.material[k])].is_rigid()) continue;
    for (int d = 0; d < Dim; ++d) P[d] += p.mass[k] * p.velocity[Dim * k + static_cast<std::size_t>(d)];
  }
  MPI_Allreduce(MPI_IN_PLACE, P, Dim, MPI_DOUBLE, MPI_SUM, comm_);
  // The energy books (the serial series_row's columns and definitions, DecomposedMpm::energy_balance),
  // with the frictional work of the scene's heating order (also without heat, as the serial run).
  const mechanics::EnergyBalance books =
      mpm_->energy_balance(s_.thermal.heating_order);
  // The serial strain_energy and total_energy columns leave out the penalty springs' energy, which
  // the books' stored energy holds (the same on every rank).
  const mechanics::PenaltyContact<Dim>* pc = mpm_->penalty_contact();
  const double strain = pc ? books.stored - pc->stored_energy() : books.stored;
  std::vector<double> row{row_time, static_cast<double>(step_), last_dt_, books.kinetic, strain,
                          books.kinetic + strain, books.external_work};
  for (int d = 0; d < Dim; ++d) row.push_back(P[d]);
  row.insert(row.end(), {books.rigid_work, books.damping_work, books.plastic_work, books.lost(),
                         books.numerical_dissipation(), books.contact_normal_work, books.boundary_stop_work,
                         books.stored_lead});
  const detail::BodySums<Dim> bodies = body_sums(p);
  bodies.append_means(row);
  if (s_.contact.enabled) {  // the serial series_row's contact columns, from sums over ranks
    const std::size_t nm = s_.materials.size();
    const std::vector<std::pair<int, int>> pairs = contact_pairs();
    std::vector<double> work[2];  // per order: the total, then per pair
    for (const auto each : {mechanics::HeatingOrder::first, mechanics::HeatingOrder::second}) {
      std::vector<double>& w = work[each == mechanics::HeatingOrder::first ? 0 : 1];
      w.push_back(mpm_->cumulative_frictional_work(each));
      const std::vector<double> pair_work = mpm_->cumulative_pair_work(each);
      for (const auto& [a, b] : pairs) w.push_back(pair_work[mechanics::pair_book_index(a, b, nm)]);
      row.insert(row.end(), w.begin(), w.end());
    }
    const mechanics::DecomposedContactStats cs = mpm_->contact_stats();
    row.insert(row.end(), {static_cast<double>(cs.contact_nodes), static_cast<double>(cs.sliding_nodes)});
    bodies.append_velocities(row);
    // The work handed to the heat (the scene's heating order, also without heat, as the books above).
    const bool first = s_.thermal.heating_order == mechanics::HeatingOrder::first;
    detail::append_heat_rates(row, work[first ? 0 : 1], time_, series_memory_);  // the serial sim.time()
  }
  if (pc) detail::append_penalty_row(row, *pc, mpm_->boundary_points());
  if (heat_) {
    const DecomposedHeatBooks& b = heat_->books();
    // The highest temperature of the conducting particles over all ranks, from the last update.
    row.insert(row.end(), {b.heat_delivered, b.particle_energy_change, hot_->tracker().max_temperature()});
    hot_->extend_series_row(row);
    row.insert(row.end(), {static_cast<double>(b.windows + b.continuation_intervals), b.work_received,
                           b.nodal_energy_change});
    if (s_.thermal.coupler.plastic.enabled) row.insert(row.end(), {b.plastic_work_received, b.plastic_heat_received});
    if (heat_->reaction_enabled()) row.insert(row.end(), {b.reaction_heat_released, heat_->max_reaction_progress()});
    if (heat_->interface_enabled()) {  // NaN until some node has received frictional heat, as the serial run
      const double t_int = heat_->max_interface_temperature();
      row.push_back(std::isfinite(t_int) ? t_int : std::numeric_limits<double>::quiet_NaN());
      if (heat_->interface_patches()) {
        const double t_node = heat_->max_node_interface_temperature();
        row.push_back(std::isfinite(t_node) ? t_node : std::numeric_limits<double>::quiet_NaN());
      }
    }
    if (heat_->interface_enabled() && heat_->reaction_enabled()) row.push_back(heat_->max_interface_reaction_progress());
  }
  std::string error;  // rank 0's write failure, agreed below so that no rank goes on alone
  if (out_) {
    series_rows_.insert(series_rows_.end(), row.begin(), row.end());  // for checkpoints
    series_columns_ = static_cast<long>(row.size());
    try {
      out_->append_series(row);
      if (hot_) hot_->append_table_rows(*out_, row_time);
      if (seconds_since(last_flush_) >= o_.flush_interval) {
        out_->flush();
        last_flush_ = Clock::now();
      }
    } catch (const std::exception& e) {
      note_write_error(e.what());
      error = std::string("writing '") + out_->live_path() + "': " + e.what();
    }
  }
  if (const std::string why = detail::agreed_error(comm_, error); !why.empty()) throw std::runtime_error(why);
  last_series_step_ = step_;
  output_seconds_ += seconds_since(c0);
}

namespace {

// The decomposed rank file as write_particle_fields's output (particle_output.hpp).
struct SnapshotFields {
  DecomposedSnapshot& snap;
  void snapshot_field(const std::string& name, const double* data, std::size_t n, int components) {
    snap.fields.emplace_back(name, std::vector<double>(data, data + n * static_cast<std::size_t>(components)), components);
  }
  void snapshot_field(const std::string& name, const std::int32_t* data, std::size_t n) {
    snap.integer_fields.emplace_back(name, std::vector<int>(data, data + n));
  }
};

}  // namespace

// The serial snapshot's fields besides those DecomposedOutput writes itself (position, velocity,
// temperature, material): displacement and initial_position, stress, stress_zz, mass, volume, body,
// as the scene's output.fields lists them, by the serial kernel on this rank's particles (issue 32).
template <int Dim>
void DecomposedRun<Dim>::snapshot_fields(const mechanics::DecomposedLocalParticles& p, DecomposedSnapshot& snap) const {
  using V = mechanics::Vec<Dim>;
  using M = mechanics::Mat<Dim>;
  const std::size_t n = p.mass.size();
  std::vector<V> x(n), X(n), v(n);
  std::vector<M> stress(n);
  std::vector<std::int32_t> body(n);
  const std::vector<double> b = mpm_->particle_scalar(mpm_->particle_scalar_index("body"));
  for (std::size_t k = 0; k < n; ++k) {
    x[k] = Eigen::Map<const V>(&p.position[Dim * k]);
    X[k] = Eigen::Map<const V>(&p.initial_position[Dim * k]);
    v[k] = Eigen::Map<const V>(&p.velocity[Dim * k]);
    stress[k] = Eigen::Map<const M>(&p.stress[Dim * Dim * k]);
    body[k] = static_cast<std::int32_t>(b[k]);
  }
  detail::ParticleArrays<Dim> a;
  a.n = n;
  a.position = x.data();
  a.velocity = v.data();
  a.initial_position = X.data();
  a.stress = stress.data();
  a.stress_zz = &p.stress_zz;
  a.mass = &p.mass;
  a.volume = &p.volume;
  a.body = body.data();
  std::vector<std::string> fields;
  for (const std::string& f : s_.output.fields)
    if (f != "position" && f != "velocity" && f != "temperature" && f != "material") fields.push_back(f);
  SnapshotFields out{snap};
  detail::write_particle_fields(out, a, fields);
}

template <int Dim>
void DecomposedRun<Dim>::snapshot(double time) {
  const Clock::time_point c0 = Clock::now();
  const mechanics::DecomposedLocalParticles p = mpm_->local_particle_data(true);
  DecomposedSnapshot snap;
  snap.id = p.id;
  snap.position = p.position;
  snap.velocity = p.velocity;
  snap.material = p.material;
  snap.temperature = mpm_->particle_scalar(temperature_);
  snapshot_fields(p, snap);
  if (heat_ && heat_->interface_enabled())  // T_int,p of the last update, as the serial snapshot field
    snap.fields.emplace_back("interface_temperature",
                             mpm_->particle_scalar(mpm_->particle_scalar_index("interface_temperature")));
  if (heat_ && heat_->reaction_enabled())  // λ_p, as the serial snapshot field
    snap.fields.emplace_back("reaction_progress", mpm_->particle_scalar(mpm_->particle_scalar_index("reaction_progress")));
  if (heat_ && heat_->interface_reaction().started())  // λ_int,p in the particles' current order
    snap.fields.emplace_back("interface_reaction_progress", heat_->interface_reaction_progress(*mpm_));
  if (heat_) {  // the thermal grid's owned unknowns, by the serial writer (node_output.hpp)
    const DecomposedThermalNodes nodes = heat_->thermal_nodes();
    detail::write_node_fields<Dim>(snap, mpm_->grid(), nodes.grid_node, nodes.temperature.data(),
                                   nodes.heat_capacity.data());
  }
  snapshots_out_->write(step_, std::isnan(time) ? time_ : time, snap);
  ++snapshots_;
  last_snapshot_step_ = step_;
  output_seconds_ += seconds_since(c0);
}

template <int Dim>
void DecomposedRun<Dim>::finish_output() {
  std::string error;
  int refused = 0;
  if (out_) {
    try {
      error = publish();
    } catch (const std::exception& e) {
      error = e.what();
      refused = 1;
    }
  }
  const std::string why = detail::agreed_error(comm_, error);
  MPI_Bcast(&refused, 1, MPI_INT, 0, comm_);
  if (why.empty()) return;
  if (refused) throw OutputError(why);
  throw DecomposedRunError(why);
}

template <int Dim>
std::string DecomposedRun<Dim>::publish() {
  r_.series_rows = out_->series_rows();
  try {
    if (!write_error_.empty()) throw std::runtime_error(write_error_);
    write_end_metadata();
    // OUT.xdmf (and OUT_reference.xdmf) with OUT.h5, as the serial run's
    out_->publish_xdmf_with_result(snapshots_out_->xdmf_text(), snapshots_out_->reference_xdmf_text(),
                                   snapshots_out_->nodes_xdmf_text());
    out_->sync();  // before the name: the published result is on disk
  } catch (const std::exception& e) {
    const std::string live = out_->live_path();
    out_->abandon();
    out_.reset();
    return (r_.status == RunResult::Status::failed ? r_.message + "; then " : std::string()) +
           "writing the result failed at step " + std::to_string(step_) + ", t = " + format_number(time_) +
           " s: " + e.what() + "; what was written stays in " + live + " (status running), not published as " +
           r_.output;
  }
  std::unique_ptr<H5Output> out = std::move(out_);
  out->close();  // renames OUT.h5.<pid>.part onto OUT.h5
  return "";
}

template <int Dim>
void DecomposedRun<Dim>::write_end_metadata() {
  if (r_.status == RunResult::Status::interrupted) out_->write_metadata("interruption", r_.message);
  for (const auto& [name, seconds] : r_.phase_seconds) out_->write_metadata("time_" + name, seconds);
  if (heat_)
    detail::write_decomposed_heat_metadata(*out_, s_, *heat_, pending_heat_, particle_reaction_heat_,
                                           hot_->tracker().ids_issued());
  const char* status = r_.status == RunResult::Status::failed                 ? "failed"
                       : r_.status == RunResult::Status::stopped_at_max_steps ? "stopped_at_max_steps"
                       : r_.status == RunResult::Status::interrupted          ? "interrupted"
                                                                              : "completed";
  out_->write_metadata("status", status);
  if (checkpoints_written_ > 0) {
    out_->write_metadata("checkpoints_written", checkpoints_written_);
    out_->write_metadata("checkpoint_write_time", checkpoint_seconds_);  // s, this process's checkpoints
  }
  if (resuming_) out_->write_metadata("resumed_from", o_.resume_checkpoint);
  if (redistributed_from_ > 0) out_->write_metadata("resumed_from_ranks", redistributed_from_);
  out_->write_metadata("steps", r_.steps);
  out_->write_metadata("final_time", r_.time);
  out_->write_metadata("wall_time", r_.wall_time);
}

template <int Dim>
void DecomposedRun<Dim>::rewrite_rows() {
  const auto c = static_cast<std::size_t>(series_columns_);
  for (std::size_t a = 0; c > 0 && a + c <= series_rows_.size(); a += c)
    out_->append_series(std::vector<double>(series_rows_.begin() + static_cast<long>(a),
                                            series_rows_.begin() + static_cast<long>(a + c)));
  if (hot_) hot_->rewrite_table_rows(*out_);
  out_->write_metadata("resumed_at_step", step_);
}

#define FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(D) \
  template void DecomposedRun<D>::open_output(); \
  template void DecomposedRun<D>::write_start_metadata(); \
  template std::vector<std::string> DecomposedRun<D>::series_names() const; \
  template void DecomposedRun<D>::series(double); \
  template void DecomposedRun<D>::snapshot(double); \
  template void DecomposedRun<D>::snapshot_fields(const mechanics::DecomposedLocalParticles&, DecomposedSnapshot&) const; \
  template std::vector<std::string> DecomposedRun<D>::body_names() const; \
  template std::vector<std::pair<int, int>> DecomposedRun<D>::contact_pairs() const; \
  template detail::BodySums<D> DecomposedRun<D>::body_sums(const mechanics::DecomposedLocalParticles&) const; \
  template void DecomposedRun<D>::finish_output(); \
  template std::string DecomposedRun<D>::publish(); \
  template void DecomposedRun<D>::write_end_metadata(); \
  template void DecomposedRun<D>::rewrite_rows();
FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(2)
FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(3)
#undef FRICTHERM_INSTANTIATE_DECOMPOSED_RUN

}  // namespace frictherm::coupling::decomposed
