// The output guard: nothing non-finite ever reaches the disk. A NaN injected into the state (in a field the step
// reads and in fields it does not) stops the run with a NumericalError (exit 3 in the command line), the frame
// is not written, and every file that is on disk holds only finite numbers.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <limits>
#include <sstream>
#include <string>

#include "app/console.hpp"
#include "app/output.hpp"
#include "app/output_files.hpp"
#include "app/simulate_command.hpp"
#include "app_test_support.hpp"
#include "io/obj.hpp"
#include "io/scene_parser.hpp"
#include "io/state.hpp"
#include "math/errors.hpp"
#include "sim/simulation.hpp"

namespace arcsim::app_test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A hanging sheet with a frame 0 and a frame 1 written, as `arcsim simulate` leaves them.
struct GuardedRun {
  TempFolder dir;
  std::unique_ptr<Simulation> sim;
  std::unique_ptr<OutputFolder> out;

  GuardedRun() {
    dir.write("sheet.obj", tiny_sheet_obj());
    const std::string scene = dir.write("scene.json", tiny_scene("sheet.obj"));
    sim = std::make_unique<Simulation>(load_scene(scene));
    sim->set_end_frame(3);
    out = std::make_unique<OutputFolder>(dir / "out");
    out->write_frame(*sim);
    sim->advance_frame();
    out->write_frame(*sim);
  }

  std::string frame_file(int frame) const { return dir / ("out/" + cloth_frame_file_name(frame, 0)); }
  std::string state_file(int frame) const { return dir / ("out/" + state_file_name(frame)); }

  // Every frame on disk reads back (the readers refuse non-finite numbers) and has no nan/inf text.
  void expect_frames_on_disk_finite(int last_frame) const {
    for (int f = 0; f <= last_frame; ++f) {
      SCOPED_TRACE("frame " + std::to_string(f));
      ASSERT_TRUE(fs::exists(frame_file(f)));
      ASSERT_TRUE(fs::exists(state_file(f)));
      const std::string text = read_text(frame_file(f));
      EXPECT_EQ(text.find("nan"), std::string::npos);
      EXPECT_EQ(text.find("inf"), std::string::npos);
      EXPECT_NO_THROW(load_obj_mesh(frame_file(f)));
      Simulation reader(sim->scene());
      EXPECT_NO_THROW(load_state(reader, state_file(f)));
    }
  }
};

TEST(OutputGuard, FiniteStatePassesAndEveryInjectedNaNIsNamed) {
  GuardedRun run;
  EXPECT_EQ(run.sim->nonfinite_state(), "");
  Mesh& mesh = run.sim->cloths[0].mesh;
  struct Injection {
    const char* name;
    std::function<double&(Mesh&)> field;
    const char* named;
  };
  const std::vector<Injection> injections = {
      {"node x", [](Mesh& m) -> double& { return m.nodes[4].x.z(); }, "cloth 0 node 4:"},
      {"vert sizing", [](Mesh& m) -> double& { return m.verts[2].sizing(1, 1); }, "cloth 0 vert 2:"},
      {"edge rest angle", [](Mesh& m) -> double& { return m.edges[3].rest_theta; }, "cloth 0 edge 3:"},
      {"face Fp", [](Mesh& m) -> double& { return m.faces[5].Fp(0, 1); }, "cloth 0 face 5:"},
      {"face thickness", [](Mesh& m) -> double& { return m.faces[1].thickness; }, "cloth 0 face 1:"},
  };
  for (const Injection& injection : injections) {
    SCOPED_TRACE(injection.name);
    double& value = injection.field(mesh);
    const double kept = value;
    value = kNaN;
    EXPECT_EQ(run.sim->nonfinite_state().rfind(injection.named, 0), 0u) << run.sim->nonfinite_state();
    value = std::numeric_limits<double>::infinity();
    EXPECT_NE(run.sim->nonfinite_state(), "");
    value = kept;
  }
  EXPECT_EQ(run.sim->nonfinite_state(), "");
  ASSERT_FALSE(run.sim->handles.empty());
  run.sim->handles[0].anchors[0].x() = kNaN;
  EXPECT_EQ(run.sim->nonfinite_state().rfind("handle 0 anchor 0", 0), 0u) << run.sim->nonfinite_state();
}

// A NaN the step did not catch (the write follows the injection at once): the frame and its state are refused
// whole, earlier frames stay.
TEST(OutputGuard, FrameWithANaNIsNotWrittenAtAll) {
  GuardedRun run;
  run.sim->advance_frame();
  run.sim->cloths[0].mesh.verts[3].sizing(0, 0) = kNaN;
  try {
    run.out->write_frame(*run.sim);
    FAIL() << "a frame with a NaN was written";
  } catch (const NumericalError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("frame 2 not written"), std::string::npos) << message;
    EXPECT_NE(message.find("cloth 0 vert 3"), std::string::npos) << message;
  }
  EXPECT_FALSE(fs::exists(run.frame_file(2)));
  EXPECT_FALSE(fs::exists(run.state_file(2)));
  // save_state on its own refuses too (it is also called outside write_frame).
  EXPECT_THROW(save_state(*run.sim, run.dir / "direct.state"), NumericalError);
  EXPECT_FALSE(fs::exists(run.dir / "direct.state"));
  run.expect_frames_on_disk_finite(1);
}

// A NaN in the plastic deformation of one face, which the next step's forces read: the run stops with a
// NumericalError naming the failure and the frames kept, and nothing non-finite is on disk.
TEST(OutputGuard, NaNInjectedMidRunStopsTheRunAndLeavesOnlyFiniteFrames) {
  GuardedRun run;
  run.sim->cloths[0].mesh.faces[2].Fp(1, 1) = kNaN;
  run.sim->cloths[0].elements_dirty = true;
  std::ostringstream out_text, err_text;
  const Console console{out_text, err_text, false};
  SimulateOptions options;
  options.quiet = true;
  try {
    run_frames(*run.sim, run.out.get(), options, console);
    FAIL() << "the run went on with a NaN in the state";
  } catch (const NumericalError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("frames up to 1 are kept"), std::string::npos) << message;
  }
  EXPECT_FALSE(fs::exists(run.frame_file(2)));
  EXPECT_FALSE(fs::exists(run.state_file(2)));
  run.expect_frames_on_disk_finite(1);
}

}  // namespace
}  // namespace arcsim::app_test
