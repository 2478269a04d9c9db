// How a decomposed run ends when something throws (decomposed_run_impl.hpp, decomposed_failure.hpp;
// issue 34): the failing state gathered under /failure of OUT.h5 when every rank failed alike; on
// one rank alone, rank 0 publishes what it holds and every rank ends.
#include "distributed_run/decomposed_run_impl.hpp"

namespace frictherm::coupling::decomposed {

template <int Dim>
void DecomposedRun<Dim>::write_failure(long step, double time) {
  const std::vector<typename Mpm::Particle> all = mpm_->gather();
  if (rank_ != 0 || !out_) return;
  detail::write_failure_record(*out_, step, time, r_.message, [&] {
    const std::size_t n = all.size();
    std::vector<double> position(n * Dim), velocity(n * 3, 0.0);
    std::vector<std::int32_t> material(n);
    for (std::size_t k = 0; k < n; ++k) {
      for (int d = 0; d < Dim; ++d) {
        position[k * Dim + static_cast<std::size_t>(d)] = all[k].position[d];
        velocity[k * 3 + static_cast<std::size_t>(d)] = all[k].velocity[d];
      }
      material[k] = all[k].material;
    }
    out_->snapshot_field("position", position.data(), n, Dim);
    out_->snapshot_field("velocity", velocity.data(), n, 3);
    out_->snapshot_field("material", material.data(), n);
  }, [&](const char* what) { note_write_error(what); });  // finish_output says that the result is incomplete
}

template <int Dim>
void DecomposedRun<Dim>::fail(long step, double time, const std::string& message) {
  r_.status = RunResult::Status::failed;
  r_.message = message;
  write_failure(step, time);
}

template <int Dim>
void DecomposedRun<Dim>::note_write_error(const std::string& what) {
  if (rank_ == 0 && write_error_.empty()) write_error_ = what;
}

template <int Dim>
std::string DecomposedRun<Dim>::agreed(const std::string& what) {
  if (std::optional<std::string> m = detail::agree_on_failure(failure_comm_, what, agreement_seconds_)) return *m;
  const std::string why = "step " + std::to_string(step_) + ", t = " + format_number(time_) + " s: on rank " +
                          std::to_string(rank_) + " alone: " + what +
                          " (the other ranks were waiting in a collective call: every rank ends; the failing "
                          "state is not gathered)";
  std::cerr << "frictherm: simulation failed: " << why
            << (rank_ == 0 ? std::string()
                           : "; the result is not published: what rank 0 wrote stays in " + r_.output +
                                 ".<pid>.part (status running)")
            << '\n';
  if (rank_ == 0 && out_) {
    r_.status = RunResult::Status::failed;
    r_.message = why;
    try {
      out_->write_metadata("failure", why);
    } catch (const std::exception& e) {
      note_write_error(e.what());
    }
    r_.wall_time = 0.0;
    std::string left;
    try {
      left = publish();
    } catch (const std::exception& e) {
      left = e.what();
    }
    std::cerr << "frictherm: " << (left.empty() ? "kept " + r_.output + " (status failed)" : left) << '\n';
  }
  claim_.reset();  // the output's lock file (MPI_Abort runs no destructor)
  std::cerr.flush();
  MPI_Abort(comm_, 1);
  std::abort();  // not reached
}

#define FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(D) \
  template void DecomposedRun<D>::write_failure(long step, double time); \
  template void DecomposedRun<D>::fail(long step, double time, const std::string& message); \
  template void DecomposedRun<D>::note_write_error(const std::string& what); \
  template std::string DecomposedRun<D>::agreed(const std::string& what);
FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(2)
FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(3)
#undef FRICTHERM_INSTANTIATE_DECOMPOSED_RUN

}  // namespace frictherm::coupling::decomposed
