// Which scenes the decomposed engine runs (decomposed_support.hpp): every feature DecomposedMpm and
// DecomposedHeat implement, checked key by key before anything is built, so that a scene they do not
// support is refused with the scene key, its value and the way out (the serial run).
#include <frictherm/coupling/decomposed_support.hpp>

#include <string>

namespace frictherm::coupling {

namespace {

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

// "KEY: VALUE is not supported in a decomposed run (expected ...); the serial run (without mpirun,
// or mpirun -n 1) supports it".
std::string refuse(const std::string& key, const std::string& value, const std::string& expected) {
  return key + ": " + value + " is not supported in a decomposed run (expected " + expected +
         "); the serial run (without mpirun, or with -n 1) supports it";
}

// The mechanics refuse nothing now; the check stays with the others for what comes next.
std::string mechanics_refusal(const Scene&) {
  // Every shape function runs decomposed, the extended B-spline too (the serial EbsBasis on the
  // particles gathered from all ranks, a ghost layer of its reach: mechanics/src/distributed/extended_bsplines.cpp).
  // USL, MUSL and USF with or without contact (DecomposedMpm: the USL phases with, under MUSL, the
  // remap, its exchange and, with multimaterial contact, the contact pass on the remapped momenta;
  // under USF the stress update from the extrapolated velocities after their ghost update, then the
  // forces and their exchange: mechanics/src/distributed/phase_lists.cpp).
  // Every grid-to-particle transfer: FLIP with the PIC blend, XPIC and FMPM (the filters' series at
  // the owners with a Dim-vector exchange per term: mechanics/src/distributed/velocity_filter.cpp).
  // Damping, point loads and tractions run decomposed (the serial kernels, loads/grid_loads.hpp).
  // Every material kind runs decomposed (DecomposedMpm: linear elastic, neo-Hookean, Mie-Grüneisen/J2,
  // rigid walls and rigid contact partners; docs/distributed_pbx.md).
  return "";
}

std::string contact_refusal(const Scene& s) {
  if (!s.contact.enabled) return "";
  const mechanics::ContactOptions& c = s.contact.options;
  // Penalty contact runs (DecomposedMpm: the serial kernels on the points replicated on every rank,
  // mechanics/src/distributed/penalty_phases.cpp) when every pair uses it.
  const bool penalty = c.default_pair.method == mechanics::ContactMethod::penalty;
  for (std::size_t i = 0; i < s.contact.pairs.size(); ++i)
    if ((s.contact.pairs[i].settings.method == mechanics::ContactMethod::penalty) != penalty)
      return refuse("contact.pairs[" + std::to_string(i) + "].method",
                    quoted(mechanics::to_string(s.contact.pairs[i].settings.method)) + " beside contact.method " +
                        quoted(mechanics::to_string(c.default_pair.method)),
                    "every pair with the same method");

  // The regularisation runs (the serial kernel with each owned node's lagged traction, which its
  // checkpoints hold: DecomposedMpm::CheckpointState).
  return "";
}

std::string thermal_refusal(const Scene& s) {
  if (!s.thermal.enabled) return "";
  // Every integrator name runs (DecomposedHeat: matrix-free forward Euler, or the distributed integrator
  // of that name on the assembled rows); every linear solver: "klu", the serial sparse direct solve, as
  // MUMPS' sparse direct LU of I − γJ over the ranks preconditioning PCG (make_distributed_integrator).
  // Matrix-free windows with the serial "substep" policy and the Gershgorin estimate; every other
  // policy and estimate runs, as serially, the serial forward Euler Scheme on the assembled rows
  // ("refuse" stops every rank alike: the limit is reduced over ranks; "power" iterates with reduced
  // dot products from the serial start vector: DistributedProblem::lambda_max_power).
  // thermal.forward_euler.max_dt caps the sub-steps of both paths (as the serial Coupler's window).
  // Fixed-temperature faces run (DecomposedHeat: the serial for_each_fixed_node, both paths).
  // The reaction runs on assembled windows (DecomposedHeat, decomposed_reaction.cpp; the distributed
  // integrators carry λ: forward Euler's reacting sub-steps too, the serial Scheme on the distributed
  // ODE); its interface reaction during loading or from the continuation on, λ_int,p and its rate in
  // particle scalars that migrate with the particles (decomposed_interface.cpp).
  // The interface temperature runs on the owned nodes (decomposed_interface.cpp); its patches
  // (patch_length > 0) from every rank's heated nodes gathered; its checkpoints hold each rank's
  // histories (resumed on the rank count that wrote them).
  // Every window policy runs (every_step, every_n_steps, adaptive: DecomposedHeat::after_step). Matrix-free
  // windows reuse the last gather as the serial ones when the scene sets coupling.reuse_distance > 0
  // (DecomposedHeat::reuse_window, the particles' gather positions in particle scalars); without the
  // key they gather every window (the serial default reuse distance is not applied there).
  // Plastic heating and the sub-grid relaxation run (DecomposedHeat, decomposed_sources.cpp).
  // The continuation runs (DecomposedHeat::continue_thermal, the fates reduced over ranks), with
  // checkpoints during the loading and at its end (a resume from the end reruns the continuation).
  return "";
}

}  // namespace

std::string decomposed_run_refusal(const Scene& scene) {
  for (const std::string& why : {mechanics_refusal(scene), contact_refusal(scene), thermal_refusal(scene)})
    if (!why.empty()) return why;
  return "";
}

}  // namespace frictherm::coupling
