// The failure agreement of a decomposed run (coupling/src/distributed_run/decomposed_failure.cpp;
// issue 34, docs/robustness.md "The same under mpirun"), on 2 and 4 ranks:
//   * every rank failing (an error thrown on every rank alike): every rank gets the lowest rank's
//     message, so that the run ends as one breakdown;
//   * the last rank failing alone while the others wait in another collective call (here a barrier
//     on the run's communicator, which the failing rank joins only once the agreement has given up):
//     the agreement returns nothing after its timeout instead of waiting for ever — the run then
//     ends every rank. It cannot return before the timeout (the elapsed time is a lower bound only,
//     never an upper one: a loaded machine may take longer). The other ranks then join the posted
//     operation so that the test ends cleanly.
#include "distributed_run/decomposed_failure.hpp"

#include "../mpi_test_main.hpp"

#include <chrono>
#include <string>

using frictherm::coupling::detail::agree_on_failure;

namespace {

struct Comm {  // a duplicate of MPI_COMM_WORLD used for nothing else, as the run's
  MPI_Comm c = MPI_COMM_NULL;
  Comm() { MPI_Comm_dup(MPI_COMM_WORLD, &c); }
  ~Comm() { MPI_Comm_free(&c); }
};

int rank_and_size(int& size) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return rank;
}

}  // namespace

TEST(FailureAgreement, EveryRankFailingAgreesOnTheLowestRanksMessage) {
  int size = 1;
  const int rank = rank_and_size(size);
  const Comm comm;
  const auto m = agree_on_failure(comm.c, "failed on rank " + std::to_string(rank), 600.0);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(*m, "failed on rank 0");
}

TEST(FailureAgreement, OneRankFailingAloneGivesUpAfterTheTimeout) {
  int size = 1;
  const int rank = rank_and_size(size);
  const Comm comm;
  if (rank == size - 1) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto m = agree_on_failure(comm.c, "alone", 0.5);
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_FALSE(m.has_value()) << *m;
    EXPECT_GE(waited, 0.5);
  }
  MPI_Barrier(MPI_COMM_WORLD);  // the others wait in another collective call meanwhile
  if (rank != size - 1) {       // clean-up: the posted operation completes
    int mine = rank, lowest = 0;
    MPI_Request r = MPI_REQUEST_NULL;
    MPI_Iallreduce(&mine, &lowest, 1, MPI_INT, MPI_MIN, comm.c, &r);
    MPI_Wait(&r, MPI_STATUS_IGNORE);
    EXPECT_EQ(lowest, 0);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

int main(int argc, char** argv) { return frictherm::test::run_tests_under_mpi(argc, argv); }
