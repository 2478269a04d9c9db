// A decomposed run's result and its checkpoint belong together (issue 34 item 3; docs/robustness.md,
// docs/checkpoints.md "Decomposed runs"; coupling/src/distributed_run/decomposed_runner.cpp,
// coupling/app/cli_run_mpi.cpp): every result of `mpirun -n 2 frictherm run` carries a fresh
// /meta/run_id and every checkpoint it writes the same id in /marks/run_id, as the serial run's; a
// resume is refused (exit code 2, naming both runs) when the checkpoint beside the result is another
// run's — a later run on the same output that did not finish, or files of two runs put together —
// and the result, its XDMF, its rank files and the checkpoint are left byte for byte as they were.
// On 79aaa40 the decomposed checkpoint's /marks/run_id was empty and the resume went on, rewriting
// the result with the other run's series rows (exit code 0).
// Skipped when mpirun is not installed. Labels verification;mpi.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_mpirun_test_support.hpp"
#include "h5_test_support.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using namespace frictherm::test;  // exe, scene, shell, Result, read_doubles, read_text, ...

namespace {


class CliMpirunRunId : public frictherm::test::MpirunScratchTest {
 protected:
  CliMpirunRunId() : MpirunScratchTest("frictherm_mpirun_run_id_") {}

  // The sliding block for 0.2 ms (~70 steps) with a checkpoint every 0.1 ms, into `name`.
  Result run(const std::string& name) const {
    return shell(frictherm::test::mpirun_command(2) + " " + exe() + " run " +
                 frictherm::test::scene("decomposed_sliding_block.json") + " -q --set run.end_time=2e-4" +
                 " --set run.checkpoint_interval=1e-4 -o '" + path(name) + "'");
  }

  std::map<std::string, std::string> contents() const {  // every file of the folder, by name
    std::map<std::string, std::string> all;
    for (const auto& e : fs::directory_iterator(dir_)) {
      std::ifstream in(e.path(), std::ios::binary);
      std::stringstream text;
      text << in.rdbuf();
      all[e.path().filename().string()] = text.str();
    }
    return all;
  }
};

}  // namespace

TEST_F(CliMpirunRunId, ResumeRefusesTheCheckpointOfAnotherRun) {
  const Result a = run("a.h5"), b = run("b.h5");
  ASSERT_EQ(a.code, 0) << a.output;
  ASSERT_EQ(b.code, 0) << b.output;
  const std::string id_a = read_text(path("a.h5"), "/meta/run_id"), id_b = read_text(path("b.h5"), "/meta/run_id");
  EXPECT_EQ(id_a.size(), 32u) << "128 random bits in hex";
  EXPECT_NE(id_a, id_b);
  EXPECT_EQ(read_text(path("a.h5.checkpoint"), "/marks/run_id"), id_a) << "the checkpoint names its result";
  EXPECT_EQ(read_text(path("b.h5.checkpoint"), "/marks/run_id"), id_b);

  // b's checkpoint (the global file and its rank files) put beside a's result in place of a's own.
  for (const auto& e : fs::directory_iterator(dir_)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("a.h5.checkpoint", 0) == 0) fs::remove(e.path());
  }
  for (const auto& e : fs::directory_iterator(dir_)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("b.h5.checkpoint", 0) == 0) fs::copy_file(e.path(), path("a" + name.substr(1)));
  }
  const std::map<std::string, std::string> before = contents();
  const Result r = shell(frictherm::test::mpirun_command(2) + " " + exe() + " resume '" + path("a.h5") + "'");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("is the result of run " + id_a + ", the checkpoint belongs to run " + id_b));
  const std::map<std::string, std::string> after = contents();
  EXPECT_EQ(after.size(), before.size()) << "no file added or removed";
  for (const auto& [name, bytes] : before) {
    const auto it = after.find(name);
    EXPECT_TRUE(it != after.end() && it->second == bytes) << name << " changed";
  }
}
