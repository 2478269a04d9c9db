#pragma once
// CPU time of this process, all its threads (user + system), for the benchmarks' per-CPU-second figures.
#include <sys/resource.h>

namespace frictherm::bench {

inline double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

}  // namespace frictherm::bench
