// The failure agreement of a decomposed run (decomposed_failure.hpp).
#include "distributed_run/decomposed_failure.hpp"

#include <chrono>
#include <thread>

namespace frictherm::coupling::detail {

std::optional<std::string> agree_on_failure(MPI_Comm comm, const std::string& message, double timeout_seconds) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  // On the heap: after a timeout the posted operation may still complete (the other ranks joining
  // late), writing its result after this function has returned. Left to the process's end then.
  auto* lowest = new int[2]{rank, rank};
  MPI_Request request = MPI_REQUEST_NULL;
  MPI_Iallreduce(&lowest[0], &lowest[1], 1, MPI_INT, MPI_MIN, comm, &request);
  const auto t0 = std::chrono::steady_clock::now();
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) break;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >= timeout_seconds)
      return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const int first = lowest[1];
  delete[] lowest;
  long length = static_cast<long>(message.size());
  MPI_Bcast(&length, 1, MPI_LONG, first, comm);
  std::string text = rank == first ? message : std::string(static_cast<std::size_t>(length), ' ');
  MPI_Bcast(text.data(), static_cast<int>(length), MPI_CHAR, first, comm);
  return text;
}

}  // namespace frictherm::coupling::detail
