// The Arrhenius reaction in a decomposed run (issue 32; thermal.reaction, decomposed_reaction.cpp and
// the distributed integrators' λ): `mpirun -n 2 frictherm run` against `frictherm run --threads 1` on
// the PBX specimen (examples/pbx_compaction.json as written: its reaction held back to the
// continuation, its interface temperature) shortened to 0.2 us of compaction and 1 us of conduction
// alone in 4 intervals. Rogers' HMX kinetics do nothing at 293 K (λ ~ 1e-15 in 1 us), so the reaction
// is made fast: Z = 7.74e11 /s, E_a = 49 886 J/mol (Θ = 6000 K: k(293.15 K) = 1000 /s), q = 2.09 MJ/kg
// (HMX's): the grains react to λ ≈ 1.1e-3 and warm by 2.4 K in the microsecond. Checked:
//   * series reaction_heat, max_reaction_progress, max_interface_reaction_progress,
//     max_interface_temperature, max_temperature every row; the same CVODE steps;
//   * snapshot fields reaction_progress and interface_reaction_progress of every particle (by id over
//     both rank files) at the continuation's end;
//   * metadata reaction_heat_released = particle_reaction_heat (the heat the nodes released is the
//     particles' q Σ m λ_p), the energy changes the serial run's and = heat delivered + reaction heat;
//   * the same with the reaction during loading too (thermal.reaction.during_loading), without and
//     with the interface temperature (its interface reaction then runs during loading as well, λ_int,p
//     migrating with the particles as a particle scalar).
// Tolerances: both runs integrate [T; λ] with CVODE, GMRES and the serial 2×2 block-Jacobi
// preconditioner to rtol = 1e-8, atol = 1e-6 K, progress_atol = 1e-6: converged to 0.1 of the error
// weights (test_cli_mpirun.cpp): temperatures within 0.1 (rtol T_max + atol) = 3.0e-7 K, λ within
// 0.1 (rtol λ_max + progress_atol) = 1.0e-7, the reaction heat within the same fraction of λ_max.
// Skipped when mpirun is not installed. Labels verification;mpi.
#include <gtest/gtest.h>

#include "mpirun_compare_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace {

using frictherm::test::read_doubles;

const char* const kScene = "examples/pbx_compaction.json";
const char* const kSets =
    " --set run.end_time=2e-7 --set output.series_interval=null --set output.snapshot_count=1"
    " --set 'coupling.continuation={\"duration\":1e-6,\"intervals\":4}'"
    " --set 'thermal.reaction.kinetics={\"prefactor\":7.74e11,\"activation_energy\":49886,\"heat_of_reaction\":2.09e6}'";
constexpr double kRtol = 1e-8, kAtol = 1e-6, kProgressAtol = 1e-6;

class MpirunReaction : public frictherm::test::MpirunCompare {
 protected:
  double meta(const std::string& file, const std::string& key) const {
    const std::vector<double> v = read_doubles(path(file), "/meta/" + key);
    return v.empty() ? std::nan("") : v[0];
  }

  // Largest |serial − split| (NaN rows equal in both).
  double max_difference(const std::vector<double>& a, const std::vector<double>& b, const std::string& what) const {
    EXPECT_FALSE(a.empty()) << what;
    EXPECT_EQ(a.size(), b.size()) << what;
    double diff = 0.0;
    for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
      if (std::isnan(a[k]) || std::isnan(b[k])) {
        EXPECT_TRUE(std::isnan(a[k]) && std::isnan(b[k])) << what << " row " << k;
        continue;
      }
      diff = std::max(diff, std::fabs(a[k] - b[k]));
    }
    return diff;
  }

  double column_difference(const std::string& c, double bound) const {
    const double d = max_difference(column("serial.h5", c), column("split.h5", c), c);
    EXPECT_LE(d, bound) << c;
    std::printf("  %-32s %.3g from the serial run (bound %.3g)\n", c.c_str(), d, bound);
    return d;
  }

  // The last snapshot's `field` of every particle over both rank files against the serial run's.
  double field_difference(const std::string& field, double bound) const {
    const std::string snap = "/snapshots/000002/";
    const std::vector<double> a = read_doubles(path("serial.h5"), snap + field);
    EXPECT_EQ(a.size(), 15376u) << field;
    std::vector<double> b(a.size(), std::nan(""));
    for (int r = 0; r < 2; ++r) {
      const std::string f = "split.rank" + std::to_string(r) + ".h5";
      const std::vector<double> id = read_doubles(path(f), snap + "id"), v = read_doubles(path(f), snap + field);
      EXPECT_EQ(id.size(), v.size()) << f << " " << field;
      for (std::size_t k = 0; k < std::min(id.size(), v.size()); ++k) b.at(static_cast<std::size_t>(id[k])) = v[k];
    }
    for (double x : b) EXPECT_FALSE(std::isnan(x)) << field << ": a particle missing";
    const double d = max_difference(a, b, field);
    EXPECT_LE(d, bound) << field;
    std::printf("  snapshot %-23s %.3g from the serial run (bound %.3g)\n", field.c_str(), d, bound);
    return d;
  }

  void compare(bool interface) {
    const std::vector<double> lam = column("serial.h5", "max_reaction_progress");
    ASSERT_FALSE(lam.empty());
    const double lam_max = *std::max_element(lam.begin(), lam.end());
    EXPECT_GT(lam_max, 5e-4) << "the grains react";
    EXPECT_LT(lam_max, 1e-2) << "without running away";
    const std::vector<double> Ts = column("serial.h5", "max_temperature");
    const double t_max = *std::max_element(Ts.begin(), Ts.end());
    EXPECT_GT(t_max, 295.0) << "the reaction heats them";
    const double dT = 0.1 * (kRtol * t_max + kAtol), dlam = 0.1 * (kRtol * lam_max + kProgressAtol);
    const double heat = meta("serial.h5", "reaction_heat_released");
    EXPECT_EQ(meta("split.h5", "thermal_steps"), meta("serial.h5", "thermal_steps"));
    column_difference("max_temperature", dT);
    column_difference("max_reaction_progress", dlam);
    column_difference("reaction_heat", heat * dlam / lam_max);
    field_difference("temperature", dT);
    field_difference("reaction_progress", dlam);
    if (interface) {
      column_difference("max_interface_temperature", dT);
      column_difference("max_interface_reaction_progress", dlam);
      field_difference("interface_reaction_progress", dlam);
    }
    // Books: the heat the nodes released is the particles' q Σ m λ_p; the energy changes hold it.
    const double released = meta("split.h5", "reaction_heat_released");
    EXPECT_NEAR(released, heat, heat * dlam / lam_max);
    EXPECT_NEAR(meta("split.h5", "particle_reaction_heat"), released, 1e-12 * released);
    // The energy changes: the serial run's, and heat delivered + reaction heat to the integrator's
    // imbalance (Newton and GMRES stop at 0.1 of the error weights: Σ M T − Σ Q λ is not kept exactly;
    // measured 8e-9 of the reaction heat in both runs).
    const double delivered = meta("split.h5", "heat_delivered");
    for (const char* k : {"nodal_energy_change", "particle_energy_change"}) {
      EXPECT_NEAR(meta("split.h5", k), meta("serial.h5", k), 1e-9 * released) << k;
      EXPECT_NEAR(meta("split.h5", k), delivered + released, 1e-7 * released) << k;
    }
    std::printf("  reaction heat %.6g J/m, λ_max %.4g, T_max %.4f K\n", released, lam_max, t_max);
  }
};

TEST_F(MpirunReaction, PbxReactionInTheContinuationEqualsTheSerialRun) {
  run_both(kScene, kSets, 2);
  if (HasFatalFailure()) return;
  compare(true);
}

// Forward Euler with the reaction (its reacting sub-steps: the serial Scheme on the distributed ODE,
// the self-heating step bound agreed over the ranks), during loading and in the continuation.
TEST_F(MpirunReaction, PbxReactionWithForwardEulerEqualsTheSerialRun) {
  run_both(kScene,
           std::string(kSets) + " --set thermal.integrator=forward_euler --set thermal.linear_solver=null --set thermal.reaction.during_loading=true"
                                " --set coupling.interface_temperature=null",
           2);
  if (HasFatalFailure()) return;
  compare(false);
}

TEST_F(MpirunReaction, PbxReactionDuringLoadingEqualsTheSerialRun) {
  run_both(kScene,
           std::string(kSets) + " --set thermal.reaction.during_loading=true --set coupling.interface_temperature=null",
           2);
  if (HasFatalFailure()) return;
  compare(false);
}

// The interface reaction during loading: λ_int,p advanced every window at T_int,p while the
// particles move between the ranks (0.2 us of compaction, ~360 steps), then in the continuation.
TEST_F(MpirunReaction, PbxInterfaceReactionDuringLoadingEqualsTheSerialRun) {
  run_both(kScene, std::string(kSets) + " --set thermal.reaction.during_loading=true", 2);
  if (HasFatalFailure()) return;
  compare(true);
  // The interface reaction acted during loading: its progress at the end of loading is not zero.
  const std::vector<double> lam = column("serial.h5", "max_interface_reaction_progress");
  const std::vector<double> t = column("serial.h5", "time");
  double at_end_of_loading = 0.0;
  for (std::size_t k = 0; k < std::min(lam.size(), t.size()); ++k)
    if (t[k] <= 2e-7 * (1.0 + 1e-9)) at_end_of_loading = lam[k];
  EXPECT_GT(at_end_of_loading, 0.0);
  std::printf("  interface λ_max at the end of loading %.4g\n", at_end_of_loading);
}

// What a decomposed run takes with a reaction, said by `frictherm validate` (the same check,
// decomposed_run_refusal, refuses `mpirun -n K frictherm run` what it does not take): with the
// interface temperature, the reaction during loading or held back; forward Euler with the reaction.
TEST_F(MpirunReaction, ValidateNamesWhatIsNotDecomposed) {
  const std::string scene = source("tests/coupling/scenes/decomposed_sliding_block.json");
  const std::string reaction =
      " --set 'thermal.reaction={\"kinetics\":\"hmx_rogers1975\",\"materials\":[\"block\"]}'";
  const std::pair<std::string, std::string> cases[] = {
      {reaction, "mpirun -n K frictherm run decomposes it"},  // forward Euler (the scene's) with the reaction
      {reaction + " --set thermal.integrator=cvode_bdf --set coupling.interface_temperature=true",
       "mpirun -n K frictherm run decomposes it"},
      {reaction + " --set thermal.integrator=cvode_bdf", "mpirun -n K frictherm run decomposes it"},
      {reaction + " --set thermal.integrator=auto --set coupling.interface_temperature=true"
                  " --set thermal.reaction.during_loading=false",
       "mpirun -n K frictherm run decomposes it"}};
  for (const auto& [sets, expected] : cases) {
    const frictherm::test::Result r = frictherm::test::shell(exe() + " validate " + scene + sets);
    EXPECT_EQ(r.code, 0) << sets << ": " << r.output;
    EXPECT_NE(r.output.find(expected), std::string::npos) << sets << ": " << r.output;
  }
}

}  // namespace
