// Files never lost (issue 15, output_files.hpp): an existing result is refused unless --force or
// output.overwrite; the scene and other inputs are never written over; a result is written under a
// temporary name and renamed when complete, so two runs writing one file both leave readable files.
#include <frictherm/coupling/h5_output.hpp>

#include "cli_test_support.hpp"
#include "h5_test_support.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using frictherm::test::Result;
using frictherm::test::shell;

namespace {

Result frictherm(const std::string& args) { return shell(std::string("'") + FRICTHERM_EXE + "' " + args); }

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The run's /meta/status, or "" when the file does not open as HDF5.
std::string status_of(const std::string& h5) {
  const hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return "";
  std::string s;
  const hid_t d = H5Dopen2(f, "/meta/status", H5P_DEFAULT);
  if (d >= 0) {
    const hid_t t = H5Dget_type(d);
    s.resize(H5Tget_size(t));
    H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.data());
    s.resize(s.find('\0') == std::string::npos ? s.size() : s.find('\0'));
    H5Tclose(t);
    H5Dclose(d);
  }
  H5Fclose(f);
  return s;
}

class Files : public frictherm::test::ScratchDirTest {
 protected:
  Files() : ScratchDirTest("frictherm_files_") {}
};

using frictherm::test::kTinyScene;

TEST_F(Files, ExistingResultRefusedUnlessForcedOrOverwriteKey) {
  const std::string scene = write("tiny.json", kTinyScene), out = path("run.h5");
  ASSERT_EQ(frictherm("run " + scene + " -o " + out + " --quiet").code, 0);
  const std::string first = slurp(out);
  ASSERT_EQ(status_of(out), "completed");

  const Result again = frictherm("run " + scene + " -o " + out + " --quiet");
  EXPECT_EQ(again.code, 2) << again.output;
  EXPECT_THAT(again.output, HasSubstr("exists"));
  EXPECT_THAT(again.output, HasSubstr("--force"));
  EXPECT_TRUE(slurp(out) == first) << "a refused run must not touch the existing result";

  const Result forced = frictherm("run " + scene + " -o " + out + " --quiet --force");
  EXPECT_EQ(forced.code, 0) << forced.output;
  EXPECT_EQ(status_of(out), "completed");
  const Result by_key = frictherm("run " + scene + " -o " + out + " --quiet --set output.overwrite=true");
  EXPECT_EQ(by_key.code, 0) << by_key.output;
  EXPECT_EQ(status_of(out), "completed");
  // Nothing left behind under temporary names.
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_NE(e.path().extension(), ".part") << e.path();
}

TEST_F(Files, InputsAreNeverWrittenOverEvenWithForce) {
  const std::string scene = write("tiny.json", kTinyScene);
  for (const std::string force : {"", " --force"}) {
    const Result r = frictherm("run " + scene + " -o " + scene + " --quiet" + force);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr("input of this run"));
    EXPECT_EQ(slurp(scene), kTinyScene);
  }
  // The same file under another spelling (a symbolic link) is the same input.
  fs::create_symlink(scene, path("link.json"));
  const Result via_link = frictherm("run " + scene + " -o " + path("link.json") + " --quiet --force");
  EXPECT_EQ(via_link.code, 2) << via_link.output;
  EXPECT_EQ(slurp(scene), kTinyScene);

  // export-csv never writes over the run it reads.
  ASSERT_EQ(frictherm("run " + scene + " -o " + path("run.h5") + " --quiet").code, 0);
  const std::string run = slurp(path("run.h5"));
  const Result csv = frictherm("export-csv " + path("run.h5") + " -o " + path("run.h5") + " --force");
  EXPECT_EQ(csv.code, 2) << csv.output;
  EXPECT_TRUE(slurp(path("run.h5")) == run);
  EXPECT_EQ(status_of(path("run.h5")), "completed");
  // An existing CSV is replaced only with --force.
  ASSERT_EQ(frictherm("export-csv " + path("run.h5") + " -o " + path("s.csv")).code, 0);
  EXPECT_EQ(frictherm("export-csv " + path("run.h5") + " -o " + path("s.csv")).code, 2);
  EXPECT_EQ(frictherm("export-csv " + path("run.h5") + " -o " + path("s.csv") + " --force").code, 0);
}

// A run's checkpoint and XDMF files belong to it (issue 34): export-csv, continue and resume never
// write over them, nor over the result itself under another spelling (./run.h5, a symbolic link), nor
// over any run's checkpoint, whatever its name; export-csv (a CSV) replaces no HDF5 file at all
// (another run's result, found by its content). --force changes none of that, and every file is
// byte-equal after the refusal. Before (a47c20f), `export-csv R.h5 -o R.h5.checkpoint --force`
// replaced the checkpoint with the CSV (exit 0), and so did every case below but the first.
TEST_F(Files, ResultCheckpointAndXdmfAreNeverOutputsOfTheCommandsReadingThem) {
  const std::string scene = write("tiny.json", kTinyScene), run = path("run.h5"), other = path("other.h5");
  const std::string every = " --quiet --set run.checkpoint_interval=1e-3";
  ASSERT_EQ(frictherm("run " + scene + " -o " + run + every).code, 0);
  ASSERT_EQ(frictherm("run " + scene + " -o " + other + every).code, 0);
  fs::create_symlink(run, path("link.h5"));
  fs::copy_file(other + ".checkpoint", path("renamed.bin"));  // a checkpoint under a name that does not say so
  const std::vector<std::string> kept = {run, run + ".checkpoint", path("run.xdmf"), other, other + ".checkpoint",
                                         path("other.xdmf"), path("renamed.bin")};
  std::vector<std::string> before;
  for (const std::string& f : kept) before.push_back(slurp(f));
  ASSERT_GT(before[1].size(), 1000u) << "the setup run wrote a checkpoint";
  struct Case {
    std::string command, output, why;
  };
  const std::vector<Case> cases = {
      {"export-csv " + run, run + ".checkpoint", "it is the checkpoint of"},
      {"export-csv " + run, dir_.string() + "/./run.h5", "it is the input of"},
      {"export-csv " + path("link.h5"), run, "it is the input of"},
      {"export-csv " + path("link.h5"), run + ".checkpoint", "it is the checkpoint of"},
      {"export-csv " + run, path("run.xdmf"), "it is the XDMF file of"},
      {"export-csv " + run, other, "it is a result of frictherm"},
      {"export-csv " + run, other + ".checkpoint", "it is a checkpoint of frictherm"},
      {"export-csv " + run, path("renamed.bin"), "it is a checkpoint of frictherm"},
      {"continue " + run, run + ".checkpoint", "it is the checkpoint of"},
      {"continue " + run, path("run.xdmf"), "it is the XDMF file of"},
      {"continue " + run, other + ".checkpoint", "it is a checkpoint of frictherm"},
      {"resume " + run, path("run.xdmf"), "it is the XDMF file of"},
      {"resume " + run, path("renamed.bin"), "it is a checkpoint of frictherm"},
  };
  for (const Case& c : cases) {
    const bool csv = c.command.rfind("export-csv", 0) == 0;  // export-csv has no --quiet
    const Result r = frictherm(c.command + " -o '" + c.output + "' --force" + (csv ? "" : " --quiet"));
    EXPECT_EQ(r.code, 2) << c.command << " -o " << c.output << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr("refusing to write '" + c.output + "': " + c.why)) << c.command;
    EXPECT_THAT(r.output, HasSubstr("--force or not")) << c.command;
    for (std::size_t k = 0; k < kept.size(); ++k)
      EXPECT_TRUE(slurp(kept[k]) == before[k]) << kept[k] << " changed by " << c.command << " -o " << c.output;
  }
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_NE(e.path().extension(), ".part") << e.path();
  // What is not the input's and holds no HDF5 is written as before: a new CSV, an existing one with --force.
  EXPECT_EQ(frictherm("export-csv " + path("link.h5") + " -o " + path("s.csv")).code, 0);
  EXPECT_EQ(frictherm("export-csv " + run + " -o " + path("s.csv") + " --force").code, 0);
  EXPECT_THAT(slurp(path("s.csv")), HasSubstr("time"));
  // resume onto another run's result with --force replaces it, as run --force does.
  const Result onto = frictherm("resume " + run + " -o " + other + " --force --quiet");
  EXPECT_EQ(onto.code, 0) << onto.output;
  EXPECT_EQ(status_of(other), "completed");
}

// A result is published by renaming over its name, which would turn a device or a pipe (-o /dev/null
// as root) into a regular file: such a name is refused even with --force, and left as it was. A named
// pipe in the scratch folder stands for them (the test must not risk /dev/null).
TEST_F(Files, SpecialFilesAreNeverReplacedEvenWithForce) {
  const std::string scene = write("tiny.json", kTinyScene);
  const std::string pipe = path("pipe.h5");
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  const Result r = frictherm("run " + scene + " -o " + pipe + " --quiet --force");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("it is a named pipe, not a regular file"));
  EXPECT_TRUE(fs::is_fifo(pipe));
  ASSERT_EQ(frictherm("run " + scene + " -o " + path("run.h5") + " --quiet").code, 0);
  const Result csv = frictherm("export-csv " + path("run.h5") + " -o " + pipe + " --force");
  EXPECT_EQ(csv.code, 2) << csv.output;
  EXPECT_TRUE(fs::is_fifo(pipe));
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_NE(e.path().extension(), ".part") << e.path();
}

// Damaged inputs of resume, continue and export-csv (a truncated checkpoint, a truncated result) are
// refused before any work as bad input, exit code 2, naming the file; nothing is left behind and the
// damaged files are not touched.
TEST_F(Files, DamagedCheckpointOrResultIsRefusedBeforeAnyWork) {
  const std::string scene = write("tiny.json", kTinyScene), run = path("run.h5");
  ASSERT_EQ(frictherm("run " + scene + " -o " + run + " --quiet --set run.checkpoint_interval=1e-3").code, 0);
  const std::string checkpoint = slurp(run + ".checkpoint"), result = slurp(run);
  ASSERT_GT(checkpoint.size(), 1000u);
  auto write_bytes = [](const std::string& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; };
  auto no_leftovers = [&] {
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string name = e.path().filename().string();
      EXPECT_EQ(name.find(".part"), std::string::npos) << name;
      EXPECT_EQ(name.find(".continuation"), std::string::npos) << name;
      EXPECT_FALSE(name.rfind("out", 0) == 0) << name;
    }
  };
  for (const std::string& cut : {checkpoint.substr(0, checkpoint.size() / 2), std::string()}) {
    write_bytes(run + ".checkpoint", cut);
    for (const std::string command : {"resume", "continue"}) {
      const Result r = frictherm(command + " " + run + " -o " + path("out.h5") + " --quiet");
      EXPECT_EQ(r.code, 2) << command << ": " << r.output;
      EXPECT_THAT(r.output, HasSubstr("not a readable checkpoint")) << command;
    }
    EXPECT_TRUE(slurp(run + ".checkpoint") == cut);
    no_leftovers();
  }
  write_bytes(run + ".checkpoint", checkpoint);
  write_bytes(run, result.substr(0, result.size() / 3));
  const Result r = frictherm("resume " + run + " -o " + path("out.h5") + " --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("could not be appended"));
  const Result csv = frictherm("export-csv " + run + " -o " + path("out.csv"));
  EXPECT_EQ(csv.code, 2) << csv.output;
  EXPECT_TRUE(slurp(run) == result.substr(0, result.size() / 3));
  no_leftovers();
  // The intact pair still resumes.
  write_bytes(run, result);
  EXPECT_EQ(frictherm("resume " + run + " -o " + path("resumed.h5") + " --quiet").code, 0);
}

// A write that fails mid-run (a full disk; here the file-size limit RLIMIT_FSIZE, whose writes fail
// with EFBIG as a full disk's do with ENOSPC) ends the run with exit code 1 and the system's reason,
// not a crash: HDF5 1.10's clean-up at exit segfaulted on the file whose close had failed (exit code
// 139) after dumping its error stack. The partial result stays under its temporary name.
TEST_F(Files, FailedWriteEndsTheRunWithAMessageNotACrash) {
  const std::string scene = std::string(FRICTHERM_SOURCE_DIR) + "/examples/sliding_block.json";
  const std::string out = path("run.h5"), log = path("stderr.txt");
  const pid_t pid = fork();
  if (pid == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // the write fails instead of the signal killing the process
    const rlimit limit{200 * 1024, 200 * 1024};
    setrlimit(RLIMIT_FSIZE, &limit);
    std::freopen(log.c_str(), "w", stderr);
    execl(FRICTHERM_EXE, FRICTHERM_EXE, "run", scene.c_str(), "-o", out.c_str(), "--quiet", "--set", "run.threads=1",
          "--set", "run.end_time=2e-3", static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  const std::string message = slurp(log);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0) << "\n" << message;
  EXPECT_EQ(WEXITSTATUS(status), 1) << message;
  EXPECT_THAT(message, HasSubstr("File too large"));
  EXPECT_EQ(message.find("HDF5-DIAG"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(out));
  bool partial = false;
  for (const auto& e : fs::directory_iterator(dir_)) partial = partial || e.path().extension() == ".part";
  EXPECT_TRUE(partial) << "the partial result is kept under its temporary name";
}

// Two runs started together on one output file: the first to finish publishes it; the second finds
// the name taken and keeps its own result under its temporary name (exit code 2, saying where).
// Both files are complete, readable results; nothing is truncated.
TEST_F(Files, TwoWritersOfOneFileBothKeepReadableResults) {
  std::string scene_text = kTinyScene;
  scene_text.replace(scene_text.find("2e-3"), 4, "4e-2");  // ~0.5 s each: the two runs overlap
  const std::string scene = write("tiny.json", scene_text), out = path("same.h5");
  pid_t pids[2];
  for (int k = 0; k < 2; ++k) {
    pids[k] = fork();
    if (pids[k] == 0) {
      std::freopen(path("stderr" + std::to_string(k) + ".txt").c_str(), "w", stderr);
      execl(FRICTHERM_EXE, FRICTHERM_EXE, "run", scene.c_str(), "-o", out.c_str(), "--quiet", static_cast<char*>(nullptr));
      _exit(127);
    }
  }
  int codes[2];
  for (int k = 0; k < 2; ++k) {
    int status = 0;
    waitpid(pids[k], &status, 0);
    codes[k] = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  EXPECT_EQ(status_of(out), "completed");
  int published = 0;
  for (int k = 0; k < 2; ++k) {
    const std::string live = out + "." + std::to_string(pids[k]) + ".part";
    if (codes[k] == 0) {
      ++published;
      EXPECT_FALSE(fs::exists(live));
    } else {
      const std::string err = slurp(path("stderr" + std::to_string(k) + ".txt"));
      EXPECT_EQ(codes[k], 2) << err;
      if (err.find("refusing to replace an existing result") != std::string::npos ||
          err.find("is being written by another run") != std::string::npos) {
        // It started while the other held the output's claim, or after it had published: refused
        // before any step, nothing of its own written, the other's file untouched.
        EXPECT_FALSE(fs::exists(live)) << err;
      } else {
        // Both ran at once: the later one keeps its result under its own name.
        EXPECT_THAT(err, HasSubstr(live));
        EXPECT_EQ(status_of(live), "completed");
      }
    }
  }
  EXPECT_GE(published, 1);
}

// The output is claimed (flock on OUT.h5.lock) before anything is built or written (issue 34 item 3:
// a second run a second after the first had replaced the first's XDMF and checkpoint before it was
// refused at publication). The test holds the claim itself, as a running first run would, so nothing
// depends on timing: the second run must be refused with exit code 2 (with --force: by the claim), leaving every
// file of the folder byte-equal and adding none. Once the claim is let go (the lock file stays
// behind, as after a killed run) the same command runs, and removes the lock file at its end.
// (The first version of this test waited up to 10 s for a first run's .part file; on a loaded machine
// that wait ran out, the ASSERT returned without killing the first run, and ctest then waited for that
// orphan, which held the test's output pipe, until its time limit: 357 s.)
TEST_F(Files, SecondRunOnAClaimedOutputIsRefusedBeforeWriting) {
  const std::string scene = write("tiny.json", kTinyScene), out = path("same.h5");
  ASSERT_EQ(frictherm("run " + scene + " -o " + out + " --quiet --set run.checkpoint_interval=1e-3").code, 0);
  auto files = [&] {
    std::vector<std::pair<std::string, std::string>> all;
    for (const auto& e : fs::directory_iterator(dir_)) all.emplace_back(e.path().filename().string(), slurp(e.path().string()));
    std::sort(all.begin(), all.end());
    return all;
  };
  const int fd = ::open((out + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  const auto before = files();
  ASSERT_EQ(before.size(), 6u);  // tiny.json, same.h5, same.xdmf, same_reference.xdmf, same.h5.checkpoint, same.h5.lock
  // Without --force the existing result is refused first; with it, the claim refuses the run.
  for (const std::string force : {"", " --force"}) {
    const Result r = frictherm("run " + scene + " -o " + out + " --quiet" + force);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr(force.empty() ? "exists; refusing to replace" : "is being written by another run"));
    EXPECT_TRUE(files() == before) << "the refused run changed or added a file";
  }
  ::close(fd);  // let go; the lock file stays, claiming nothing
  const Result after = frictherm("run " + scene + " -o " + out + " --quiet --force");
  EXPECT_EQ(after.code, 0) << after.output;
  EXPECT_EQ(status_of(out), "completed");
  EXPECT_FALSE(fs::exists(out + ".lock")) << "the claim is released with the run";
}

// The library level of the same: a file that appears under the final name while an H5Output writes
// under its temporary name is left alone, and the output stays readable under the temporary name.
TEST_F(Files, TemporaryOutputNeverReplacesAFileThatAppearedMeanwhile) {
  using frictherm::coupling::H5Output;
  using frictherm::coupling::H5OutputOptions;
  const std::string out = path("r.h5");
  H5OutputOptions o;
  o.via_temporary = true;
  o.replace_existing = false;
  H5Output w(out, 2, o);
  EXPECT_EQ(w.path(), out);
  EXPECT_NE(w.live_path(), out);
  EXPECT_EQ(fs::path(w.live_path()).parent_path(), dir_);
  w.write_metadata("status", "completed");
  write("r.h5", "someone else's result");
  const std::string live = w.live_path();
  EXPECT_THROW(w.close(), std::runtime_error);
  EXPECT_EQ(slurp(out), "someone else's result");
  EXPECT_EQ(status_of(live), "completed");

  H5OutputOptions replace = o;
  replace.replace_existing = true;
  H5Output v(out, 2, replace);
  v.write_metadata("status", "completed");
  v.close();
  EXPECT_EQ(status_of(out), "completed");
  EXPECT_FALSE(fs::exists(v.live_path()));
}

}  // namespace
