#pragma once
// This process's rank, the number of ranks in MPI_COMM_WORLD and the largest of a value over them
// (the distributed tests).
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

/// The largest x over the ranks of MPI_COMM_WORLD.
inline double global_max(double x) {
  double out = 0.0;
  MPI_Allreduce(&x, &out, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return out;
}

}  // namespace frictherm::test
