// Resource bombs and endless runs refused by `frictherm validate` (issue 15 items 1-2, scene_cost.hpp):
// each bad scene exits with code 2, with one message naming the key path and the numbers, before
// anything large is allocated (its peak resident size is checked, not its wall time: a loaded
// machine must not fail the test; tests/robustness/bad_inputs.py bounds CPU time and 200 MB).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_test_support.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

namespace {

struct Result {
  int code = -1;
  std::string output;
  double peak_mb = 0.0;  // largest resident size of any child this process has waited for
};

Result validate(const std::string& scene, const std::string& sets) {
  const std::string cmd = std::string("'") + FRICTHERM_EXE + "' validate '" + scene + "' " + sets + " 2>&1";
  Result r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int status = pclose(p);
  rusage children{};
  getrusage(RUSAGE_CHILDREN, &children);
  r.peak_mb = static_cast<double>(children.ru_maxrss) / 1024.0;  // kB on Linux
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

const char* const kBase = frictherm::test::kTinyScene;

class Limits : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = (fs::temp_directory_path() / ("frictherm_limits_" + std::to_string(getpid()) + ".json")).string();
    std::ofstream(scene_) << kBase;
  }
  void TearDown() override { fs::remove(scene_); }
  // A refusal: exit code 2, one message starting with "frictherm: SCENE: KEY", nothing large allocated:
  // every bomb here asks for terabytes, the sanitizer build's program holds about 300 MB.
  void expect_refused(const std::string& sets, const std::string& key, const std::string& detail) {
    const Result r = validate(scene_, sets);
    EXPECT_EQ(r.code, 2) << sets << "\n" << r.output;
    EXPECT_THAT(r.output, StartsWith("frictherm: " + scene_ + ": " + key)) << sets;
    EXPECT_THAT(r.output, HasSubstr(detail)) << sets;
    EXPECT_LT(r.peak_mb, 1500.0) << sets;
  }
  std::string scene_;
};

TEST_F(Limits, BaseSceneValidatesAndPrintsTheEstimate) {
  const Result r = validate(scene_, "");
  ASSERT_EQ(r.code, 0) << r.output;
  // 4 x 3 cells of block at 2 x 2 particles per cell: 48 particles, the box bound counts (4+1) x (3+1) x 4 = 80.
  EXPECT_THAT(r.output, HasSubstr("at most 80 particles, 66 grid nodes"));
}

TEST_F(Limits, ResourceBombsRefusedBeforeAllocation) {
  // 7000 x 7000 cells at 10 x 10 particles per cell: ~4.8e9 particles, ~2 TB.
  expect_refused("--set grid.hi=[7,7] --set grid.cell_size=0.001 --set 'bodies[0].shape.lo=[0,0]' "
                 "--set 'bodies[0].shape.hi=[6.9,6.9]' --set 'bodies[0].particles_per_cell=10'",
                 "bodies[0]: the scene needs about", "particles");
  // An explicit memory limit below the (small) estimate.
  expect_refused("--set run.max_memory=1e6", "bodies[0]", "the limit is 1 MB (run.max_memory)");
  // 4.9e7-node grid for 48 particles: mostly empty, refused unless run.max_memory is given.
  expect_refused("--set grid.hi=[70,70] --set grid.cell_size=0.01", "grid: 49014001 grid nodes", "nodes per particle");
  // --set growing an array to 2e8 elements.
  expect_refused("--set 'bodies[200000000]=1'", "--set bodies[200000000]", "beyond the end of an array of 1");
  // The same under a key the scene does not have (or has as null): an array made from nothing.
  expect_refused("--set 'extra[100000000]=1'", "--set extra[100000000]", "beyond the end of an array of 0");
  expect_refused("--set 'bodies[0].spin[50000000]=1'", "--set bodies[0].spin[50000000]", "beyond the end of an array of 0");
  expect_refused("--set 'extra[9999999999999999999][9]=1'", "--set extra[9999999999999999999][9]", "beyond the end");
  // A path that goes on after ']' without '.' or '[' (once read as extra[...].9).
  expect_refused("--set 'extra[9999999999999999999]9=1'", "--set extra[9999999999999999999]9",
                 "expected '.' or '[' after ']'");
}

// Contact keeps materials x materials tables (pair settings index, pair work books; per contact
// thread again): 50,000 materials had ended validate with std::bad_alloc (exit 1) and 20,000 took
// 7.9 GB (issue 34). The estimate counts them (20 B + 17 B per thread and pair): 3000 materials in
// contact need 333 MB, over a 200 MB run.max_memory, refused naming `materials` before the tables
// exist; the same materials without contact (no tables) validate.
TEST_F(Limits, MaterialPairTablesCountedBeforeAllocation) {
  std::string materials;
  for (int i = 0; i < 3000; ++i)
    materials += ", \"m" + std::to_string(i) +
                 "\": {\"type\": \"linear_elastic\", \"density\": 1000, \"youngs_modulus\": 1e6, \"poisson_ratio\": 0.3}";
  std::string scene = kBase;
  const std::string soft = "\"poisson_ratio\": 0.3}}";
  scene.insert(scene.find(soft) + soft.size() - 1, materials);
  std::ofstream(scene_) << scene;
  expect_refused("--set run.max_memory=2e8 --set contact={}", "materials: 3001 materials in contact",
                 "the limit is 200 MB (run.max_memory)");
  const Result r = validate(scene_, "--set run.max_memory=2e8");
  EXPECT_EQ(r.code, 0) << r.output;
}

TEST_F(Limits, EndlessRunsRefusedWithTheirNumbers) {
  expect_refused("--set output.snapshot_count=null --set output.snapshot_interval=1e-300", "output",
                 "2e+297 snapshots");
  expect_refused("--set output.snapshot_count=1000000", "output", "1000001 snapshots");
  expect_refused("--set solver.max_time_step=1e-300", "run.end_time", "2e+297 steps of 1e-300 s");
  expect_refused("--set run.end_time=1e300 --set 'bodies[0].velocity=[0,0]'", "run.end_time", "steps of");
  // |v| overflows: the first time step would be 0, even with max_steps bounding the run.
  expect_refused("--set 'bodies[0].velocity=[1e308,1e308]' --set run.max_steps=10", "bodies[0].velocity",
                 "the first time step would be 0 s");
  // With run.max_steps the same long run is bounded, so accepted.
  EXPECT_EQ(validate(scene_, "--set solver.max_time_step=1e-300 --set run.max_steps=5").code, 0);
}

}  // namespace
