// `frictherm continue` (coupling/app/cli_continue.cpp, issue 17): one PBX loading
// (examples/pbx_microstructure_small.json, 2 us of compaction, hot spots above a 3 K rise, 20 us of
// conduction with Arrhenius heat after it) continued with two other thermal integrators gives the
// hot-spot fates that running each integrator from scratch gives: the same hot spots (ids), fates and
// decision times, and peak temperatures within 5 mK (the scratch runs' loadings differ from the saved
// one by their integrators' tolerances; measured: below 1 mK). Keys that change the loading are refused.
#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/results.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace frictherm;

namespace {

const std::string kSets =
    " --quiet --force --set run.threads=1 --set run.end_time=2e-6"
    // Matrix-free forward Euler reuses its gather across loading windows (coupling.reuse_distance),
    // which moves peaks by ~0.1 %: off, so that loading with any integrator is the same to round-off
    // and only the continuation's integrator differs between `continue` and a run from scratch.
    " --set coupling.reuse_distance=0"
    " --set 'thermal.reaction={\"kinetics\": \"hmx_rogers1975\", \"materials\": [\"hmx\"], \"during_loading\": false}'"
    // 2 K: the scene's USL update with the PIC blend heats less than MUSL with FLIP did (7 hot spots).
    " --set 'coupling.hotspots={\"mode\": \"rise\", \"threshold\": 2.0, \"min_particles\": 2}'"
    " --set 'coupling.continuation={\"duration\": 20e-6, \"intervals\": 20}'";

int sh(const std::string& command) { return std::system(command.c_str()); }

TEST(CliContinue, TwoIntegratorsGiveTheFatesOfRunsFromScratch) {
  const fs::path dir = fs::temp_directory_path() / ("frictherm_continue_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string exe = FRICTHERM_EXE, d = dir.string() + "/";
  const std::string scene = std::string(FRICTHERM_SOURCE_DIR) + "/examples/pbx_microstructure_small.json";
  ASSERT_EQ(sh(exe + " run " + scene + " -o " + d + "base.h5" + kSets), 0);
  ASSERT_TRUE(fs::exists(d + "base.h5.checkpoint")) << "the end-of-loading checkpoint";
  for (const std::string integrator : {"forward_euler", "cvode_adams"}) {
    const std::string cont = d + integrator + "_continued.h5", full = d + integrator + "_scratch.h5";
    ASSERT_EQ(sh(exe + " continue " + d + "base.h5 -o " + cont + " --quiet --set thermal.integrator=" + integrator), 0);
    ASSERT_EQ(sh(exe + " run " + scene + " -o " + full + kSets + " --set thermal.integrator=" + integrator), 0);
    EXPECT_EQ(coupling::read_metadata_string(cont, "thermal_integrator"), integrator);
    const coupling::SeriesTable a = coupling::read_table(cont, "hotspot_fates"), b = coupling::read_table(full, "hotspot_fates");
    ASSERT_GE(a.column("id").size(), 3u) << "the loading must leave hot spots";
    ASSERT_EQ(a.column("id"), b.column("id")) << integrator;
    EXPECT_EQ(a.column("fate"), b.column("fate")) << integrator;
    EXPECT_EQ(a.column("decision_time"), b.column("decision_time")) << integrator;
    for (const char* c : {"initial_peak_temperature", "final_peak_temperature", "max_peak_temperature"})
      for (std::size_t i = 0; i < a.column(c).size(); ++i)
        EXPECT_NEAR(a.column(c)[i], b.column(c)[i], 5e-3) << integrator << " " << c << " of hot spot " << i;
    // The continued result keeps the loading: as many series rows as the run from scratch.
    EXPECT_EQ(coupling::read_series(cont).column("time").size(), coupling::read_series(full).column("time").size());
  }
  // A key of the loading is refused (exit code 2) and nothing is written.
  EXPECT_EQ(WEXITSTATUS(sh(exe + " continue " + d + "base.h5 -o " + d + "bad.h5 --set solver.cfl=0.3 2>" + d + "err.txt")), 2);
  std::ifstream in(d + "err.txt");
  const std::string err((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(err.find("solver.cfl"), std::string::npos) << err;
  EXPECT_NE(err.find("thermal."), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(d + "bad.h5"));
  fs::remove_all(dir);
}

// Issue 34: `continue --set thermal.reaction=...` of a loading without a reaction had failed at the
// append (exit 1, "the columns of /series differ"). The continued result keeps the loading's rows bit
// for bit, gets the reaction's columns (0 in the loading's rows: nothing released, λ = 0), and its
// books close on every row: with adiabatic edges Σ_p m_p c_p ΔT_p = heat_delivered + reaction_heat
// (docs/coupling.md). λ starts at 0: the released heat equals q Σ_p m_p λ_p (particle_reaction_heat).
TEST(CliContinue, AReactionTheLoadingDidNotHaveStartsFromZeroAndTheBooksClose) {
  const fs::path dir = fs::temp_directory_path() / ("frictherm_continue_reaction_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string exe = FRICTHERM_EXE, d = dir.string() + "/";
  const std::string scene = std::string(FRICTHERM_SOURCE_DIR) + "/examples/pbx_microstructure_small.json";
  ASSERT_EQ(sh(exe + " run " + scene + " -o " + d + "inert.h5 --quiet --force --set run.threads=1 --set run.end_time=1e-6"
                    " --set thermal.reaction=null --set 'coupling.continuation={\"duration\": 5e-6, \"intervals\": 5}'"),
            0);
  // Kinetics fast at room temperature (k = 1e5 exp(-1000 K/T) ≈ 3.6e3 1/s at 300 K: λ ≈ 2 % in 5 us,
  // 0.4 J released, 100 K of self-heating at most), so that the reaction heat dwarfs the loading's
  // frictional heat (0.6 mJ) and the balance below tests it.
  ASSERT_EQ(sh(exe + " continue " + d + "inert.h5 -o " + d + "reacting.h5 --quiet --set 'thermal.reaction={\"kinetics\": "
                    "{\"prefactor\": 1e5, \"activation_energy\": 8314.0, \"heat_of_reaction\": 5e6}, \"materials\": "
                    "[\"hmx\"], \"during_loading\": false}'"),
            0)
      << "continue with a reaction the loading did not have";
  const std::size_t loading = static_cast<std::size_t>(coupling::checkpoint_marks(d + "inert.h5.checkpoint").series_rows);
  const coupling::SeriesTable inert = coupling::read_series(d + "inert.h5"), s = coupling::read_series(d + "reacting.h5");
  const std::size_t rows = s.column("time").size();
  ASSERT_EQ(rows, loading + 5) << "the loading's rows, then one per continuation interval";
  for (const std::string& name : inert.names)  // the loading's rows as they were (NaN where they were NaN)
    for (std::size_t r = 0; r < loading; ++r) {
      const double a = inert.column(name)[r], b = s.column(name)[r];
      ASSERT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << name << " row " << r << ": " << a << " became " << b;
    }
  const std::vector<double>&q = s.column("reaction_heat"), &lam = s.column("max_reaction_progress"),
                   &heat = s.column("heat_delivered"), &e = s.column("thermal_energy_change");
  for (std::size_t r = 0; r < loading; ++r) ASSERT_TRUE(q[r] == 0.0 && lam[r] == 0.0) << "loading row " << r;
  for (std::size_t r = loading; r < rows; ++r) EXPECT_GT(q[r], q[r - 1]) << "the reaction releases heat in interval " << r - loading;
  ASSERT_GT(q.back(), 100.0 * heat.back()) << "the reaction heat must dominate the balance";
  // The books on every row, relative to the energy the run moves (0.42 J). Σ M ΔT = Q Δλ is a linear
  // invariant the integrator keeps (1ᵀK = 0) up to its linear solves and round-off (Σ_p m_p c_p T_p
  // of ~2 J summed over the particles): measured at most 6e-14 J (1.4e-13); 1e-9 leaves room for the
  // iterative solver, while a λ, a heat or a row off by one interval is off by percent.
  const double moved = heat.back() + q.back();
  for (std::size_t r = 0; r < rows; ++r) EXPECT_NEAR(e[r], heat[r] + q[r], 1e-9 * moved) << "row " << r;
  // λ from 0: the heat the particles' progress holds, q Σ m_p λ_p, is the heat released (round-off).
  const double released = coupling::read_metadata_number(d + "reacting.h5", "reaction_heat_released");
  EXPECT_DOUBLE_EQ(released, q.back());
  EXPECT_NEAR(coupling::read_metadata_number(d + "reacting.h5", "particle_reaction_heat"), released, 1e-12 * released);
  // The joined result continues in turn: its checkpoint has the reaction, the columns now agree.
  EXPECT_EQ(sh(exe + " continue " + d + "reacting.h5 -o " + d + "again.h5 --quiet --set thermal.rtol=1e-7"), 0);
  EXPECT_EQ(coupling::read_series(d + "again.h5").column("reaction_heat").size(), rows);
  // Hot spots judged by the interface temperature need the loading's: refused by the key (exit 2),
  // not as a damaged checkpoint ("has no '/interface/boundaries'", before), nothing written.
  EXPECT_EQ(WEXITSTATUS(sh(exe + " continue " + d + "inert.h5 -o " + d + "iface.h5 --quiet"
                                 " --set coupling.hotspots.temperature=interface 2>" + d + "err.txt")),
            2);
  std::ifstream in(d + "err.txt");
  const std::string err((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(err.find("coupling.hotspots.temperature"), std::string::npos) << err;
  EXPECT_EQ(err.find("damaged"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(d + "iface.h5"));
  fs::remove_all(dir);
}

// The other way (issue 34): a loading whose hot spots were judged by the interface temperature,
// continued by the grid temperature, had failed at the append too (max_interface_temperature only in
// the loading). Its loading rows are kept, the continuation's are NaN (not computed there).
TEST(CliContinue, AColumnOnlyTheLoadingHasIsKeptWithNaNAfterIt) {
  const fs::path dir = fs::temp_directory_path() / ("frictherm_continue_grid_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string exe = FRICTHERM_EXE, d = dir.string() + "/";
  const std::string scene = std::string(FRICTHERM_SOURCE_DIR) + "/examples/pbx_microstructure_small.json";
  ASSERT_EQ(sh(exe + " run " + scene + " -o " + d + "iface.h5 --quiet --force --set run.threads=1 --set run.end_time=1e-6"
                    " --set thermal.reaction=null --set coupling.hotspots.temperature=interface"
                    " --set 'coupling.continuation={\"duration\": 5e-6, \"intervals\": 5}'"),
            0);
  ASSERT_EQ(sh(exe + " continue " + d + "iface.h5 -o " + d + "grid.h5 --quiet --set coupling.hotspots.temperature=grid"), 0);
  const std::size_t loading = static_cast<std::size_t>(coupling::checkpoint_marks(d + "iface.h5.checkpoint").series_rows);
  const std::vector<double> a = coupling::read_series(d + "iface.h5").column("max_interface_temperature"),
                            b = coupling::read_series(d + "grid.h5").column("max_interface_temperature");
  ASSERT_EQ(b.size(), loading + 5);
  ASSERT_GT(a[loading - 1], 300.0) << "the loading heated the interfaces";
  for (std::size_t r = 0; r < loading; ++r) ASSERT_TRUE(a[r] == b[r] || (std::isnan(a[r]) && std::isnan(b[r]))) << r;
  for (std::size_t r = loading; r < b.size(); ++r) EXPECT_TRUE(std::isnan(b[r])) << r;
  fs::remove_all(dir);
}

}  // namespace
