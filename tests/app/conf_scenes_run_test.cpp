// Every scene shipped in conf/ runs to its end with the real binary and passes `arcsim inspect` on sampled
// frames and its last: exit 0, valid meshes, nothing non-finite, no intersecting triangles within or between
// sheets or with obstacles (issue 13, acceptance 1). Minutes in all: `make slowcheck`.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "app/app_test_support.hpp"

namespace arcsim::app_test {
namespace {

TEST(ConfScenes, SlowCheckEverySceneRunsToItsEndAndInspectsClean) {
  ARCSIM_REQUIRE_BINARY();
  const std::string demo = repo_file("conf/demo.json");
  ASSERT_FALSE(demo.empty()) << "conf/ not found";
  std::vector<fs::path> scenes;
  for (const auto& entry : fs::directory_iterator(fs::path(demo).parent_path()))
    if (entry.path().extension() == ".json") scenes.push_back(entry.path());
  std::sort(scenes.begin(), scenes.end());
  ASSERT_GE(scenes.size(), 8u);
  for (const fs::path& scene : scenes) {
    SCOPED_TRACE(scene.filename().string());
    TempFolder out;
    const auto start = std::chrono::steady_clock::now();
    const RunResult run = run_arcsim({"simulate", scene.string(), (out.path() / "run").string(), "--quiet"});
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(run.exit_code, 0) << run.err;
    const RunResult sampled = run_arcsim({"inspect", (out.path() / "run").string(), "--every", "10"});
    EXPECT_EQ(sampled.exit_code, 0) << sampled.err;
    const RunResult last = run_arcsim({"inspect", (out.path() / "run").string(), "--last"});
    EXPECT_EQ(last.exit_code, 0) << last.err;
    std::printf("[ measure ] %s: %.1f s; %s", scene.filename().string().c_str(), seconds, last.err.c_str());
  }
}

}  // namespace
}  // namespace arcsim::app_test
