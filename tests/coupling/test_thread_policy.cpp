// The thread governor (thread_policy.hpp): a run on the default thread count whose threads do not get
// their cores goes on with one thread and tries the full count again later. The steps here burn CPU
// on one thread only, so the process gets at most one core's worth of CPU time per second of wall
// time whatever the machine's load: below the 0.75 × 2 = 1.5 cores the governor asks of two threads.
#include <frictherm/coupling/thread_policy.hpp>

#include <gtest/gtest.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <thread>

namespace {

using frictherm::coupling::ThreadGovernor;

// A mechanics step's stand-in: `seconds` of arithmetic on the calling thread.
void busy_step(ThreadGovernor& g, std::string& note, double seconds) {
  g.step_started();
  const auto t0 = std::chrono::steady_clock::now();
  volatile double x = 1.0;
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < seconds) x = std::sqrt(x + 1.0);
  const std::string n = g.step_finished();
  if (!n.empty()) note = n;
}

TEST(ThreadGovernor, OneCoreForTwoThreadsDropsToOneThreadAndRetriesLater) {
  const int before = omp_get_max_threads();
  ThreadGovernor g(2, /*window=*/0.05, /*retry=*/0.2);
  std::string note;
  for (int i = 0; i < 8 && g.threads() == 2; ++i) busy_step(g, note, 0.01);
  ASSERT_EQ(g.threads(), 1) << "one busy thread is at most one core: below 1.5 of 2";
  EXPECT_EQ(omp_get_max_threads(), 1);  // what the next mechanics step uses
  EXPECT_NE(note.find("going on with 1 thread"), std::string::npos) << note;
  EXPECT_NE(note.find("again in 0.2 s"), std::string::npos) << note;
  EXPECT_EQ(g.changes(), 1);

  // Within the retry time it stays at one thread.
  busy_step(g, note, 0.01);
  EXPECT_EQ(g.threads(), 1);
  // After it, a step tries both threads; the window still gets one core: back to one, and the next
  // try waits twice as long.
  std::this_thread::sleep_for(std::chrono::milliseconds(250));
  g.step_started();
  EXPECT_EQ(g.threads(), 2);
  EXPECT_EQ(omp_get_max_threads(), 2);
  g.step_finished();
  note.clear();
  for (int i = 0; i < 8 && g.threads() == 2; ++i) busy_step(g, note, 0.01);
  EXPECT_EQ(g.threads(), 1);
  EXPECT_NE(note.find("again in 0.4 s"), std::string::npos) << note;
  omp_set_num_threads(before);
}

TEST(ThreadGovernor, OneThreadRunsAreLeftAlone) {
  const int before = omp_get_max_threads();
  ThreadGovernor g(1, 0.01, 0.01);
  std::string note;
  for (int i = 0; i < 5; ++i) busy_step(g, note, 0.005);
  EXPECT_EQ(g.threads(), 1);
  EXPECT_TRUE(note.empty());
  EXPECT_EQ(g.changes(), 0);
  EXPECT_EQ(omp_get_max_threads(), before);  // never touched
}

}  // namespace
