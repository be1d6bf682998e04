// Every scene shipped in conf/ runs to its end with the real binary and passes `arcsim inspect` on sampled
// frames and its last: exit 0, valid meshes, nothing non-finite, no intersecting triangles within or between
// sheets or with obstacles (issue 13, acceptance 1). Minutes in all: `make slowcheck`.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <limits>
#include <sstream>

#include "app/app_test_support.hpp"
#include "io/obj.hpp"
#include "mesh/pieces.hpp"

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

// Each "pieces": N of an `arcsim inspect --last --quiet` line, sheet by sheet.
std::vector<int> pieces_per_sheet(const std::string& inspect_out) {
  std::vector<int> pieces;
  const std::string key = "\"pieces\":";
  for (size_t at = inspect_out.find(key); at != std::string::npos; at = inspect_out.find(key, at + 1))
    pieces.push_back(std::stoi(inspect_out.substr(at + key.size())));
  return pieces;
}

// The first number of "piece_faces": [...] (inspect lists them largest first) and the sheet's face count.
std::pair<int, int> largest_piece_and_faces(const std::string& inspect_out) {
  const size_t faces = inspect_out.find("\"faces\":");
  const size_t largest = inspect_out.find("\"piece_faces\":[");
  if (faces == std::string::npos || largest == std::string::npos) return {0, 0};
  return {std::stoi(inspect_out.substr(largest + 15)), std::stoi(inspect_out.substr(faces + 8))};
}

// Each vertex position ("v x y z") of a saved frame's cloth OBJ (m).
std::vector<std::array<double, 3>> obj_vertices(const std::string& obj) {
  std::vector<std::array<double, 3>> out;
  for (const std::string& line : lines_of(read_text(obj))) {
    if (line.rfind("v ", 0) != 0) continue;
    std::istringstream in(line.substr(2));
    double x, y, z;
    if (in >> x >> y >> z) out.push_back({x, y, z});
  }
  return out;
}

// The sum of every frame's "cracks" (fracture openings) in a run's log.jsonl.
int total_cracks(const std::string& log) {
  int total = 0;
  const std::string key = "\"cracks\":";
  for (const std::string& line : lines_of(read_text(log))) {
    const size_t at = line.find(key);
    if (at != std::string::npos) total += std::stoi(line.substr(at + key.size()));
  }
  return total;
}

// The lowest z of a saved frame's cloth OBJ (m).
double lowest_z(const std::string& obj) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& v : obj_vertices(obj)) lowest = std::min(lowest, v[2]);
  return lowest;
}

// A shipped scene run to its end with one thread (exit 0 asserted by the caller through `ok`), its frames
// inspected every `every` (exit 0 expected) and its last frame inspected: the inspection's JSON lines in `last`.
struct SceneRun {
  std::string dir;
  RunResult last;
  bool ok = false;
};

SceneRun run_and_inspect(const std::string& conf, const TempFolder& out, const std::string& every) {
  SceneRun result;
  const std::string scene = repo_file(conf);
  EXPECT_FALSE(scene.empty()) << conf << " not found";
  if (scene.empty()) return result;
  result.dir = (out.path() / "run").string();
  const RunResult run = run_arcsim({"simulate", scene, result.dir, "--quiet", "--threads", "1"});
  EXPECT_EQ(run.exit_code, 0) << run.err;
  if (run.exit_code != 0) return result;
  const RunResult sampled = run_arcsim({"inspect", result.dir, "--every", every, "--quiet"});
  EXPECT_EQ(sampled.exit_code, 0) << sampled.out << sampled.err;
  result.last = run_arcsim({"inspect", result.dir, "--last", "--quiet"});
  EXPECT_EQ(result.last.exit_code, 0) << result.last.err;
  result.ok = result.last.exit_code == 0;
  return result;
}

// Fig. 1: one press of a ball 1 cm into five clamped sheets. With the default contact settings (1e9 N/m^3, 1 mm)
// the draft shattered the steel and foil at first contact and stopped (exit 3); with ARCSim's fracture-scene
// contact settings each sheet responds as its material: the brittle acrylic breaks into pieces, the ductile foil
// and steel keep a plastic dent, the elastic cork and vinyl spring back flat. About 20 s.
TEST(ConfScenes, SlowCheckPaperVarietySheetsRespondEachAsTheirMaterial) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder out;
  const SceneRun run = run_and_inspect("conf/paper-variety.json", out, "5");
  ASSERT_TRUE(run.ok);
  const std::vector<int> pieces = pieces_per_sheet(run.last.out);  // cork, foil, acrylic, steel, vinyl
  ASSERT_EQ(pieces.size(), 5u) << run.last.out;
  EXPECT_GE(pieces[2], 2) << "acrylic should break";
  EXPECT_EQ(pieces[3], 1) << "steel should dent, not break";
  EXPECT_EQ(pieces[4], 1) << "vinyl should not break";
  // The sheets lie at z = 0 and are pressed 1 cm; the last frame (80 ms) is long after the ball has left.
  const auto last_z = [&](int sheet) { return lowest_z(run.dir + "/00040_0" + std::to_string(sheet) + ".obj"); };
  EXPECT_LT(last_z(1), -3e-3) << "foil keeps a plastic dent";
  EXPECT_LT(last_z(3), -3e-3) << "steel keeps a plastic dent";
  EXPECT_GT(last_z(0), -1e-3) << "cork springs back";
  EXPECT_GT(last_z(4), -1e-3) << "vinyl springs back";
  EXPECT_LT(lowest_z(run.dir + "/00010_04.obj"), -5e-3) << "the ball pressed the vinyl";
}

// Fig. 11 left: a 20 m/s ball through an acrylic dome. With the draft's soft contact (1e11 N/m^3, 0.5 mm) pieces
// intersected in frames 2-8; with ARCSim's fracture-scene contact settings the ball breaks a hole of shards out
// of the top while the dome stands. About 40 s.
TEST(ConfScenes, SlowCheckPaperDomeBreaksAHoleOfShardsAndStands) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder out;
  const SceneRun run = run_and_inspect("conf/paper-dome.json", out, "1");
  ASSERT_TRUE(run.ok);
  const std::vector<int> pieces = pieces_per_sheet(run.last.out);
  ASSERT_EQ(pieces.size(), 1u) << run.last.out;
  EXPECT_GE(pieces[0], 50) << "shards";
  const auto [largest, faces] = largest_piece_and_faces(run.last.out);
  EXPECT_GE(largest, faces / 5) << "the dome itself stays one piece";
}

// Fig. 9 left: a polycarbonate tube pushed down 2 cm buckles into lobes and cracks along its folds. The draft
// (docs/repro/paper-cylinder-draft.json until 2026-12-05) blew up after its first openings: lip gaps strained the
// plastic lip faces, and the bending-fracture curvature disagreed with the hinges on crack lips
// (docs/stability.md, 2026-12-05 evening). About 3 min.
TEST(ConfScenes, SlowCheckPaperCylinderBucklesAndCracksAlongItsFolds) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder out;
  const SceneRun run = run_and_inspect("conf/paper-cylinder.json", out, "5");
  ASSERT_TRUE(run.ok);
  // The top rim went down 2 cm: the tube is 10 cm tall at the end (12 cm at rest).
  const std::vector<std::array<double, 3>> end = obj_vertices(run.dir + "/00030_00.obj");
  ASSERT_FALSE(end.empty());
  double top = -1, radial = 0;
  for (const auto& [x, y, z] : end) {
    top = std::max(top, z);
    // Buckled: away from the collars the wall has left its 5 cm radius by lobes of millimetres (0.1 mm at rest).
    if (z > 0.02 && z < 0.08) radial = std::max(radial, std::abs(std::hypot(x, y) - 0.05));
  }
  EXPECT_NEAR(top, 0.10, 1e-3) << "the clamp pushed the top rim 2 cm down";
  EXPECT_GT(radial, 3e-3) << "the tube buckles into lobes";
  EXPECT_GE(total_cracks(run.dir + "/log.jsonl"), 20) << "the folds crack";
  const auto [largest, faces] = largest_piece_and_faces(run.last.out);
  EXPECT_GE(largest, 9 * faces / 10) << "the tube cracks, it does not shatter";
}

// Fig. 8a: paper held at its four corners, turned and pulled apart in its plane, tears from the notch in its top
// edge down through the sheet into two halves. The earlier draft (hung from two top grips, pulled out of plane)
// tore a ragged notch and arrested in one piece (docs/scenes.md). About 35 s.
TEST(ConfScenes, SlowCheckPaperTearingTearsThroughIntoTwoHalves) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder out;
  const SceneRun run = run_and_inspect("conf/paper-tearing.json", out, "25");
  ASSERT_TRUE(run.ok);
  const std::vector<int> pieces = pieces_per_sheet(run.last.out);
  ASSERT_EQ(pieces.size(), 1u) << run.last.out;
  EXPECT_EQ(pieces[0], 2) << "two halves, no shards";
  const auto [largest, faces] = largest_piece_and_faces(run.last.out);
  EXPECT_LE(largest, 6 * faces / 10) << "the tear runs down the middle";
  // Torn through: the two halves' nearest nodes are centimetres apart at the end (the hands pulled 12 cm). The
  // halves are the last frame's pieces as its faces join them (wherever the tear ran), and the gap is the
  // smallest distance between a node of one and a node of the other: 8.53 cm measured (one thread, 2 cm asked).
  const Mesh end = load_obj_mesh(run.dir + "/00500_00.obj");
  ASSERT_EQ(mesh_pieces(end).size(), 2u);
  std::array<std::vector<Vec3>, 2> halves;
  std::vector<char> seen(end.nodes.size(), 0);
  const std::vector<int> piece_of_face = face_pieces(end);
  for (int f = 0; f < static_cast<int>(end.faces.size()); ++f) {
    if (piece_of_face[f] < 0) continue;  // a dead face (none in a loaded frame)
    for (int c = 0; c < 3; ++c) {
      const int n = end.face_node(f, c);
      if (!seen[n]) halves[piece_of_face[f]].push_back(end.nodes[n].x);
      seen[n] = 1;
    }
  }
  double gap = std::numeric_limits<double>::infinity();
  for (const Vec3& a : halves[0])
    for (const Vec3& b : halves[1]) gap = std::min(gap, (a - b).norm());
  std::printf("[ measure ] paper-tearing: the halves are %.4f m apart at the end\n", gap);
  EXPECT_GT(gap, 0.02) << "the halves are apart";
}

}  // namespace
}  // namespace arcsim::app_test
