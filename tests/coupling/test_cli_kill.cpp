// A run killed with SIGKILL while it writes checkpoints keeps a usable one (issue 17): the sliding
// block checkpointing every 10 us of simulated time (every few steps, so writes take much of the
// wall time) is killed at random moments; each time, the checkpoint left beside the lost result
// restores into a simulation rebuilt from its stored scene. The stale per-process temporaries the
// kills leave (kills during a write) are counted: at least one kill must have hit a write.
#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/scene.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <random>
#include <string>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace frictherm;

TEST(KillDuringCheckpointWrite, ThePreviousCheckpointStaysUsable) {
  const fs::path dir = fs::temp_directory_path() / ("frictherm_kill_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = std::string(FRICTHERM_SOURCE_DIR) + "/examples/sliding_block.json";
  const std::string out = (dir / "run.h5").string(), cp = coupling::checkpoint_path(out);
  std::mt19937 rng(17);
  int hit_writes = 0;
  long last_step = -1;
  // At least 8 kills, and more (up to 40) until one has landed inside a checkpoint write: the share
  // of the run spent writing depends on the machine's speed and load, not on the code under test.
  for (int trial = 0; trial < 40 && (trial < 8 || hit_writes == 0); ++trial) {
    const pid_t pid = fork();
    if (pid == 0) {
      std::freopen("/dev/null", "w", stderr);
      execl(FRICTHERM_EXE, FRICTHERM_EXE, "run", scene.c_str(), "-o", out.c_str(), "--quiet", "--force", "--set",
            "run.threads=1", "--set", "run.checkpoint_interval=1e-5", static_cast<char*>(nullptr));
      _exit(127);
    }
    // Wait for the first checkpoint, then kill at a random moment.
    for (int i = 0; i < 400 && !fs::exists(cp); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(5, 200)(rng)));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the run must still be running when killed";
    ASSERT_TRUE(fs::exists(cp));
    const std::string tmp = cp + "." + std::to_string(pid) + ".tmp";
    if (fs::exists(tmp)) {
      ++hit_writes;
      fs::remove(tmp);
    }
    auto sim = coupling::build_simulation<2>(coupling::checkpoint_scene(cp));
    ASSERT_NO_THROW(coupling::read_mechanics_checkpoint(cp, *sim)) << "trial " << trial;
    EXPECT_GT(sim->step_count(), 0);
    EXPECT_GE(sim->time(), 1e-5 * (1 - 1e-9));
    last_step = sim->step_count();
    for (const auto& e : fs::directory_iterator(dir))  // the lost result of the killed run
      if (e.path().string().find(".part") != std::string::npos) fs::remove(e.path());
    fs::remove(cp);
  }
  EXPECT_GT(last_step, 0);
  EXPECT_GE(hit_writes, 1) << "no kill landed inside a checkpoint write";
  fs::remove_all(dir);
}
