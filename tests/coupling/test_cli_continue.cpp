// `frictherm continue` (coupling/app/cli_continue.cpp, issue 17): one PBX loading
// (examples/pbx_microstructure_small.json, 2 us of compaction, hot spots above a 3 K rise, 20 us of
// conduction with Arrhenius heat after it) continued with two other thermal integrators gives the
// hot-spot fates that running each integrator from scratch gives: the same hot spots (ids), fates and
// decision times, and peak temperatures within 5 mK (the scratch runs' loadings differ from the saved
// one by their integrators' tolerances; measured: below 1 mK). Keys that change the loading are refused.
#include <frictherm/coupling/results.hpp>

#include <gtest/gtest.h>

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

}  // namespace
