#pragma once
// Thread policy for runs on shared machines (issue 13, docs/coupling.md "Threads"):
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
#include <cstddef>

namespace frictherm::coupling {

/// If OMP_WAIT_POLICY is unset: sets it to "passive" and executes /proc/self/exe again with argv.
/// Returns only if no re-execution happened (the policy was set already, or exec failed).
void ensure_passive_wait(char** argv);

/// Cores not running other processes now: online cores minus the runnable tasks of /proc/loadavg
/// other than this process (at least 1; all online cores if /proc/loadavg cannot be read).
int idle_cores();

/// The thread count when the user gave none: OpenMP's default if OMP_NUM_THREADS is set, else
/// min(idle_cores(), particles / 2000), at least 1.
int default_thread_count(std::size_t particles);

}  // namespace frictherm::coupling
