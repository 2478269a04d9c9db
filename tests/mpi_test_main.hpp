#pragma once
// The main() of an MPI test program that needs MPI only (no PETSc): MPI around GoogleTest.
#include <gtest/gtest.h>
#include <mpi.h>

namespace frictherm::test {

inline int run_tests_under_mpi(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  const int rc = RUN_ALL_TESTS();
  MPI_Finalize();
  return rc;
}

}  // namespace frictherm::test
