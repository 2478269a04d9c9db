// Decomposed MPM step (frictherm/mechanics/distributed.hpp) under mpirun with any rank count. 2D: an
// elastic block (one material, no contact) and a sliding block (base fixed at its bottom, block
// pressed by gravity and sliding with Coulomb friction: multimaterial contact and frictional work),
// 2 × 2 uGIMP particles per cell. 3D (case block3d): an elastic block, 2³ uGIMP particles per cell,
// measured both ways in one run: strong (the --cells3d grid on any rank count) and weak (the grid's
// x extent times the rank count, so every rank keeps the particles of one rank's run).
// Prints, per case, the wall time per step (slowest rank) and the CPU time per step (all ranks),
// particle-steps per second (all ranks, and per rank), per CPU-second, the slowest rank's share of
// each phase, and each rank's ghost nodes and communication per step (the two grid exchanges, the
// per-material entries at multi-material nodes, the migrated particles) in bytes. 2D strong scaling:
// the same --cells at 1, 2, 4 ranks; weak scaling (--weak): the grid grows with the ranks so that
// every rank keeps the particles of --cells at one rank. 3D heated sliding block (case heated3d, built
// with the coupling's decomposed part): the same scene run twice, mechanics only and coupled (frictional
// heat and matrix-free conduction every step, DecomposedHeat), strong and weak as block3d; prints both
// times per step, their ratio and the heat windows' grid exchanges per step and rank in bytes.
// Asserts nothing.
//
//   mpirun -n 4 mechanics_distributed_scaling [--cells 200] [--steps 100] [--weak]
//                                             [--cases block,sliding,grains,grains16,block3d,heated3d]
//                                             [--cells3d 24]
// grainsG: the 2D block cut into G × G-cell grains, each its own Mie-Grüneisen material, in contact
// (G = 4 when omitted): the per-material boxes and exchanges with hundreds to thousands of materials.
//                                             [--repeat 3]   (heated3d: interleaved pairs, smallest kept)
#include "cpu_time.hpp"
#include <frictherm/mechanics/distributed.hpp>
#ifdef FRICTHERM_BENCH_DECOMPOSED_HEAT
#include <frictherm/coupling/decomposed_heat.hpp>
#endif

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace fm = frictherm::mechanics;
using V2 = fm::Vec<2>;
using V3 = fm::Vec<3>;

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

// One case: set-up (rank 0's particles spread by the first migration), one untimed step, `steps`
// timed steps, then the figures (see the header).
template <int Dim>
void measure(const std::string& which, const char* grid_label, const fm::Grid<Dim>& grid,
             const std::vector<fm::Material>& mats, const typename fm::DecomposedMpm<Dim>::Options& opt,
             std::vector<typename fm::DecomposedMpm<Dim>::Particle>& particles, double dt, int steps, int rank,
             int ranks, std::size_t count = 0) {
  if (count == 0) count = particles.size();
  fm::DecomposedMpm<Dim> split(MPI_COMM_WORLD, grid, mats, opt);
  split.add_particles(rank == 0 ? particles : std::vector<typename fm::DecomposedMpm<Dim>::Particle>{});
  particles.clear();
  particles.shrink_to_fit();
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
  const double mine[8] = {grid_bytes, field_bytes, migration_bytes, static_cast<double>(split.local_particles()),
                          static_cast<double>(t.ghost_nodes), cpu, static_cast<double>(split.peak_field_slots()),
                          static_cast<double>(split.velocity_fields()) * split.local_node_count()};
  std::vector<double> all(8 * static_cast<std::size_t>(ranks));
  MPI_Gather(mine, 8, MPI_DOUBLE, all.data(), 8, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (rank != 0) return;
  const double ps = static_cast<double>(count) * steps;
  std::string procs;
  for (int p : split.processes()) procs += (procs.empty() ? "" : "x") + std::to_string(p);
  std::printf("%-8s %dD %d rank%s (%s)  %s  %zu particles  %d steps  wall %.3e s/step  cpu %.3e s/step (all ranks)  "
              "%.2f M p-steps/s (%.2f per rank)  %.2f M p-steps/cpu-s\n",
              which.c_str(), Dim, ranks, ranks > 1 ? "s" : " ", procs.c_str(), grid_label, count, steps, wall_max / steps,
              cpu_all / steps, ps / wall_max / 1e6, ps / wall_max / 1e6 / ranks, ps / cpu_all / 1e6);
  std::printf("  phases (slowest rank, %% of the wall time):");
  const auto& names = fm::DecomposedMpm<Dim>::phase_names();
  for (std::size_t p = 0; p < names.size(); ++p)
    if (phases_max[p] > 0.005 * wall_max) std::printf(" %s %.1f", names[p], 100.0 * phases_max[p] / wall_max);
  std::printf("\n");
  for (int r = 0; r < ranks; ++r) {
    const double* a = &all[8 * static_cast<std::size_t>(r)];
    std::printf("  rank %d: %.0f particles, %.0f ghost nodes, cpu %.3e s/step; received per step: grid %.1f kB, "
                "material entries %.2f kB, migration %.2f kB; field slots %.0f (fields x local nodes %.0f)\n",
                r, a[3], a[4], a[5] / steps, a[0] / 1e3, a[1] / 1e3, a[2] / 1e3, a[6], a[7]);
  }
  std::fflush(stdout);
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
  double c_max = 0.0;  // the largest wave speed for dt (0: the first material's P-wave speed)
  if (which.rfind("grains", 0) == 0) {
    // A PBX-like specimen: the block region cut into square grains of G × G cells (case grainsG,
    // default 4), each its own Mie-Grüneisen/J2 material (HMX of Nairn et al. 2018 table 1),
    // squeezed by v_x = −v0 (x − xc)/(W/2), multimaterial contact with Coulomb μ = 0.3 between every
    // pair (average-volume-gradient normal): the per-material storage and exchanges at scale.
    const int G = std::min({which == "grains" ? 4 : std::max(1, std::atoi(which.c_str() + 6)), nx - 2, ny - 2});
    const int gx = std::max(1, (nx - 2) / G), gy = std::max(1, (ny - 2) / G);
    for (int j = 0; j < gy; ++j)
      for (int i = 0; i < gx; ++i) {
        fm::Material m;
        m.name = "grain" + std::to_string(mats.size());
        m.kind = fm::MaterialKind::mie_gruneisen;
        m.density = 1891.0;
        m.mie_gruneisen = fm::MieGruneisenParams{1891.0, 3070.0, 1.79, 0.0, 0.7, 4.81e9, 2.6e8, 0.0};
        const V2 lo(h * (1 + G * i), h * (1 + G * j));
        fill(particles, lo, lo + V2(G * h, G * h), h, static_cast<int>(mats.size()), V2::Zero(), m.density);
        mats.push_back(m);
      }
    for (auto& p : particles) p.velocity[0] = -v0 * (p.position[0] - 0.5 * W) / (0.5 * W);
    opt.contact = true;
    opt.contact_options.default_pair.law = fm::FrictionLaw::coulomb(0.3);
    opt.contact_options.default_pair.normal = fm::NormalMethod::average_volume_gradient;
    c_max = 1.3 * 3070.0 + std::sqrt(4.0 / 3.0 * 4.81e9 / 1891.0);
  } else if (which == "block") {
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
  const double c = c_max > 0.0 ? c_max : std::sqrt(mats[0].p_wave_modulus(fm::Analysis::plane_strain) / rho);
  const double dt = 0.5 * h / (c + 2.0 * v0);
  char label[96];
  std::snprintf(label, sizeof label, "%dx%d cells, %zu materials", nx, ny, mats.size());
  measure<2>(which, label, grid, mats, opt, particles, dt, steps, rank, ranks);
}

// 3D elastic block: nx × n × n cells, the block one cell inside the grid on every side, 2³ uGIMP
// particles per cell, sheared (v_y, v_z up to 1.5 and 1 m/s, varying along x) and stretched along x
// (v_x = sin(πx/W) m/s): it moves ≤ 0.5 mm over 100 steps, so it stays inside the grid at any size;
// particles near the cuts change rank.
void run_block3d(const std::string& which, int nx, int n, int steps, int rank, int ranks) {
  const double h = 1e-3, rho = 1000.0, v0 = 2.0;  // v0: the speed bound in dt
  const fm::Grid<3> grid(V3::Zero(), V3::Constant(h), {nx, n, n});
  fm::DecomposedMpm3D::Options opt;
  opt.shape = fm::ShapeKind::ugimp;
  const std::vector<fm::Material> mats{elastic("block", 2e7)};
  std::vector<fm::DecomposedMpm3D::Particle> particles;
  if (rank == 0) {
    const double s = h / 2.0, W = nx * h;
    const int m[3] = {2 * (nx - 2), 2 * (n - 2), 2 * (n - 2)};
    particles.reserve(static_cast<std::size_t>(m[0]) * m[1] * m[2]);
    for (int k = 0; k < m[2]; ++k)
      for (int j = 0; j < m[1]; ++j)
        for (int i = 0; i < m[0]; ++i) {
          fm::DecomposedMpm3D::Particle p;
          p.id = static_cast<std::int64_t>(particles.size());
          p.position = V3::Constant(h) + s * V3(i + 0.5, j + 0.5, k + 0.5);
          p.half_size = V3::Constant(s / 2.0);
          p.volume = s * s * s;
          p.mass = rho * p.volume;
          const double x = p.position[0];
          p.velocity = V3(std::sin(M_PI * x / W), 1.5 * std::sin(3.0 * x / W), std::cos(3.0 * x / W));
          particles.push_back(p);
        }
  }
  long long count = static_cast<long long>(particles.size());
  MPI_Bcast(&count, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  const double c = std::sqrt(mats[0].p_wave_modulus(fm::Analysis::three_d) / rho);
  const double dt = 0.5 * h / (c + 2.0 * v0);
  char label[64];
  std::snprintf(label, sizeof label, "%dx%dx%d cells", nx, n, n);
  measure<3>(which, label, grid, mats, opt, particles, dt, steps, rank, ranks, static_cast<std::size_t>(count));
}

#ifdef FRICTHERM_BENCH_DECOMPOSED_HEAT
// 3D heated sliding block: nx × ny × nz cells of 1 mm; base [1, nx−1] × [1, ny−1] × [0, nz/2] mm fixed
// at z_min, block [0.2 W, 0.6 W] × [1, ny−1] × [nz/2, 3nz/4] mm sliding along x at 10 m/s, pressed by
// g = 2e4 m/s² along −z, Coulomb μ = 0.3 (specified normal), 2³ uGIMP particles per cell; thermal: base
// C = 100 J/(kg K), k = 50 W/(m K), block C = 150, k = 20 (the tests' values). Timed: `steps` steps
// after one untimed, mechanics only, then the same scene coupled (step + DecomposedHeat::after_step).
struct HeatedTimes {
  double wall = 0.0, cpu = 0.0;  // slowest rank's wall, this rank's CPU (s)
};

HeatedTimes time_heated3d(const fm::Grid<3>& grid, const std::vector<fm::Material>& mats,
                          const fm::DecomposedMpm3D::Options& opt, const std::vector<fm::DecomposedMpm3D::Particle>& all,
                          double dt, int steps, int rank, bool coupled, std::vector<double>* report) {
  fm::DecomposedMpm3D split(MPI_COMM_WORLD, grid, mats, opt);
  std::vector<fm::DecomposedMpm3D::Particle> mine = rank == 0 ? all : std::vector<fm::DecomposedMpm3D::Particle>{};
  if (!coupled)
    for (auto& p : mine) p.scalars.clear();  // no temperature field in the mechanics-only swarm
  split.add_particles(mine);
  mine.clear();
  mine.shrink_to_fit();
  frictherm::coupling::DecomposedHeatOptions ho;
  ho.materials = {{true, 100.0, 50.0}, {true, 150.0, 20.0}};
  std::unique_ptr<frictherm::coupling::DecomposedHeat> heat;
  if (coupled) heat = std::make_unique<frictherm::coupling::DecomposedHeat>(split, ho);
  split.step(dt);  // first step (set-up of the exchanges) not timed
  if (heat) heat->after_step(dt);
  const long exchanges0 = heat ? heat->books().exchanges : 0, substeps0 = heat ? heat->books().substeps : 0;
  MPI_Barrier(MPI_COMM_WORLD);
  const double w0 = MPI_Wtime(), c0 = cpu_seconds();
  for (int s = 0; s < steps; ++s) {
    split.step(dt);
    if (heat) heat->after_step(dt);
  }
  HeatedTimes t;
  t.cpu = cpu_seconds() - c0;
  MPI_Barrier(MPI_COMM_WORLD);
  t.wall = MPI_Wtime() - w0;
  MPI_Allreduce(MPI_IN_PLACE, &t.wall, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  if (report && heat) {
    // Per step and rank: the heat windows' grid exchanges, each moving this rank's ghost nodes × the
    // DMDA's 7 values × 8 B (what it receives; what it sends is alike).
    const fm::DecomposedTraffic& tr = split.traffic();
    const double per_step = static_cast<double>(heat->books().exchanges - exchanges0) / steps;
    *report = {static_cast<double>(split.local_particles()), static_cast<double>(tr.ghost_nodes),
               per_step * static_cast<double>(tr.ghost_nodes) * tr.values_per_node * 8.0,
               static_cast<double>(heat->books().substeps - substeps0) / steps, per_step,
               heat->books().work_received, heat->books().particle_energy_change};
  }
  return t;
}

void run_heated3d(const std::string& which, int nx, int ny, int nz, int steps, int repeat, int rank, int ranks) {
  const double h = 1e-3, rho = 1000.0, v0 = 10.0, g = 2e4;
  const fm::Grid<3> grid(V3::Zero(), V3::Constant(h), {nx, ny, nz});
  const std::vector<fm::Material> mats{elastic("base", 2e7), elastic("block", 1.5e7)};
  fm::DecomposedMpm3D::Options opt;
  opt.shape = fm::ShapeKind::ugimp;
  opt.gravity = V3(0.0, 0.0, -g);
  opt.fixed_faces = {fm::FixedFace{2, false, {{true, true, true}}}};
  opt.contact = true;
  opt.contact_options.default_pair.law = fm::FrictionLaw::coulomb(0.3);
  opt.contact_options.default_pair.normal = fm::NormalMethod::specified;
  opt.contact_options.default_pair.normal_vector = V3(0.0, 0.0, 1.0);
  opt.contact_pairs = {fm::DecomposedContactPair{0, 1, opt.contact_options.default_pair}};
  std::vector<fm::DecomposedMpm3D::Particle> all;
  const double W = nx * h, s = h / 2.0;
  auto box = [&](V3 lo, V3 hi, int material, double vx) {
    int m[3];
    for (int a = 0; a < 3; ++a) m[a] = static_cast<int>(std::lround((hi[a] - lo[a]) / s));
    for (int k = 0; k < m[2]; ++k)
      for (int j = 0; j < m[1]; ++j)
        for (int i = 0; i < m[0]; ++i) {
          fm::DecomposedMpm3D::Particle p;
          p.id = static_cast<std::int64_t>(all.size());
          p.position = lo + s * V3(i + 0.5, j + 0.5, k + 0.5);
          p.half_size = V3::Constant(s / 2.0);
          p.volume = s * s * s;
          p.mass = rho * p.volume;
          p.velocity = V3(vx, 0.0, 0.0);
          p.material = material;
          p.scalars = {300.0};
          all.push_back(p);
        }
  };
  if (rank == 0) {
    box(V3(h, h, 0.0), V3(W - h, (ny - 1) * h, (nz / 2) * h), 0, 0.0);
    box(V3(std::round(0.2 * nx) * h, h, (nz / 2) * h), V3(std::round(0.6 * nx) * h, (ny - 1) * h, (3 * nz / 4) * h), 1, v0);
  }
  long long count = static_cast<long long>(all.size());
  MPI_Bcast(&count, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  const double c = std::sqrt(mats[0].p_wave_modulus(fm::Analysis::three_d) / rho);
  const double dt = 0.5 * h / (c + 2.0 * v0);
  fm::DecomposedMpm3D::Options coupled_opt = opt;
  coupled_opt.particle_scalars = {"temperature"};
  std::vector<double> report;
  // `repeat` interleaved pairs; each figure is its smallest over them (other jobs on the machine only
  // ever add time, and interleaving exposes both runs to the same load).
  HeatedTimes mech{1e300, 0.0}, heat{1e300, 0.0};
  double cpu[2] = {1e300, 1e300};
  for (int r = 0; r < repeat; ++r) {
    const HeatedTimes m = time_heated3d(grid, mats, opt, all, dt, steps, rank, false, nullptr);
    const HeatedTimes cr = time_heated3d(grid, mats, coupled_opt, all, dt, steps, rank, true, &report);
    double both[2] = {m.cpu, cr.cpu};
    MPI_Allreduce(MPI_IN_PLACE, both, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    mech.wall = std::min(mech.wall, m.wall);
    heat.wall = std::min(heat.wall, cr.wall);
    cpu[0] = std::min(cpu[0], both[0]);
    cpu[1] = std::min(cpu[1], both[1]);
  }
  std::vector<double> rows(report.size() * static_cast<std::size_t>(ranks));
  MPI_Gather(report.data(), static_cast<int>(report.size()), MPI_DOUBLE, rows.data(), static_cast<int>(report.size()),
             MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (rank != 0) return;
  const double ps = static_cast<double>(count) * steps;
  std::printf("heated3d %-6s 3D %d rank%s  %dx%dx%d cells  %lld particles  %d steps, smallest of %d interleaved pairs\n",
              which.c_str(), ranks, ranks > 1 ? "s" : " ", nx, ny, nz, count, steps, repeat);
  std::printf("  mechanics only: wall %.3e s/step  cpu %.3e s/step (all ranks)  %.2f M p-steps/s  %.2f M p-steps/cpu-s\n",
              mech.wall / steps, cpu[0] / steps, ps / mech.wall / 1e6, ps / cpu[0] / 1e6);
  std::printf("  coupled:        wall %.3e s/step  cpu %.3e s/step (all ranks)  %.2f M p-steps/s  %.2f M p-steps/cpu-s"
              "  coupled/mechanics wall %.2f cpu %.2f\n",
              heat.wall / steps, cpu[1] / steps, ps / heat.wall / 1e6, ps / cpu[1] / 1e6, heat.wall / mech.wall,
              cpu[1] / cpu[0]);
  std::printf("  heat: %.2f sub-steps and %.1f grid exchanges per step; work %.4e J, particles' heat %.4e J\n", rows[3],
              rows[4], rows[5], rows[6]);
  for (int r = 0; r < ranks; ++r) {
    const double* a = &rows[report.size() * static_cast<std::size_t>(r)];
    std::printf("  rank %d: %.0f particles, %.0f ghost nodes, heat exchanges %.1f kB per step\n", r, a[0], a[1], a[2] / 1e3);
  }
  std::fflush(stdout);
}
#endif

}  // namespace

int main(int argc, char** argv) {
  fm::DecomposedPetscSession session(&argc, &argv);
  int cells = 200, steps = 100, cells3d = 24, repeat = 3;
  bool weak = false;
  std::string cases = "block,sliding";
  for (int a = 1; a < argc; ++a) {
    const std::string k = argv[a];
    if (k == "--weak") weak = true;
    else if (a + 1 < argc && k == "--cells") cells = std::atoi(argv[++a]);
    else if (a + 1 < argc && k == "--cells3d") cells3d = std::atoi(argv[++a]);
    else if (a + 1 < argc && k == "--steps") steps = std::atoi(argv[++a]);
    else if (a + 1 < argc && k == "--repeat") repeat = std::atoi(argv[++a]);
    else if (a + 1 < argc && k == "--cases") cases = argv[++a];
    else {
      std::fprintf(stderr, "unknown option %s (valid: --cells N, --cells3d N, --steps N, --repeat N, --weak, --cases "
                   "block,sliding,grains,grainsG,block3d,heated3d)\n", k.c_str());
      return 2;
    }
  }
  if (cells < 8 || cells3d < 6 || steps < 1 || repeat < 1) {
    std::fprintf(stderr, "--cells must be at least 8, --cells3d at least 6, --steps and --repeat at least 1\n");
    return 2;
  }
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  // 2D weak scaling: the area grows with the ranks (cells along x and y by √ranks).
  const int n = weak ? static_cast<int>(std::lround(cells * std::sqrt(static_cast<double>(ranks)))) : cells;
  if (rank == 0)
    std::printf("mechanics_distributed_scaling: %d ranks, 2D cases %s scaling, 1 mm cells, uGIMP 2 per cell and axis\n",
                ranks, weak ? "weak" : "strong");
  for (std::size_t at = 0; at <= cases.size();) {
    const std::size_t comma = std::min(cases.find(',', at), cases.size());
    const std::string c = cases.substr(at, comma - at);
    if (c == "block" || c == "sliding" || c.rfind("grains", 0) == 0) {
      run_case(c, n, steps, rank, ranks);
    } else if (c == "block3d") {
      // Strong: cells3d × ⅔ cells3d × ⅔ cells3d on any rank count. Weak: the block's x extent (cells3d − 2
      // cells) times the ranks, so the particles per rank stay those of the one-rank run.
      const int n3 = std::max(6, 2 * cells3d / 3);
      run_block3d("strong", cells3d, n3, steps, rank, ranks);
      if (ranks > 1) run_block3d("weak", (cells3d - 2) * ranks + 2, n3, steps, rank, ranks);
      else if (rank == 0) std::printf("weak     3D 1 rank: the strong run above\n");
#ifdef FRICTHERM_BENCH_DECOMPOSED_HEAT
    } else if (c == "heated3d") {
      // Strong: cells3d × ⅔ cells3d × ½ cells3d on any rank count; weak: the x extent (cells3d − 2
      // cells) times the ranks.
      const int ny = std::max(6, 2 * cells3d / 3), nz = std::max(6, cells3d / 2);
      run_heated3d("strong", cells3d, ny, nz, steps, repeat, rank, ranks);
      if (ranks > 1) run_heated3d("weak", (cells3d - 2) * ranks + 2, ny, nz, steps, repeat, rank, ranks);
      else if (rank == 0) std::printf("heated3d weak 1 rank: the strong run above\n");
#endif
    } else if (rank == 0) {
      std::fprintf(stderr, "unknown case '%s' (valid: block, sliding, grains, grainsG, block3d, heated3d)\n", c.c_str());
    }
    at = comma + 1;
  }
  return 0;
}
