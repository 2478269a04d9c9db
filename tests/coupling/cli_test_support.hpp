#pragma once
// Shared by the tests of the frictherm program (test_cli*.cpp, test_cli_mpi.cpp, test_cli_mpirun.cpp):
// a shell command's exit code and everything it printed, a fresh folder per test, and a small scene.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include <sys/wait.h>
#include <unistd.h>

namespace frictherm::test {

struct Result {
  int code = -1;       // the exit code; -1 when the command could not start or ended by a signal
  std::string output;  // stdout and stderr together
};

/// Runs `cmd` with /bin/sh, its stderr joined to its stdout.
inline Result shell(const std::string& cmd) {
  Result r;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

/// `mpirun` with `ranks` processes on any machine (oversubscribed: 4 ranks on 2 cores; as root Open
/// MPI wants --allow-run-as-root), one OpenMP thread each, waiting ranks yielding their core (Open MPI
/// polls busily unless it counts more ranks than slots, and other processes may hold the cores), over
/// the single-node transports (FRICTHERM_MPI_TEST_ENVIRONMENT in tests/CMakeLists.txt says why).
inline std::string mpirun_command(int ranks) {
  std::string cmd = "env OMP_NUM_THREADS=1 OMPI_MCA_mpi_yield_when_idle=1 OMPI_MCA_pml=ob1 OMPI_MCA_btl=self,vader"
                    " mpirun --oversubscribe -n " + std::to_string(ranks);
  if (geteuid() == 0) cmd += " --allow-run-as-root";
  return cmd;
}

/// A fixture with a fresh folder per test, <temp>/<prefix><test name>_<pid> (tests may run in
/// parallel), removed after the test.
class ScratchDirTest : public ::testing::Test {
 protected:
  explicit ScratchDirTest(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() / (prefix_ + info->name() + "_" + std::to_string(getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  /// Writes `text` to the file `name` of the folder; returns its path.
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }
  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

/// A scratch folder per test for tests that launch mpirun; skipped where mpirun is not installed.
class MpirunScratchTest : public ScratchDirTest {
 protected:
  using ScratchDirTest::ScratchDirTest;
  void SetUp() override {
    if (shell("command -v mpirun").code != 0) GTEST_SKIP() << "mpirun is not installed (Debian: openmpi-bin)";
    ScratchDirTest::SetUp();
  }
};

/// The program tests' small scene: a block moving at 1 m/s, a few dozen steps, four snapshots.
inline constexpr const char* kTinyScene = R"({
  "dimension": 2,
  "grid": {"lo": [0, 0], "hi": [0.1, 0.05], "cell_size": 0.01},
  "materials": {"soft": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.3}},
  "bodies": [{"name": "block", "material": "soft", "velocity": [1, 0],
              "shape": {"type": "rectangle", "lo": [0.02, 0.01], "hi": [0.06, 0.04]}}],
  "run": {"end_time": 2e-3, "threads": 1},
  "output": {"snapshot_count": 4}
})";

}  // namespace frictherm::test
