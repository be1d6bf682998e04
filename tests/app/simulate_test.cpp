// `arcsim simulate` end to end: a scene's output folder (frames, conf.json and referenced files,
// log.jsonl), --progress json, dry runs, option overrides, self-contained output folders and numerical failure.
#include <gtest/gtest.h>
#include <json/json.h>

#include <cmath>

#include "app/output_files.hpp"
#include "app_test_support.hpp"
#include "io/obj.hpp"

namespace arcsim::app_test {
namespace {

Json::Value parse_json(const std::string& text) {
  Json::CharReaderBuilder builder;
  builder["allowComments"] = true;
  builder["allowSpecialFloats"] = true;
  Json::Value root;
  std::string errors;
  std::istringstream in(text);
  EXPECT_TRUE(Json::parseFromStream(builder, in, &root, &errors)) << errors << " in: " << text;
  return root;
}

std::vector<Json::Value> parse_json_lines(const std::string& text) {
  std::vector<Json::Value> values;
  for (const std::string& line : lines_of(text)) values.push_back(parse_json(line));
  return values;
}

// Reads a frame file and checks it is a mesh of finite coordinates.
ObjData read_frame(const std::string& path) {
  ObjData obj;
  EXPECT_NO_THROW(obj = read_obj(path)) << path;
  for (const Vec3& x : obj.node_x) EXPECT_TRUE(x.allFinite()) << path;
  return obj;
}

// conf/swing.json: a small, fast scene (121 nodes, a vinyl sheet held by two corners) for the mechanics of a run.
std::string swing_scene() { return repo_file("conf/swing.json"); }

#define ARCSIM_REQUIRE_SWING()                                                          \
  do {                                                                                 \
    ARCSIM_REQUIRE_BINARY();                                                           \
    if (swing_scene().empty()) GTEST_SKIP() << "conf/swing.json not found";              \
  } while (0)

TEST(Simulate, SwingSceneWritesFramesSceneCopyAndLog) {
  ARCSIM_REQUIRE_SWING();
  TempFolder tmp;
  const std::string out = tmp / "runs/swing";  // parents are created
  const RunResult r = run_arcsim({"simulate", swing_scene(), out, "--end-frame", "2", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out, "");

  // Frame 0 is the initial state: the mesh placed by the scene's transform (translate [-0.5, -1, 1]).
  const ObjData frame0 = read_frame(out + "/00000_00.obj");
  ASSERT_EQ(frame0.node_x.size(), 121u);
  EXPECT_EQ(frame0.tris.size(), 200u);
  EXPECT_EQ(frame0.node_x[0], Vec3(-0.5, -1, 1));
  for (const Vec3& x : frame0.node_x) EXPECT_EQ(x.z(), 1.0);
  EXPECT_EQ(std::count(frame0.node_label.begin(), frame0.node_label.end(), 1), 2);
  for (int f = 1; f <= 2; ++f) {
    const ObjData frame = read_frame(out + "/0000" + std::to_string(f) + "_00.obj");
    ASSERT_EQ(frame.node_x.size(), 121u);
    double lowest = 1;
    for (const Vec3& x : frame.node_x) lowest = std::min(lowest, x.z());
    EXPECT_LT(lowest, 1.0) << "frame " << f << ": the sheet should have started to fall";
  }
  EXPECT_FALSE(fs::exists(out + "/00003_00.obj"));
  EXPECT_FALSE(fs::exists(out + "/obs00.obj"));  // the scene has no obstacles

  // The scene and its files, at the paths the scene names them by, so that out/conf.json loads on its own.
  EXPECT_EQ(read_text(out + "/conf.json"), read_text(swing_scene()));
  EXPECT_EQ(read_text(out + "/meshes/square.obj"), read_text(repo_file("meshes/square.obj")));
  EXPECT_EQ(read_text(out + "/materials/vinyl.json"), read_text(repo_file("materials/vinyl.json")));

  const std::vector<Json::Value> log = parse_json_lines(read_text(out + "/log.jsonl"));
  ASSERT_EQ(log.size(), 3u);
  for (int f = 0; f < 3; ++f) {
    const Json::Value& line = log[f];
    EXPECT_EQ(line["frame"].asInt(), f);
    EXPECT_NEAR(line["time"].asDouble(), 0.04 * f, 1e-12);
    EXPECT_EQ(line["steps"].asInt(), f == 0 ? 0 : 4);  // frame_steps 4
    EXPECT_EQ(line["nodes"].asInt(), 121);
    EXPECT_EQ(line["faces"].asInt(), 200);
    EXPECT_TRUE(line["saved"].asBool());
    const Json::Value& wall = line["wall"];
    double parts = 0;
    for (const char* key : {"physics", "collision", "remeshing", "plasticity", "fracture", "output"}) {
      ASSERT_TRUE(wall[key].isNumeric()) << key;
      EXPECT_GE(wall[key].asDouble(), 0) << key;
      parts += wall[key].asDouble();
    }
    EXPECT_GE(wall["total"].asDouble(), 0.999 * parts);
    if (f > 0) {
      EXPECT_GT(wall["physics"].asDouble(), 0);
    }
  }
}

TEST(Simulate, ProgressJsonPrintsOneObjectPerFrameAndDryRunWritesNothing) {
  ARCSIM_REQUIRE_SWING();
  TempFolder tmp;
  const RunResult r = run_arcsim({"simulate", "--progress", "json", swing_scene(), "--end-frame=3"}, tmp / "");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");  // JSON mode: no text progress
  const std::vector<Json::Value> lines = parse_json_lines(r.out);
  ASSERT_EQ(lines.size(), 3u) << r.out;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(lines[k]["frame"].asInt(), k + 1);
    EXPECT_EQ(lines[k]["total"].asInt(), 3);
    EXPECT_NEAR(lines[k]["time"].asDouble(), 0.04 * (k + 1), 1e-12);
    EXPECT_EQ(lines[k]["faces"].asInt(), 200);
    EXPECT_EQ(lines[k]["nodes"].asInt(), 121);
    EXPECT_GT(lines[k]["wall"].asDouble(), 0);
  }
  EXPECT_TRUE(fs::is_empty(tmp.path())) << "a dry run must not write files";
}

TEST(Simulate, TextProgressOnANonTerminalAndQuietSilencesIt) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder tmp;
  tmp.write("sheet.obj", tiny_sheet_obj());
  const std::string scene = tmp.write("scene.json", tiny_scene("sheet.obj"));
  const RunResult loud = run_arcsim({"simulate", scene, "--end-frame", "2"});
  ASSERT_EQ(loud.exit_code, 0) << loud.err;
  EXPECT_EQ(loud.out, "");
  EXPECT_EQ(loud.err.find('\r'), std::string::npos) << "no live line when stderr is not a terminal";
  const std::vector<std::string> lines = lines_of(loud.err);
  ASSERT_EQ(lines.size(), 3u) << loud.err;  // frame 1 (the first), frame 2 (100%), the summary
  EXPECT_EQ(lines[0].rfind("frame 1/2", 0), 0u) << lines[0];
  EXPECT_EQ(lines[1].rfind("frame 2/2", 0), 0u) << lines[1];
  EXPECT_EQ(lines[2].rfind("done: 2 frames", 0), 0u) << lines[2];

  const RunResult quiet = run_arcsim({"simulate", scene, "--end-frame", "2", "--quiet"});
  EXPECT_EQ(quiet.exit_code, 0);
  EXPECT_EQ(quiet.err, "");
}

TEST(Simulate, EndTimeOptionOverridesTheScene) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder tmp;
  tmp.write("sheet.obj", tiny_sheet_obj());
  const std::string scene = tmp.write("scene.json", tiny_scene("sheet.obj"));  // 0.02 s per frame, 3 frames
  const RunResult r = run_arcsim({"simulate", scene, tmp / "out", "--end-time", "0.04", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines_of(read_text(tmp / "out/log.jsonl")).size(), 3u);  // frames 0, 1, 2
  EXPECT_TRUE(fs::exists(tmp / "out/00002_00.obj"));
  EXPECT_FALSE(fs::exists(tmp / "out/00003_00.obj"));
}

TEST(Simulate, WarningsGoToStderrUnlessQuiet) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder tmp;
  tmp.write("sheet.obj", tiny_sheet_obj());
  const std::string scene = tmp.write("scene.json", tiny_scene("sheet.obj", "{\"thickness\": 1e-3, "
                                                                            "\"density\": 500, \"colour\": \"red\","
                                                                            " \"elastic_modulus\": 1e6}"));
  const RunResult loud = run_arcsim({"simulate", scene, "--end-frame", "1"});
  ASSERT_EQ(loud.exit_code, 0) << loud.err;
  const std::vector<std::string> lines = lines_of(loud.err);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0].rfind("arcsim: warning: ", 0), 0u) << lines[0];
  EXPECT_NE(lines[0].find("colour"), std::string::npos) << lines[0];
  const RunResult quiet = run_arcsim({"simulate", scene, "--end-frame", "1", "--quiet"});
  EXPECT_EQ(quiet.exit_code, 0);
  EXPECT_EQ(quiet.err, "");
}

TEST(Simulate, ReusedOutputFolderStartsANewLog) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder tmp;
  tmp.write("sheet.obj", tiny_sheet_obj());
  const std::string scene = tmp.write("scene.json", tiny_scene("sheet.obj"));
  ASSERT_EQ(run_arcsim({"simulate", scene, tmp / "out", "--quiet"}).exit_code, 0);
  EXPECT_EQ(lines_of(read_text(tmp / "out/log.jsonl")).size(), 4u);  // frames 0-3
  const std::string frame1 = read_text(tmp / "out/00001_00.obj");
  const RunResult again = run_arcsim({"simulate", scene, tmp / "out", "--quiet", "--end-frame", "1"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(lines_of(read_text(tmp / "out/log.jsonl")).size(), 2u);
  EXPECT_EQ(read_text(tmp / "out/00001_00.obj"), frame1);  // deterministic, rewritten in place
}

// Everything an output folder needs is inside it: the scene names its files relative to the scene folder's
// parent, relative to the working directory, with "..", and by absolute path; after the originals are deleted,
// out/conf.json must still run and give the same frames.
TEST(Simulate, OutputFolderRunsOnItsOwnAfterTheOriginalsAreGone) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder tmp;
  tmp.write("project/meshes/sheet.obj", tiny_sheet_obj());  // "../meshes/sheet.obj" from project/conf/
  tmp.write("project/materials/soft.json",                 // "materials/soft.json": found in the parent
            "// a soft sheet\n{\"thickness\": 1e-3, \"density\": 500, \"elastic_modulus\": 1e6, "
            "\"poisson_ratio\": 0.3}\n");
  tmp.write("work/ground.obj", "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nf 1 2 3\nf 1 3 4\n");  // in the CWD
  const std::string absolute_post =
      tmp.write("elsewhere/post.obj", "v 0 0 -2\nv 0.1 0 -2\nv 0 0.1 -2\nf 1 2 3\n");
  const std::string scene = tmp.write(
      "project/conf/scene.json",
      "// comments survive a plain copy, not a rewrite\n" +
          tiny_scene("../meshes/sheet.obj", "{\"data\": \"materials/soft.json\"}",
                     ",\n  \"motions\": [[{\"time\": 0},\n"
                     "    {\"time\": 0.1, \"transform\": {\"translate\": [0, 0, 1]}}]],\n"
                     "  \"obstacles\": [{\"mesh\": \"ground.obj\", \"motion\": 0}, {\"mesh\": \"" +
                         absolute_post + "\"}]"));
  const std::string out = tmp / "out";
  const RunResult first = run_arcsim({"simulate", scene, out, "--quiet", "--threads", "1"}, tmp / "work");
  ASSERT_EQ(first.exit_code, 0) << first.err;

  EXPECT_EQ(read_text(out + "/files/sheet.obj"), tiny_sheet_obj());
  EXPECT_TRUE(fs::exists(out + "/materials/soft.json"));
  EXPECT_TRUE(fs::exists(out + "/ground.obj"));
  EXPECT_TRUE(fs::exists(out + "/files/post.obj"));
  const Json::Value conf = parse_json(read_text(out + "/conf.json"));
  EXPECT_EQ(conf["cloths"][0]["mesh"].asString(), "files/sheet.obj");
  EXPECT_EQ(conf["cloths"][0]["materials"][0]["data"].asString(), "materials/soft.json");
  EXPECT_EQ(conf["obstacles"][0]["mesh"].asString(), "ground.obj");
  EXPECT_EQ(conf["obstacles"][1]["mesh"].asString(), "files/post.obj");
  // Obstacle 0 moves: one file per frame; obstacle 1 is static: one file.
  for (int f = 0; f <= 3; ++f) EXPECT_TRUE(fs::exists(out + "/0000" + std::to_string(f) + "_obs00.obj")) << f;
  EXPECT_FALSE(fs::exists(out + "/obs00.obj"));
  EXPECT_TRUE(fs::exists(out + "/obs01.obj"));
  EXPECT_FALSE(fs::exists(out + "/00000_obs01.obj"));
  // Frame 3 is t = 0.06 s, 0.6 of the way between the keyframes: the Hermite blend 3s^2 - 2s^3 = 0.648.
  const Vec3 ground0 = read_frame(out + "/00003_obs00.obj").node_x[0];
  EXPECT_NEAR((ground0 - Vec3(-1, -1, -1 + 0.648)).norm(), 0, 1e-12) << ground0.transpose();

  fs::remove_all(tmp / "project");
  fs::remove_all(tmp / "work");
  fs::remove_all(tmp / "elsewhere");
  fs::create_directories(tmp / "empty");
  const std::string again = tmp / "again";
  const RunResult second =
      run_arcsim({"simulate", out + "/conf.json", again, "--quiet", "--threads", "1"}, tmp / "empty");
  ASSERT_EQ(second.exit_code, 0) << second.err;
  for (const char* name : {"00000_00.obj", "00003_00.obj", "00003_obs00.obj", "obs01.obj"})
    EXPECT_EQ(read_text(again + "/" + name), read_text(out + "/" + name)) << name;
}

// ARCSim's obstacle pattern form, named with "..": the pattern is rewritten to files/ and every file copied.
TEST(Simulate, ObstaclePatternIsCopiedAndRewritten) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder tmp;
  tmp.write("scene/sheet.obj", tiny_sheet_obj());
  tmp.write("shapes/post_00.obj", "v 0 0 -2\nv 0.1 0 -2\nv 0 0.1 -2\nf 1 2 3\n");
  tmp.write("shapes/post_01.obj", "v 0 0 -3\nv 0.1 0 -3\nv 0 0.1 -3\nf 1 2 3\n");
  const std::string scene = tmp.write(
      "scene/scene.json", tiny_scene("sheet.obj", "{\"thickness\": 1e-3, \"density\": 500, \"elastic_modulus\": 1e6}",
                                     ",\n  \"obstacles\": \"../shapes/post_%02d.obj\""));
  const std::string out = tmp / "out";
  const RunResult r = run_arcsim({"simulate", scene, out, "--quiet", "--end-frame", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(parse_json(read_text(out + "/conf.json"))["obstacles"].asString(), "files/post_%02d.obj");
  EXPECT_EQ(read_text(out + "/files/post_01.obj"), read_text(tmp / "shapes/post_01.obj"));
  EXPECT_EQ(read_text(out + "/sheet.obj"), tiny_sheet_obj());
  fs::remove_all(tmp / "shapes");
  fs::remove_all(tmp / "scene");
  const RunResult again = run_arcsim({"simulate", out + "/conf.json", tmp / "again", "--quiet", "--end-frame", "1"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(read_text(tmp / "again/obs01.obj"), read_text(out + "/obs01.obj"));
  EXPECT_FALSE(fs::exists(tmp / "again/obs02.obj"));
}

// Free fall with absurd gravity and time step: the speed passes 1e4 m/s (the simulation's instability test) in
// frame 6. Exit 3 with one clear line, and frames 0-5 stay on disk, complete.
TEST(Simulate, NumericalBlowUpExitsThreeAndKeepsEarlierFrames) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder tmp;
  tmp.write("sheet.obj", tiny_sheet_obj());
  const std::string scene = tmp.write(
      "scene.json",
      "{\"frame_time\": 2, \"end_frame\": 20,\n"
      " \"cloths\": [{\"mesh\": \"sheet.obj\", \"materials\": [{\"thickness\": 1e-3, \"density\": 1000,"
      " \"elastic_modulus\": 1e6, \"poisson_ratio\": 0.3}]}],\n"
      " \"gravity\": [0, 0, -900], \"wind\": {\"density\": 0}, \"disable\": [\"remeshing\"]}\n");
  const std::string out = tmp / "out";
  const RunResult r = run_arcsim({"simulate", scene, out, "--quiet"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  const std::vector<std::string> lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_EQ(lines[0].rfind("arcsim: numerical failure: ", 0), 0u) << lines[0];
  EXPECT_NE(lines[0].find("unstable"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("frames up to 5"), std::string::npos) << lines[0];
  for (int f = 0; f <= 5; ++f) {
    const ObjData frame = read_frame(out + "/0000" + std::to_string(f) + "_00.obj");
    ASSERT_EQ(frame.node_x.size(), 9u);
    // Implicit Euler free fall: v_k = g k dt, x_k = -g dt^2 k (k + 1) / 2 (exact for a rigid translation).
    EXPECT_NEAR(frame.node_x[0].z(), -900.0 * 4 * f * (f + 1) / 2, 1e-6 * (1 + 1800.0 * f * f)) << f;
  }
  EXPECT_FALSE(fs::exists(out + "/00006_00.obj"));
  EXPECT_EQ(lines_of(read_text(out + "/log.jsonl")).size(), 6u);
}

// A full disk during a run (a 2 MiB tmpfs: frames of ~0.3 MB from frame 0 on, mounted if this test runs as root where mounting is allowed): the
// run stops with one clear line naming the file and "No space left on device", exit 2 or 3, and every frame
// with a state file is complete (byte-identical to the same frame of a run with room), with no temporary file
// left behind.
TEST(Simulate, FullDiskStopsWithAClearErrorAndKeepsCompleteFrames) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder tmp;
  const std::string disk = tmp / "disk";
  fs::create_directories(disk);
  if (::geteuid() != 0 ||
      std::system(("mount -t tmpfs -o size=2m tmpfs " + shell_quote(disk) + " 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "cannot mount a small tmpfs here (needs root and mount permission)";
  struct Unmount {
    std::string path;
    ~Unmount() { (void)std::system(("umount " + shell_quote(path) + " 2>/dev/null").c_str()); }
  } unmount{disk};
  tmp.write("sheet.obj", tiny_sheet_obj());
  // A sheet remeshed finer and finer as it falls and bends: each frame is larger than the one before.
  const std::string scene = tmp.write(
      "scene.json",
      "{\"frame_time\": 0.02, \"frame_steps\": 2, \"end_frame\": 200,\n"
      " \"cloths\": [{\"mesh\": \"sheet.obj\", \"materials\": [{\"thickness\": 1e-3, \"density\": 500,"
      " \"elastic_modulus\": 1e6, \"poisson_ratio\": 0.3}],\n"
      " \"remeshing\": {\"refine_angle\": 0.1, \"refine_compression\": 0.01, \"refine_velocity\": 1,"
      " \"size\": [0.01, 0.1], \"aspect_min\": 0.2}}],\n"
      " \"handles\": [{\"label\": 1}], \"gravity\": [0, 0, -9.8]}\n");
  const std::string out = disk + "/out";
  const RunResult r = run_arcsim({"simulate", scene, out, "--quiet"});
  EXPECT_TRUE(r.exit_code == 2 || r.exit_code == 3) << r.exit_code << ": " << r.err;
  const std::vector<std::string> lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_NE(lines[0].find("No space left on device"), std::string::npos) << lines[0];
  int complete = 0;
  std::vector<std::string> states;
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name << " left behind";
    if (state_file_frame(name) >= 0) states.push_back(name);
  }
  ASSERT_FALSE(states.empty());
  const std::string roomy = tmp / "roomy";
  ASSERT_EQ(run_arcsim({"simulate", scene, roomy, "--quiet", "--end-frame", std::to_string(states.size() + 1)})
                .exit_code, 0);
  for (const std::string& name : states) {
    const std::string obj = name.substr(0, 5) + "_00.obj";
    EXPECT_TRUE(read_text(out + "/" + name) == read_text(roomy + "/" + name)) << name;
    EXPECT_TRUE(read_text(out + "/" + obj) == read_text(roomy + "/" + obj)) << obj;
    ++complete;
  }
  EXPECT_LT(complete, 200);
}

}  // namespace
}  // namespace arcsim::app_test
