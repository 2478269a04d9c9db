#pragma once
// This process's rank and the number of ranks in MPI_COMM_WORLD (the distributed tests).
#include <mpi.h>

namespace frictherm::test {

inline int comm_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

inline int comm_size() {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

}  // namespace frictherm::test
