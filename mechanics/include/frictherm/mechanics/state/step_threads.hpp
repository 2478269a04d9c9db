#pragma once
// The OpenMP threads of a Simulation<Dim>'s step (thread_partition.hpp; simulation_fields.cpp):
// how many, which particles and fields each one has, and their scatter buffers.
#include <frictherm/mechanics/state/nodal_fields.hpp>
#include <frictherm/mechanics/thread_partition.hpp>

#include <vector>

namespace frictherm::mechanics {

/// The thread partition of the step and each thread's share of the particle passes.
template <int Dim>
struct StepThreads {
  int count = 1;                    // threads of this step: 1 for small problems (threading would cost more)
  ThreadPartition partition;       // each thread's particles, the fields threads share
  PassSplit pass_split;            // each thread's particles in the particle passes (timed, rebalanced)
  std::vector<double> work_blocks;  // the particle pass's external work per PassSplit block (threads > 1)
  std::vector<double> power_blocks;  // its stress power Σ V σ:L per PassSplit block (threads > 1)
  std::vector<double> speed_max;    // per ThreadPartition part: its particles' largest c_p + |v_p| (the CFL speed)
  std::vector<NodalFields<Dim>> nodes;  // per-thread scatter buffers (threads 1..n-1), shared fields only
};

}  // namespace frictherm::mechanics
