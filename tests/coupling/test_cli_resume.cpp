// `frictherm resume` (coupling/app/cli_resume.cpp): examples/sliding_block.json interrupted by SIGINT
// while running on one thread and resumed ends in the same state as an uninterrupted run: the two
// final checkpoints (every particle array, time, step count, work books, output marks) are byte-equal
// files, and the resumed result, appended to the interrupted one, has the uninterrupted run's series
// row for row (export-csv prints the same text) and XDMF files (RUN.xdmf, RUN_reference.xdmf) listing
// the same grids.
#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/results.hpp>
#include <frictherm/coupling/xdmf.hpp>

#include <gtest/gtest.h>

#include "result_compare_support.hpp"

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

using frictherm::test::expect_same_xdmf;
using frictherm::test::slurp;

TEST(CliResume, InterruptedAndResumedRunEqualsUninterruptedRun) {
  const fs::path dir = fs::temp_directory_path() / ("frictherm_resume_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = std::string(FRICTHERM_SOURCE_DIR) + "/examples/sliding_block.json";
  const std::string part = (dir / "part.h5").string(), full = (dir / "full.h5").string();
  const pid_t pid = fork();
  if (pid == 0) {
    std::freopen((dir / "stderr.txt").c_str(), "w", stderr);
    execl(FRICTHERM_EXE, FRICTHERM_EXE, "run", scene.c_str(), "-o", part.c_str(), "--quiet", "--set",
          "run.threads=1", "--set", "run.checkpoint_interval=0.01", static_cast<char*>(nullptr));
    _exit(127);
  }
  const std::string live = part + "." + std::to_string(pid) + ".part";  // the output while it runs
  for (int i = 0; i < 200 && !fs::exists(live); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(25));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  if (WEXITSTATUS(status) == 0) GTEST_SKIP() << "the run ended before the signal arrived";
  ASSERT_EQ(WEXITSTATUS(status), 128 + SIGINT) << slurp(dir / "stderr.txt");
  ASSERT_TRUE(fs::exists(part + ".checkpoint")) << "SIGINT must leave a checkpoint";

  const std::string exe = FRICTHERM_EXE;
  const std::string at_interruption = slurp(part + ".checkpoint");
  ASSERT_EQ(std::system((exe + " resume " + part + " -t 1 --quiet").c_str()), 0);
  ASSERT_EQ(std::system((exe + " run " + scene + " -o " + full +
                         " --quiet --set run.threads=1 --set run.checkpoint_interval=0.01").c_str()),
            0);
  std::string resumed = slurp(part + ".checkpoint"), uninterrupted = slurp(full + ".checkpoint");
  // The two results are different runs (/meta/run_id, also in their checkpoints): the same state
  // otherwise, byte for byte. /marks/run_id is stored as one chunk, the id followed by its 4-byte
  // Fletcher32 checksum (checkpoint format 3), which differs with the id.
  for (auto [text, file] : {std::pair<std::string*, std::string>{&resumed, part}, {&uninterrupted, full}}) {
    const std::string id = frictherm::coupling::checkpoint_marks(file + ".checkpoint").run_id;
    ASSERT_EQ(id.size(), 32u);
    for (std::size_t at = text->find(id); at != std::string::npos; at = text->find(id, at + 1))
      text->replace(at, std::min(id.size() + 4, text->size() - at), std::string(std::min(id.size() + 4, text->size() - at), '-'));
  }
  ASSERT_FALSE(uninterrupted.empty());
  EXPECT_TRUE(resumed == uninterrupted) << "the resumed run's final checkpoint differs from the uninterrupted run's";
  EXPECT_FALSE(at_interruption == uninterrupted) << "the interruption must come before the end";
  const std::string csv_part = (dir / "part.csv").string(), csv_full = (dir / "full.csv").string();
  ASSERT_EQ(std::system((exe + " export-csv " + part + " -o " + csv_part).c_str()), 0);
  ASSERT_EQ(std::system((exe + " export-csv " + full + " -o " + csv_full).c_str()), 0);
  const std::string a = slurp(csv_part), b = slurp(csv_full);
  EXPECT_GT(std::count(b.begin(), b.end(), '\n'), 100);
  EXPECT_TRUE(a == b) << "the appended result's series differ from the uninterrupted run's";
  // The joined result ended as the resumed part did: completed, the interruption note gone.
  EXPECT_EQ(frictherm::coupling::read_metadata_string(part, "status"), "completed");
  EXPECT_THROW(frictherm::coupling::read_metadata_string(part, "interruption"), std::runtime_error);
  expect_same_xdmf(part, full, false);
  fs::remove_all(dir);
}

}  // namespace
