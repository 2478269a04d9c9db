// Passive waiting and a default thread count that does not oversubscribe a shared machine.
#include <frictherm/coupling/thread_policy.hpp>
#include <frictherm/mechanics/thread_partition.hpp>

#include <omp.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <strings.h>
#include <sstream>

namespace frictherm::coupling {

void ensure_passive_wait(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr) return;  // the user's choice (or our second start)
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0) return;
  execv("/proc/self/exe", argv);  // returns only on failure: run on with the runtime's policy
}

int idle_cores() {
  const int cores = std::max(1, omp_get_num_procs());
  // The runnable count of /proc/loadavg is a snapshot: a kernel worker or the shell that started us
  // is often runnable for a moment. The fewest others over five looks 20 ms apart is the load.
  int others = cores;
  for (int look = 0; look < 5 && others > 0; ++look) {
    if (look > 0) usleep(20000);
    std::FILE* f = std::fopen("/proc/loadavg", "r");
    if (!f) return cores;
    double l1 = 0, l5 = 0, l15 = 0;
    int running = 0, total = 0;
    const int got = std::fscanf(f, "%lf %lf %lf %d/%d", &l1, &l5, &l15, &running, &total);
    std::fclose(f);
    if (got != 5) return cores;
    others = std::min(others, std::max(0, running - 1));  // the runnable count includes this process
  }
  return std::clamp(cores - others, 1, cores);
}

int default_thread_count(std::size_t particles) {
  if (std::getenv("OMP_NUM_THREADS") != nullptr) return std::max(1, omp_get_max_threads());
  return mechanics::threads_for_particles(particles, idle_cores());
}

bool waiting_threads_spin() {
  if (std::getenv("GOMP_SPINCOUNT") != nullptr) return false;  // the user tuned the spinning
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  return policy == nullptr || strcasecmp(policy, "active") == 0;
}

namespace {
double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

ThreadGovernor::ThreadGovernor(int threads, double window, double retry)
    : full_(std::max(1, threads)), current_(full_), window_(window), retry_(retry), backoff_(retry) {}

void ThreadGovernor::set(int threads) {
  current_ = threads;
  omp_set_num_threads(threads);
}

void ThreadGovernor::step_started() {
  if (full_ < 2) return;
  if (current_ < full_ && std::chrono::duration<double>(Clock::now() - reduced_at_).count() >= backoff_) {
    set(full_);  // try the full count for one window
    probing_ = true;
    wall_ = cpu_ = 0.0;
  }
  step_wall0_ = Clock::now();
  step_cpu0_ = process_cpu_seconds();
}

std::string ThreadGovernor::step_finished() {
  if (full_ < 2) return {};
  wall_ += std::chrono::duration<double>(Clock::now() - step_wall0_).count();
  cpu_ += process_cpu_seconds() - step_cpu0_;
  if (wall_ < window_) return {};
  const double cores = cpu_ / wall_;
  wall_ = cpu_ = 0.0;
  std::ostringstream msg;
  msg.setf(std::ios::fixed);
  msg.precision(1);
  if (current_ == full_ && cores < 0.75 * full_) {
    if (probing_) backoff_ = std::min(2.0 * backoff_, 16.0 * retry_);
    probing_ = false;
    set(1);
    reduced_at_ = Clock::now();
    ++changes_;
    msg << "frictherm: " << full_ << " threads got " << cores << " cores (another process is busy): going on with 1 thread, trying "
        << full_ << " again in " << backoff_ << " s (OMP_WAIT_POLICY=passive keeps the count)";
    return msg.str();
  }
  if (probing_) {  // the full count got its cores
    probing_ = false;
    backoff_ = retry_;
    ++changes_;
    msg << "frictherm: " << full_ << " threads get their cores again (" << cores << "): going on with " << full_;
    return msg.str();
  }
  return {};
}

}  // namespace frictherm::coupling
