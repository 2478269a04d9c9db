// Distributed thermal solve (frictherm/thermal/distributed.hpp) on a 2D or 3D conduction grid
// (bench/thermal_grids.hpp), run under mpirun with any rank count: prints, per integrator, the
// wall time per step (slowest rank), the steps, and each rank's communication per step (ghost
// exchanges, values and bytes received, MPI_Allreduce calls). Strong scaling: the same grid at
// 1, 2, 4 ranks; weak scaling: grow the grid with the ranks. Prints figures, asserts nothing.
//
//   mpirun -n 4 thermal_distributed_scaling [--dim 3] [--n 48] [--windows 5]
//          [--integrators forward_euler,cvode_bdf] [--preconditioner jacobi]
#include "frictherm/thermal/distributed.hpp"
#include "thermal_grids.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace ft = frictherm::thermal;

int main(int argc, char** argv) {
  ft::PetscSession session(&argc, &argv);
  int dim = 2, n = 200, windows = 5;
  std::string integrators = "forward_euler,cvode_bdf", pc = "jacobi";
  for (int a = 1; a + 1 < argc; a += 2) {
    const std::string k = argv[a], v = argv[a + 1];
    if (k == "--dim") dim = std::atoi(v.c_str());
    else if (k == "--n") n = std::atoi(v.c_str());
    else if (k == "--windows") windows = std::atoi(v.c_str());
    else if (k == "--integrators") integrators = v;
    else if (k == "--preconditioner") pc = v;
    else {
      std::fprintf(stderr, "unknown option %s (valid: --dim 2|3, --n, --windows, --integrators, --preconditioner)\n",
                   k.c_str());
      return 2;
    }
  }
  if (dim != 2 && dim != 3) {
    std::fprintf(stderr, "--dim must be 2 or 3\n");
    return 2;
  }
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const thermal_grids::Material mat = thermal_grids::hmx_like();
  const double h = 2e-6;  // 2 µm nodes (the PBX resolution)
  Eigen::VectorXd mass;
  ft::SparseMatrix k;
  if (dim == 2) {
    auto g = thermal_grids::make_grid_2d(n, n, 0.0, 0.0, h, mat);
    mass = g.mass;
    k = g.k;
  } else {
    auto g = thermal_grids::make_grid_3d(n, n, n, 0.0, 0.0, 0.0, h, mat);
    mass = g.mass;
    k = g.k;
  }
  const ft::Index total = mass.size();
  const ft::RowRange rows = ft::partition_rows(total, MPI_COMM_WORLD);
  ft::DistributedProblem problem(MPI_COMM_WORLD, total, rows.begin, mass.segment(rows.begin, rows.size()),
                                 ft::SparseMatrix(k.middleRows(rows.begin, rows.size())));
  // A hot spot in the middle: 1 mW per unit depth (2D) or 1 µW (3D) into the central node.
  Eigen::VectorXd q = Eigen::VectorXd::Zero(rows.size());
  const ft::Index centre = total / 2 + (dim == 2 ? n / 2 : 0);
  if (problem.owns(centre)) q[centre - rows.begin] = dim == 2 ? 1e-3 : 1e-6;
  problem.set_source(q);
  const double window = 50.0 * h * h / mat.alpha();  // ≈ 200 forward Euler limits in 2D
  if (rank == 0) {
    std::printf("# %dD grid %d^%d = %ld nodes, %d rank(s), %d windows of %.3e s, preconditioner %s\n", dim, n, dim,
                static_cast<long>(total), ranks, windows, window, pc.c_str());
    std::printf("# integrator, wall s/step (slowest rank), steps, ghost exchanges/step, values received/exchange "
                "(max rank), bytes received/step (max rank), allreduce/step, books imbalance/stored energy\n");
  }
  std::string list = integrators + ",";
  for (std::size_t p = 0; (p = list.find(',')) != std::string::npos; list.erase(0, p + 1)) {
    const std::string name = list.substr(0, p);
    if (name.empty()) continue;
    ft::DistributedOptions o;
    o.preconditioner = pc;
    o.integrator.max_steps = 1000000;
    auto integ = ft::make_distributed_integrator(name, o);
    Eigen::VectorXd t = Eigen::VectorXd::Constant(rows.size(), 300.0);
    MPI_Barrier(MPI_COMM_WORLD);
    const auto start = std::chrono::steady_clock::now();
    for (int w = 0; w < windows; ++w) integ->advance(problem, t, w * window, (w + 1) * window);
    double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), wall_max = 0.0;
    MPI_Allreduce(&wall, &wall_max, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    const auto& c = integ->communication();
    long recv = static_cast<long>(c.ghosts_received), recv_max = 0;
    MPI_Allreduce(&recv, &recv_max, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
    const double steps = static_cast<double>(std::max(1L, integ->stats().steps));
    const auto& b = integ->books();
    if (rank == 0) {
      std::printf("%-14s %.3e %8ld %6.2f %8ld %10.0f %6.2f %9.2e\n", name.c_str(), wall_max / steps,
                  integ->stats().steps, c.ghost_exchanges / steps, recv_max,
                  8.0 * static_cast<double>(recv_max) * c.ghost_exchanges / steps, c.reductions / steps,
                  b.imbalance() / b.stored);
    }
  }
  return 0;
}
