#pragma once
// Thread policy for runs on shared machines (issue 13, docs/performance.md "Threads"):
//
//   int main(int argc, char** argv) {
//     frictherm::coupling::ensure_passive_wait(argv);   // first thing: may re-execute the program
//     ...
//     omp_set_num_threads(frictherm::coupling::default_thread_count(particles));
//
// * Waiting threads sleep instead of spinning (OMP_WAIT_POLICY=passive) unless the user chose a
//   policy: a spinning thread at a barrier takes the core a descheduled team mate needs when another
//   process is busy on the machine. The OpenMP runtime reads the variable once, when it loads, so the
//   program sets it and executes itself again (once: the variable is then set).
// * The default thread count (no --threads, no run.threads, no OMP_NUM_THREADS) is at most the
//   number of cores not busy with other processes at the start, and one thread per 2000 particles
//   (the mechanics step's own threshold: below it the fork/join costs more than the shared work).
// * A run whose waiting threads spin (an MPI build, where the launcher owns the process and the
//   policy is not set, or OMP_WAIT_POLICY=active), on the default count or on one given by --threads
//   or run.threads (issue 35; said on stderr), watches whether its threads get their cores
//   (ThreadGovernor): while another process holds one, two spinning threads run 10-20 times slower
//   than one, so it goes on with one thread and tries again later.
#include <chrono>
#include <cstddef>
#include <string>

namespace frictherm::coupling {

/// If OMP_WAIT_POLICY is unset: sets it to "passive" and executes /proc/self/exe again with argv.
/// Returns only if no re-execution happened (the policy was set already, or exec failed).
void ensure_passive_wait(char** argv);

/// Cores not running other processes now: online cores minus the fewest runnable tasks of
/// /proc/loadavg other than this process over five looks 20 ms apart (one look catches passing
/// kernel workers; at least 1; all online cores if /proc/loadavg cannot be read).
int idle_cores();

/// The thread count when the user gave none: OpenMP's default if OMP_NUM_THREADS is set, else
/// min(idle_cores(), particles / 2000), at least 1.
int default_thread_count(std::size_t particles);

/// True if OpenMP's waiting threads spin: OMP_WAIT_POLICY unset (libgomp then spins for
/// milliseconds before it sleeps) or "active", and GOMP_SPINCOUNT unset.
bool waiting_threads_spin();

/// The thread count of a run whose count was chosen by default, adjusted to what the machine gives
/// it. Over windows of `window` seconds of mechanics steps it compares the process's CPU time with
/// the wall time: `threads` spinning threads that have their cores use about `threads` CPU-seconds
/// per second (1.9 for two on an idle machine here), while with another process busy on one core
/// they use about one (measured: 1.04, the PBX 13 times slower than on one thread). Below
/// 0.75 × threads it sets OpenMP's count to 1; after `retry` seconds it tries the full count
/// again for one window, keeps it if the threads get their cores, else waits twice as long (up to
/// 16 × retry). The count changes round-off (the scatter buffers' sums), so a run that must be
/// bit-reproducible sets OMP_NUM_THREADS, or a passive wait policy (OMP_WAIT_POLICY=passive or
/// GOMP_SPINCOUNT): then there is no governor. A count given by --threads or run.threads with
/// spinning waits is governed too (issue 35: --threads 2 took 16.8x the 1-thread time on a busy core).
class ThreadGovernor {
 public:
  ThreadGovernor(int threads, double window = 0.2, double retry = 10.0);
  void step_started();
  /// After the step: a line for the log when the count changed, else empty.
  std::string step_finished();
  int threads() const { return current_; }
  int changes() const { return changes_; }

 private:
  using Clock = std::chrono::steady_clock;
  void set(int threads);
  int full_, current_;
  double window_, retry_, backoff_;
  int changes_ = 0;
  bool probing_ = false;
  Clock::time_point step_wall0_{}, reduced_at_{};
  double step_cpu0_ = 0.0, wall_ = 0.0, cpu_ = 0.0;  // the window's step time so far
};

}  // namespace frictherm::coupling
