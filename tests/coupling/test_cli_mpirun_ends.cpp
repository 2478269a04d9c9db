// How `mpirun -n 2 frictherm run` ends when it cannot go on (coupling/src/distributed_run/,
// coupling/app/cli_run_mpi.cpp), as the serial program ends:
//   * a block thrown out of the grid fails (exit code 1) at the serial run's step, naming its particle
//     (issue 34: status failed, every particle under /failure);
//   * a friction law that throws on one rank (an expression law turning negative) ends every rank
//     as failed, naming the pair's key and the state;
//   * Ctrl-C to mpirun stops every rank after the same step with complete, readable files.
// Skipped when mpirun is not installed. Labels verification;mpi.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_mpirun_test_support.hpp"
#include "h5_test_support.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using namespace frictherm::test;  // exe, scene, shell, Result, read_doubles, read_text, ...
constexpr auto mpirun = mpirun_command;
using CliMpirun = CliMpirunTest;

namespace {
// "step N" and "particle K" of "... failed: step N, t = ... s: particle K ..." ("" when absent).
std::string failure_point(const std::string& output) {
  const auto at = output.find("simulation failed: step ");
  if (at == std::string::npos) return "";
  const auto step_end = output.find(',', at);
  const auto particle = output.find(": particle ", step_end);
  if (step_end == std::string::npos || particle == std::string::npos) return "";
  const auto particle_end = output.find(' ', particle + 11);
  return output.substr(at + 19, step_end - at - 19) + " / " + output.substr(particle + 2, particle_end - particle - 2);
}
}  // namespace

TEST_F(CliMpirun, ParticleLeavingTheGridFailsAtTheSerialStep) {
  const std::string throw_block = " --set 'bodies[1].velocity=[400,0]'";  // leaves the 26 mm grid within 40 steps
  const Result s = shell(exe() + " run " + scene("decomposed_sliding_block.json") + throw_block + " -q -o '" +
                         path("serial.h5") + "'");
  const Result d = shell(mpirun(2) + " " + exe() + " run " + scene("decomposed_sliding_block.json") + throw_block +
                         " -q -o '" + path("split.h5") + "'");
  EXPECT_EQ(s.code, 1) << s.output;
  EXPECT_EQ(d.code, 1) << d.output;
  const std::string point = failure_point(s.output);
  EXPECT_THAT(point, HasSubstr("particle ")) << s.output;
  EXPECT_EQ(failure_point(d.output), point) << d.output;
  EXPECT_THAT(d.output, HasSubstr("left the grid"));
  EXPECT_FALSE(read_doubles(path("split.h5"), "/series/time").empty()) << "the series before the failure stay readable";
  EXPECT_EQ(read_text(path("split.h5"), "/meta/status"), "failed");  // issue 34: ended as the serial run, with /failure
  EXPECT_EQ(read_doubles(path("split.h5"), "/failure/position").size(), read_doubles(path("serial.h5"), "/failure/position").size());
}


// Issue 34: a decomposed run that fails ends as the serial run does, status failed and the failing
// state under /failure (it had kept status "running"). A friction law that throws on one rank (an
// expression law that passes the validator's sample points, v in {0, 1e-3, 1, 1e3} m/s, and turns
// negative while the block slides at 10 m/s) had left that rank's exception behind while the other
// waited in the next collective; now every rank finishes the step, agrees, and names the pair's key.
TEST_F(CliMpirun, ExpressionLawFailureEndsTheRunAsFailed) {
  const std::string law =
      " --set 'contact.pairs[0].law={\"type\":\"expression\",\"sliding_traction\":\"(v>2 && v<100) ? -0.3*N : 0.3*N\"}'"
      " --set 'contact.separation=\"position\"'";  // an expression law's default, "extent", is serial only
  const Result s = shell(exe() + " run " + scene("decomposed_sliding_block.json") + law + " -q -o '" + path("serial.h5") + "'");
  const Result d = shell(mpirun(2) + " " + exe() + " run " + scene("decomposed_sliding_block.json") + law + " -q -o '" +
                         path("split.h5") + "'");
  EXPECT_EQ(s.code, 1) << s.output;
  EXPECT_EQ(d.code, 1) << d.output;
  EXPECT_THAT(d.output, HasSubstr("contact.pairs[0].law (materials 'base' and 'block')"));
  EXPECT_THAT(d.output, HasSubstr("returned S = -"));
  EXPECT_EQ(read_text(path("split.h5"), "/meta/status"), "failed");
  EXPECT_FALSE(read_doubles(path("split.h5"), "/failure/position").empty()) << "the failing state under /failure";
  EXPECT_EQ(read_doubles(path("split.h5"), "/failure/position").size(),
            read_doubles(path("serial.h5"), "/failure/position").size()) << "every particle, once";
  EXPECT_FALSE(read_doubles(path("split.h5"), "/series/time").empty());
}

TEST_F(CliMpirun, InterruptedRunStopsEveryRankAndKeepsItsFiles) {
  // Ctrl-C to mpirun once the run writes (Open MPI's mpirun passes it on to the ranks as SIGTERM):
  // every rank stops after the same step, the files are complete and readable, rank 0 says so.
  const std::string out = path("x.h5");
  const std::string cmd = mpirun(2) + " " + exe() + " run " + scene("decomposed_sliding_block.json") +
                          " -q --set run.end_time=1 -o '" + out + "' > '" + path("log") + "' 2>&1 & pid=$!; " +
                          "for i in $(seq 1 600); do ls '" + out + "'.*.part >/dev/null 2>&1 && break; sleep 0.1; done; " +
                          "sleep 0.5; kill -INT $pid; wait $pid";
  const Result r = shell(cmd);
  std::ifstream in(path("log"));
  std::stringstream log;
  log << in.rdbuf();
  EXPECT_NE(r.code, 0) << log.str();
  EXPECT_THAT(log.str(), HasSubstr("interrupted by SIG"));
  EXPECT_THAT(log.str(), HasSubstr("/meta/status = interrupted"));
  const std::vector<double> t = read_doubles(out, "/series/time");
  ASSERT_FALSE(t.empty()) << "the series file is renamed into place and readable";
  EXPECT_LT(t.back(), 1.0) << "stopped before end_time";
  // The last snapshot is at the interruption, on the ranks that hold particles, listed in the XDMF file.
  std::ifstream xdmf(path("x.xdmf"));
  std::stringstream text;
  text << xdmf.rdbuf();
  EXPECT_THAT(text.str(), HasSubstr("x.rank0.h5:/snapshots/000001/position"));
  EXPECT_FALSE(read_doubles(path("x.rank0.h5"), "/snapshots/000001/id").empty() &&
               read_doubles(path("x.rank1.h5"), "/snapshots/000001/id").empty());
  const Result csv = shell(exe() + " export-csv '" + out + "'");
  EXPECT_EQ(csv.code, 0) << csv.output;
}
