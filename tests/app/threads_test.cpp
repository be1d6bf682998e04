// configure_threads (app/threads.hpp): a positive count fixes the team size of every parallel region; zero
// lets OpenMP size each team from the cores the load leaves free (dynamic teams), never beyond the maximum,
// until a ThreadGovernor sizes them from what other processes used.
#include "app/threads.hpp"

#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>

namespace arcsim {
namespace {

// Size of the team of one parallel region.
int team_size() {
  int size = 0;
#pragma omp parallel
  {
#pragma omp single
    size = omp_get_num_threads();
  }
  return size;
}

// Restores OpenMP's settings after each test (other tests run in the same process).
class ConfigureThreads : public ::testing::Test {
 protected:
  void SetUp() override {
    dynamic_ = omp_get_dynamic();
    max_threads_ = omp_get_max_threads();
  }
  void TearDown() override {
    omp_set_dynamic(dynamic_);
    omp_set_num_threads(max_threads_);
  }

 private:
  int dynamic_ = 0, max_threads_ = 1;
};

TEST_F(ConfigureThreads, PositiveCountFixesEveryTeam) {
  for (int threads : {1, 3, 2}) {
    configure_threads(threads);
    EXPECT_EQ(omp_get_dynamic(), 0) << threads;
    EXPECT_EQ(omp_get_max_threads(), threads);
    // Fixed teams: the runtime may not shrink them, even with more threads than cores.
    for (int region = 0; region < 3; ++region) EXPECT_EQ(team_size(), threads) << "region " << region;
  }
}

TEST_F(ConfigureThreads, ZeroSelectsDynamicTeamsUpToTheMaximum) {
  configure_threads(3);
  configure_threads(0);
  EXPECT_NE(omp_get_dynamic(), 0);
  // The maximum is left as it was; each team has between one thread and that maximum.
  EXPECT_EQ(omp_get_max_threads(), 3);
  for (int region = 0; region < 3; ++region) {
    const int size = team_size();
    EXPECT_GE(size, 1);
    EXPECT_LE(size, 3);
  }
  // A later explicit count switches dynamic teams off again.
  configure_threads(2);
  EXPECT_EQ(omp_get_dynamic(), 0);
  EXPECT_EQ(team_size(), 2);
}

CpuSample sample(double machine_busy, double own, double wall) {
  CpuSample s;
  s.valid = true;
  s.machine_busy = machine_busy;
  s.own = own;
  s.wall = wall;
  return s;
}

// The team is the cores other processes left idle: their busy time is the machine's less this process's own.
TEST(CoresLeftFree, CountsOnlyOtherProcessesLoad) {
  const CpuSample start = sample(100, 10, 1000);
  // Alone on 2 cores, using both (2 s of CPU in 1 s): both stay ours.
  EXPECT_EQ(cores_left_free(start, sample(102, 12, 1001), 2), 2);
  // Alone, one thread busy: still 2 (the idle core is free).
  EXPECT_EQ(cores_left_free(start, sample(101, 11, 1001), 2), 2);
  // Another process held a whole core: 1.
  EXPECT_EQ(cores_left_free(start, sample(102, 11, 1001), 2), 1);
  // Others held both cores (we got little): never below 1.
  EXPECT_EQ(cores_left_free(start, sample(104, 10.2, 1001), 2), 1);
  // Others held 1.4 of 4 cores over 2 s: 2.6 free, rounded to 3.
  EXPECT_EQ(cores_left_free(start, sample(100 + 2.8 + 4, 14, 1002), 4), 3);
  // No counters, or no time passed: all cores.
  CpuSample unreadable = sample(0, 0, 1001);
  unreadable.valid = false;
  EXPECT_EQ(cores_left_free(start, unreadable, 2), 2);
  EXPECT_EQ(cores_left_free(start, start, 2), 2);
}

TEST(CpuSample, ReadsThisMachinesCounters) {
  const CpuSample a = sample_cpu();
  ASSERT_TRUE(a.valid);  // Linux: /proc/stat
  volatile double x = 0;
  for (int i = 0; i < 20000000; ++i) x = x + 1e-9 * i;  // burn some CPU
  const CpuSample b = sample_cpu();
  EXPECT_GE(b.wall, a.wall);
  EXPECT_GE(b.own, a.own);
  EXPECT_GE(b.machine_busy, a.machine_busy);
  const int team = cores_left_free(a, b, omp_get_num_procs());
  EXPECT_GE(team, 1);
  EXPECT_LE(team, omp_get_num_procs());
}

TEST_F(ConfigureThreads, GovernorLeavesAFixedCountAlone) {
  configure_threads(3);
  ThreadGovernor governor(3);
  EXPECT_EQ(governor.team(), 3);
  governor.frame_done();
  EXPECT_EQ(omp_get_dynamic(), 0);
  EXPECT_EQ(team_size(), 3);
}

TEST_F(ConfigureThreads, GovernorFixesTeamsItSizes) {
  configure_threads(0);
  const int cores = std::min(omp_get_num_procs(), omp_get_max_threads());
  ThreadGovernor governor(0);
  // It starts with every core (at most OpenMP's maximum, OMP_NUM_THREADS) and fixed teams; its later choices
  // stay within [1, cores].
  EXPECT_EQ(omp_get_dynamic(), 0);
  EXPECT_EQ(governor.team(), cores);
  EXPECT_EQ(team_size(), governor.team());
  governor.frame_done();
  EXPECT_GE(governor.team(), 1);
  EXPECT_LE(governor.team(), cores);
  EXPECT_EQ(team_size(), governor.team());
}

}  // namespace
}  // namespace arcsim
