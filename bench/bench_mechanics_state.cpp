// The mechanics step's throughput and end state (issue 35): four scenes through the Simulation API
// (no coupling), 1 thread by default: the sliding block with contact at 1 mm (USL, AVG normals) and
// 2.5 mm (MUSL, MVG normals, displacement separation), as one material at 1 mm, and a 3D linear elastic
// base under a Mie-Gruneisen/J2 block (contact, MVG, displacement, gravity). Prints CPU seconds of the
// steps, M particle-steps per CPU-second and an FNV-1a hash of every particle's position, velocity,
// stress, F, volume, sigma_zz, plastic strain, energy and plastic work: two builds that should give
// the same bits print the same hashes. Asserts nothing.
//   bench_mechanics_state [scale [threads]]   (scale 1: 300 steps in 2D, 50 in 3D)
#include "../tests/verification/sliding_block.hpp"
#include <frictherm/mechanics/simulation.hpp>
#include <omp.h>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <string>
#include <cstdlib>
#include <cmath>
using namespace frictherm;
using namespace frictherm::mechanics;
static double cpu_now() { timespec t; clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
static double wall_now() { timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
struct Hash { std::uint64_t h = 1469598103934665603ULL;
  void add(const void* p, std::size_t n) { auto* b = static_cast<const unsigned char*>(p); for (std::size_t i = 0; i < n; ++i) { h ^= b[i]; h *= 1099511628211ULL; } } };
template <int Dim, class V> void addv(Hash& H, const std::vector<V>& v) { H.add(v.data(), v.size() * sizeof(V)); }
template <int Dim> std::uint64_t state_hash(const Simulation<Dim>& s) {
  const auto& p = s.particles(); Hash H;
  addv<Dim>(H, p.position); addv<Dim>(H, p.velocity); addv<Dim>(H, p.stress); addv<Dim>(H, p.deformation_gradient);
  addv<Dim>(H, p.volume); addv<Dim>(H, p.stress_zz); addv<Dim>(H, p.plastic_strain); addv<Dim>(H, p.internal_energy); addv<Dim>(H, p.plastic_work);
  return H.h; }
template <int Dim> void run(const char* name, Simulation<Dim>& sim, int warm, int steps) {
  for (int s = 0; s < warm; ++s) sim.step();
  const double c0 = cpu_now(), w0 = wall_now();
  for (int s = 0; s < steps; ++s) sim.step();
  const double cpu = cpu_now() - c0, wall = wall_now() - w0;
  const double ps = double(sim.particles().size()) * steps;
  std::printf("%-22s %7zu particles %5d steps  cpu %7.3f s wall %7.3f s  %6.2f M p-steps/cpu-s  hash %016llx\n", name,
              sim.particles().size(), steps, cpu, wall, ps / cpu / 1e6, (unsigned long long)state_hash(sim));
  std::fflush(stdout);
}
Simulation<3> block3d(double h, bool mg) {
  SimulationOptions o; o.analysis = Analysis::three_d; o.shape = ShapeKind::ugimp; o.scheme = UpdateScheme::usl; o.cfl = 0.5;
  o.gravity = Vec<3>(0, 0, -9806.65);
  const int n = static_cast<int>(std::lround(0.04 / h));
  Simulation<3> sim(Grid<3>(Vec<3>::Zero(), Vec<3>::Constant(h), IVec<3>{n + 2, n + 2, n + 2}), o);
  Material base; base.name = "base"; base.density = 1000; base.youngs_modulus = 2.5e9; base.poisson_ratio = 0.33;
  Material blk = base; blk.name = "block";
  if (mg) { blk.kind = MaterialKind::mie_gruneisen; blk.density = 1891; blk.mie_gruneisen.density = 1891; blk.mie_gruneisen.C0 = 3070;
    blk.mie_gruneisen.S1 = 1.79; blk.mie_gruneisen.gamma0 = 0.7; blk.mie_gruneisen.shear_modulus = 4.81e9; blk.mie_gruneisen.yield_stress = 2.6e8; }
  const int a = sim.add_material(base), b = sim.add_material(blk);
  sim.add_body("base", *make_box<3>(Vec<3>(h, h, h), Vec<3>(0.04, 0.04, 0.02), a), 2, Vec<3>::Zero());
  sim.add_body("block", *make_box<3>(Vec<3>(0.01, 0.01, 0.02), Vec<3>(0.03, 0.03, 0.032), b), 2, Vec<3>(20, 0, -20));
  ContactOptions co; co.default_pair.law = FrictionLaw::coulomb(0.3); co.default_pair.normal = NormalMethod::max_volume_gradient;
  co.separation = SeparationMethod::displacement; sim.enable_contact(co);
  sim.set_contact_pair(a, b, co.default_pair);
  sim.fix_face(FixedFace{2, false, {{true, true, true}}});
  return sim;
}
int main(int argc, char** argv) {
  omp_set_num_threads(argc > 2 ? std::atoi(argv[2]) : 1);
  const double scale = argc > 1 ? std::atof(argv[1]) : 1.0;
  const int S = static_cast<int>(300 * scale);
  using verification::SlidingBlockSetup;
  { SlidingBlockSetup s; s.cell = 0.001; s.scheme = UpdateScheme::usl; s.normal = NormalMethod::average_volume_gradient; int bm;
    auto sim = verification::make_sliding_block(s, bm); run("2D contact 1mm USL", sim, 10, S); }
  { SlidingBlockSetup s; s.cell = 0.0025; s.scheme = UpdateScheme::musl; s.normal = NormalMethod::max_volume_gradient;
    s.separation = SeparationMethod::displacement; int bm;
    auto sim = verification::make_sliding_block(s, bm); run("2D contact 2.5mm MUSL", sim, 10, S); }
  { SlidingBlockSetup s; s.cell = 0.001; s.scheme = UpdateScheme::usl; s.single_material = true; int bm;
    auto sim = verification::make_sliding_block(s, bm); run("2D no contact 1mm USL", sim, 10, S); }
  { auto sim = block3d(0.002, true); run("3D contact MG 2mm USL", sim, 5, S / 6); }
}
