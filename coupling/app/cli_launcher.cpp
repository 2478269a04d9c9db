// MPI launchers and the build's features: what `frictherm --version` prints, and the refusal to run as
// several copies of one command when nothing spreads the work over them (issue 14).
#include "cli.hpp"

#include <frictherm/coupling/thread_policy.hpp>

#include <Eigen/Core>
#include <hdf5.h>
#include <omp.h>
#include <sundials/sundials_config.h>

#include <cstdlib>
#include <iostream>
#include <string>

#ifdef FRICTHERM_WITH_MPI
#include <mpi.h>
#endif

#if __has_include("frictherm_git_commit.hpp")
#include "frictherm_git_commit.hpp"  // generated at build time (coupling/CMakeLists.txt)
#endif
#ifndef FRICTHERM_GIT_COMMIT
#define FRICTHERM_GIT_COMMIT ""
#endif

namespace frictherm::cli {
namespace {

// Variables MPI launchers set in every process they start: Open MPI's mpirun, MPICH/Intel MPI's
// Hydra (PMI_*), PMIx-based launchers (Open MPI 5, srun --mpi=pmix) and MVAPICH.
constexpr const char* kSizeVariables[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MV2_COMM_WORLD_SIZE"};
constexpr const char* kRankVariables[] = {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK", "MV2_COMM_WORLD_RANK"};

long env_long(const char* name) {  // -1 when unset or not a number
  const char* v = std::getenv(name);
  if (!v || !*v) return -1;
  char* end = nullptr;
  const long x = std::strtol(v, &end, 10);
  return (*end == '\0' && x >= 0) ? x : -1;
}

}  // namespace

LauncherInfo launcher_info() {
  LauncherInfo info;
  for (const char* name : kSizeVariables) {
    const long size = env_long(name);
    if (size > info.size) info.size = size, info.evidence = std::string(name) + "=" + std::getenv(name);
  }
  for (const char* name : kRankVariables) {
    const long rank = env_long(name);
    if (rank < 0) continue;
    info.launched = true;
    if (rank > info.rank) {
      info.rank = rank;
      if (info.size <= 1) info.evidence = std::string(name) + "=" + std::getenv(name);
    }
  }
  if (info.size >= 1) info.launched = true;
  return info;
}

bool several_processes(const LauncherInfo& info) { return info.size > 1 || info.rank > 0; }

int refuse_under_launcher(const std::string& command) {
  const LauncherInfo info = launcher_info();
  if (!several_processes(info)) return kOk;
#ifdef FRICTHERM_WITH_MPI
  if (command == "ensemble") return kOk;
#ifdef FRICTHERM_DECOMPOSED_RUN
  if (command == "run" || command == "resume") return kOk;  // the decomposed run (cli_run_mpi.cpp)
  const std::string why = "only 'frictherm run' and 'frictherm resume' (decomposed) and 'frictherm ensemble' share their work over MPI "
                          "processes; every process would run '" + command +
                          "' alone and write the same files. Run it without the launcher (threads: --threads)";
#else
  const std::string why = "only 'frictherm ensemble' spreads its members over MPI processes; every process would run '" +
                          command + "' alone and write the same files. Run it without the launcher (threads: --threads)";
#endif
#else
  const std::string why = "this frictherm was built without MPI, so every process would run every member of '" +
                          command + "' and write the same files. Rebuild with MPI (Debian libopenmpi-dev, CMake "
                          "-DFRICTHERM_WITH_MPI=ON; 'frictherm --version' shows the build) or run without the launcher";
#endif
  if (info.rank <= 0)
    std::cerr << "frictherm: started by an MPI launcher as several processes (" << info.evidence << "): " << why
              << ".\n";
  return kUsage;
}

void prepare_process(char** argv) {
#ifndef FRICTHERM_WITH_MPI  // under MPI the launcher owns the process: set OMP_WAIT_POLICY yourself
  coupling::ensure_passive_wait(argv);  // threads sleep at barriers (docs/performance.md, "Threads")
#else
  (void)argv;
#endif
}

void print_version(std::ostream& out) {
  out << "frictherm " << FRICTHERM_VERSION << '\n';
  const std::string commit = FRICTHERM_GIT_COMMIT;
  out << "  git commit: " << (commit.empty() ? "unknown (not built from a git checkout)" : commit) << '\n';
#ifdef FRICTHERM_WITH_MPI
  char library[MPI_MAX_LIBRARY_VERSION_STRING] = "";
  int length = 0;
  MPI_Get_library_version(library, &length);  // allowed before MPI_Init
  std::string first_line(library, static_cast<std::size_t>(length));
  first_line = first_line.substr(0, first_line.find_first_of(",\n"));
  out << "  MPI: yes, MPI " << MPI_VERSION << '.' << MPI_SUBVERSION << " (" << first_line
      << "); 'mpirun -n K frictherm ensemble ...' spreads members over K processes\n";
#else
  out << "  MPI: no (frictherm ensemble runs members one after the other; refuses to start under mpirun)\n";
#endif
  out << "  OpenMP: " << _OPENMP << " (up to " << omp_get_max_threads() << " threads here)\n";
  out << "  SUNDIALS: " << SUNDIALS_VERSION << '\n';
  unsigned major = 0, minor = 0, release = 0;
  H5get_libversion(&major, &minor, &release);
  out << "  HDF5: " << major << '.' << minor << '.' << release << '\n';
  out << "  Eigen: " << EIGEN_WORLD_VERSION << '.' << EIGEN_MAJOR_VERSION << '.' << EIGEN_MINOR_VERSION << '\n';
}

}  // namespace frictherm::cli
