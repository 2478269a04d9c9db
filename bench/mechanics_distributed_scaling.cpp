// Decomposed MPM step (frictherm/mechanics/distributed.hpp) under mpirun with any rank count: an
// elastic block (one material, no contact) and a sliding block (base fixed at its bottom, block
// pressed by gravity and sliding with Coulomb friction: multimaterial contact and frictional work),
// 2 × 2 uGIMP particles per cell. Prints, per case, the wall time per step (slowest rank) and the
// CPU time per step (all ranks), particle-steps per second and per CPU-second, the slowest rank's
// share of each phase, and each rank's communication per step (the two grid exchanges, the
// per-material entries at multi-material nodes, the migrated particles) in bytes. Strong scaling:
// the same --cells at 1, 2, 4 ranks; weak scaling (--weak): the grid grows with the ranks so that
// every rank keeps the particles of --cells at one rank. Asserts nothing.
//
//   mpirun -n 4 mechanics_distributed_scaling [--cells 200] [--steps 100] [--weak] [--cases block,sliding]
#include "cpu_time.hpp"
#include <frictherm/mechanics/distributed.hpp>

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace fm = frictherm::mechanics;
using V2 = fm::Vec<2>;

namespace {

using frictherm::bench::cpu_seconds;

fm::Material elastic(const char* name, double E) {
  fm::Material m;
  m.name = name;
  m.kind = fm::MaterialKind::linear_elastic;
  m.youngs_modulus = E;
  m.poisson_ratio = 0.3;
  m.density = 1000.0;
  return m;
}

// 2 × 2 particles per cell over [lo, hi) (rank 0 passes them; the first migration spreads them).
void fill(std::vector<fm::DecomposedParticle>& out, V2 lo, V2 hi, double h, int material, V2 velocity, double rho) {
  const double s = h / 2.0;
  const int nx = static_cast<int>(std::lround((hi[0] - lo[0]) / s)), ny = static_cast<int>(std::lround((hi[1] - lo[1]) / s));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      fm::DecomposedParticle p;
      p.id = static_cast<std::int64_t>(out.size());
      p.position = lo + V2((i + 0.5) * s, (j + 0.5) * s);
      p.half_size = V2::Constant(s / 2.0);
      p.volume = s * s;
      p.mass = rho * p.volume;
      p.velocity = velocity;
      p.material = material;
      out.push_back(p);
    }
}

void run_case(const std::string& which, int cells, int steps, int rank, int ranks) {
  const double h = 1e-3, rho = 1000.0, v0 = 10.0, g = 2e4;
  const int nx = cells, ny = std::max(4, cells / 2);
  const fm::Grid<2> grid(V2(0.0, 0.0), V2(h, h), {nx, ny});
  fm::DecomposedOptions opt;
  opt.shape = fm::ShapeKind::ugimp;
  std::vector<fm::Material> mats;
  std::vector<fm::DecomposedParticle> particles;
  const double W = nx * h, H = ny * h;
  if (which == "block") {
    mats = {elastic("block", 2e7)};
    fill(particles, V2(h, h), V2(W - h, H - h), h, 0, V2(v0, 0.0), rho);
    for (auto& p : particles) p.velocity[1] = v0 * std::sin(3.0 * p.position[0] / W);  // shears the block
  } else {
    mats = {elastic("base", 2e7), elastic("block", 1.5e7)};
    fill(particles, V2(h, 0.0), V2(W - h, 0.5 * H), h, 0, V2::Zero(), rho);
    fill(particles, V2(0.2 * W, 0.5 * H), V2(0.6 * W, 0.75 * H), h, 1, V2(v0, 0.0), rho);
    opt.gravity = V2(0.0, -g);
    opt.fixed_faces = {fm::FixedFace{1, false, {{true, true, true}}}};
    opt.contact = true;
    opt.contact_options.default_pair.law = fm::FrictionLaw::coulomb(0.3);
    opt.contact_options.default_pair.normal = fm::NormalMethod::specified;
    opt.contact_options.default_pair.normal_vector = fm::Vec<3>(0.0, 1.0, 0.0);
    opt.contact_pairs = {fm::DecomposedContactPair{0, 1, opt.contact_options.default_pair}};
  }
  const std::size_t count = particles.size();
  fm::DecomposedMpm2D split(MPI_COMM_WORLD, grid, mats, opt);
  split.add_particles(rank == 0 ? particles : std::vector<fm::DecomposedParticle>{});
  particles.clear();
  const double c = std::sqrt(mats[0].p_wave_modulus(fm::Analysis::plane_strain) / rho);
  const double dt = 0.5 * h / (c + 2.0 * v0);
  split.step(dt);  // first step (set-up of the exchanges) not timed
  const fm::DecomposedTraffic before = split.traffic();
  MPI_Barrier(MPI_COMM_WORLD);
  const double w0 = MPI_Wtime(), c0 = cpu_seconds();
  for (int s = 0; s < steps; ++s) split.step(dt);
  const double cpu = cpu_seconds() - c0;
  MPI_Barrier(MPI_COMM_WORLD);
  const double wall = MPI_Wtime() - w0;
  const fm::DecomposedTraffic& t = split.traffic();

  double cpu_all = 0.0, wall_max = 0.0;
  MPI_Reduce(&cpu, &cpu_all, 1, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  MPI_Reduce(&wall, &wall_max, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  std::array<double, 14> phases{};
  for (std::size_t p = 0; p < phases.size(); ++p) phases[p] = t.phase_seconds[p] - before.phase_seconds[p];
  std::array<double, 14> phases_max{};
  MPI_Reduce(phases.data(), phases_max.data(), 14, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  // Bytes per step received by this rank (what it sends is alike): two grid exchanges of its ghost
  // nodes, the per-material entries at multi-material nodes (to the owner and back), migration.
  const double per_step = 1.0 / steps;
  const double grid_bytes = 2.0 * static_cast<double>(t.ghost_nodes) * t.values_per_node * 8.0;
  const double field_bytes = 2.0 * static_cast<double>(t.field_entries_sent - before.field_entries_sent) *
                             t.field_entry_bytes * per_step;
  const double migration_bytes =
      static_cast<double>(t.particles_received - before.particles_received) * t.particle_bytes * per_step;
  const double mine[4] = {grid_bytes, field_bytes, migration_bytes, static_cast<double>(split.local_particles())};
  std::vector<double> all(4 * static_cast<std::size_t>(ranks));
  MPI_Gather(mine, 4, MPI_DOUBLE, all.data(), 4, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (rank != 0) return;
  const double ps = static_cast<double>(count) * steps;
  std::printf("%-8s %d rank%s  %dx%d cells  %zu particles  %d steps  wall %.3e s/step  cpu %.3e s/step  "
              "%.2f M p-steps/s  %.2f M p-steps/cpu-s\n",
              which.c_str(), ranks, ranks > 1 ? "s" : " ", nx, ny, count, steps, wall_max / steps, cpu_all / steps,
              ps / wall_max / 1e6, ps / cpu_all / 1e6);
  std::printf("  phases (slowest rank, %% of the wall time):");
  const auto& names = fm::DecomposedMpm2D::phase_names();
  for (std::size_t p = 0; p < names.size(); ++p)
    if (phases_max[p] > 0.005 * wall_max) std::printf(" %s %.1f", names[p], 100.0 * phases_max[p] / wall_max);
  std::printf("\n");
  for (int r = 0; r < ranks; ++r) {
    const double* a = &all[4 * static_cast<std::size_t>(r)];
    std::printf("  rank %d: %.0f particles; received per step: grid %.1f kB, material entries %.2f kB, "
                "migration %.2f kB\n",
                r, a[3], a[0] / 1e3, a[1] / 1e3, a[2] / 1e3);
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  fm::DecomposedPetscSession session(&argc, &argv);
  int cells = 200, steps = 100;
  bool weak = false;
  std::string cases = "block,sliding";
  for (int a = 1; a < argc; ++a) {
    const std::string k = argv[a];
    if (k == "--weak") weak = true;
    else if (a + 1 < argc && k == "--cells") cells = std::atoi(argv[++a]);
    else if (a + 1 < argc && k == "--steps") steps = std::atoi(argv[++a]);
    else if (a + 1 < argc && k == "--cases") cases = argv[++a];
    else {
      std::fprintf(stderr, "unknown option %s (valid: --cells N, --steps N, --weak, --cases block,sliding)\n", k.c_str());
      return 2;
    }
  }
  if (cells < 8 || steps < 1) {
    std::fprintf(stderr, "--cells must be at least 8 and --steps at least 1\n");
    return 2;
  }
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  // Weak scaling: the area grows with the ranks (cells along x and y by √ranks).
  const int n = weak ? static_cast<int>(std::lround(cells * std::sqrt(static_cast<double>(ranks)))) : cells;
  if (rank == 0)
    std::printf("mechanics_distributed_scaling: %d ranks, %s scaling, 1 mm cells, uGIMP 2x2\n", ranks,
                weak ? "weak" : "strong");
  for (std::size_t at = 0; at <= cases.size();) {
    const std::size_t comma = std::min(cases.find(',', at), cases.size());
    const std::string c = cases.substr(at, comma - at);
    if (c == "block" || c == "sliding") run_case(c, n, steps, rank, ranks);
    else if (rank == 0) std::fprintf(stderr, "unknown case '%s' (valid: block, sliding)\n", c.c_str());
    at = comma + 1;
  }
  return 0;
}
