// Hot spots across rank boundaries (frictherm/coupling/distributed.hpp): candidates gathered on every
// rank with MPI_Allgatherv, clustered and matched by the serial tracker.
#include <frictherm/coupling/distributed.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace frictherm::coupling {

namespace {

void mpi_check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) throw std::runtime_error(std::string("hot spots across ranks: ") + what + " failed");
}

}  // namespace

std::vector<HotCandidate> gather_hot_candidates(MPI_Comm comm, const std::vector<HotCandidate>& local) {
  static_assert(std::is_trivially_copyable_v<HotCandidate>, "candidates travel as bytes");
  int size = 1;
  mpi_check(MPI_Comm_size(comm, &size), "MPI_Comm_size");
  const int bytes = static_cast<int>(local.size() * sizeof(HotCandidate));
  std::vector<int> counts(static_cast<std::size_t>(size)), offsets(static_cast<std::size_t>(size), 0);
  mpi_check(MPI_Allgather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, comm), "MPI_Allgather");
  long long total = 0;
  for (int r = 0; r < size; ++r) {
    offsets[static_cast<std::size_t>(r)] = static_cast<int>(total);
    total += counts[static_cast<std::size_t>(r)];
  }
  if (total > std::numeric_limits<int>::max())
    throw std::runtime_error("hot spots across ranks: " + std::to_string(total / static_cast<long long>(sizeof(HotCandidate))) +
                             " hot particles exceed one MPI message");
  std::vector<HotCandidate> all(static_cast<std::size_t>(total) / sizeof(HotCandidate));
  mpi_check(MPI_Allgatherv(local.data(), bytes, MPI_BYTE, all.data(), counts.data(), offsets.data(), MPI_BYTE, comm),
            "MPI_Allgatherv");
  return all;
}

template <int Dim>
void update_hot_spots_across_ranks(MPI_Comm comm, HotSpotTracker& tracker, const mechanics::Particles<Dim>& local,
                                   const std::vector<std::int64_t>& global_ids,
                                   const std::vector<double>& reference_temperature,
                                   const std::vector<ThermalProperties>& materials,
                                   std::size_t global_particle_count, double time,
                                   const std::vector<double>* criterion) {
  for (std::int64_t id : global_ids)
    if (id < 0 || static_cast<std::size_t>(id) >= global_particle_count)
      throw std::invalid_argument("hot spots across ranks: particle id " + std::to_string(id) + " outside [0, " +
                                  std::to_string(global_particle_count) + ")");
  double local_max = 0.0;
  const std::vector<HotCandidate> mine = tracker.candidates(local, materials, local_max, &global_ids, &reference_temperature,
                                                            criterion);
  double max_temperature = -std::numeric_limits<double>::infinity();
  mpi_check(MPI_Allreduce(&local_max, &max_temperature, 1, MPI_DOUBLE, MPI_MAX, comm), "MPI_Allreduce");
  // In global-id order: the clustering's order (hence the hot spots' order, new ids and sums) is then
  // that of a serial tracker given every particle by id, whatever the partition and swarm order.
  std::vector<HotCandidate> all = gather_hot_candidates(comm, mine);
  std::sort(all.begin(), all.end(), [](const HotCandidate& a, const HotCandidate& b) { return a.index < b.index; });
  tracker.update_from(std::move(all), max_temperature, global_particle_count, time);
}

#define FRICTHERM_HOT_SPOTS_ACROSS_RANKS(D)                                                                           \
  template void update_hot_spots_across_ranks<D>(MPI_Comm, HotSpotTracker&, const mechanics::Particles<D>&,          \
                                                 const std::vector<std::int64_t>&, const std::vector<double>&,       \
                                                 const std::vector<ThermalProperties>&, std::size_t, double,  \
                                                 const std::vector<double>*);
FRICTHERM_HOT_SPOTS_ACROSS_RANKS(2)
FRICTHERM_HOT_SPOTS_ACROSS_RANKS(3)
#undef FRICTHERM_HOT_SPOTS_ACROSS_RANKS

}  // namespace frictherm::coupling
