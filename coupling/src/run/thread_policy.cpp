// Passive waiting and a default thread count that does not oversubscribe a shared machine.
#include <frictherm/coupling/thread_policy.hpp>

#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace frictherm::coupling {

void ensure_passive_wait(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr) return;  // the user's choice (or our second start)
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0) return;
  execv("/proc/self/exe", argv);  // returns only on failure: run on with the runtime's policy
}

int idle_cores() {
  const int cores = std::max(1, omp_get_num_procs());
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  if (!f) return cores;
  double l1 = 0, l5 = 0, l15 = 0;
  int running = 0, total = 0;
  const int got = std::fscanf(f, "%lf %lf %lf %d/%d", &l1, &l5, &l15, &running, &total);
  std::fclose(f);
  if (got != 5) return cores;
  const int others = std::max(0, running - 1);  // the runnable count includes this process
  return std::clamp(cores - others, 1, cores);
}

int default_thread_count(std::size_t particles) {
  if (std::getenv("OMP_NUM_THREADS") != nullptr) return std::max(1, omp_get_max_threads());
  const int by_size = static_cast<int>(std::min<std::size_t>(particles / 2000, 1024));
  return std::max(1, std::min(idle_cores(), by_size));
}

}  // namespace frictherm::coupling
