#pragma once
// A scratch folder for the distributed tests that write files: made by rank 0 (mkdtemp) and
// broadcast over MPI_COMM_WORLD, so that every rank writes into the same one (collective).
#include "mpi_ranks.hpp"

#include <mpi.h>

#include <cstdlib>
#include <string>

namespace frictherm::test {

/// `prefix` ends the folder's name before mkdtemp's six random characters, e.g. "/tmp/frictherm_x_".
inline std::string scratch_folder(const std::string& prefix) {
  std::string dir;
  if (comm_rank() == 0) {
    std::string tmpl = prefix + "XXXXXX";
    dir = mkdtemp(tmpl.data());
  }
  int length = static_cast<int>(dir.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD);
  dir.resize(static_cast<std::size_t>(length));
  MPI_Bcast(dir.data(), length, MPI_CHAR, 0, MPI_COMM_WORLD);
  return dir;
}

}  // namespace frictherm::test
