// configure_threads (app/threads.hpp): a positive count fixes the team size of every parallel region; zero
// lets OpenMP size each team from the cores the load leaves free (dynamic teams), never beyond the maximum.
#include "app/threads.hpp"

#include <gtest/gtest.h>

#include <omp.h>

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

}  // namespace
}  // namespace arcsim
