// A contact-heavy scene with every module of the step: a soft plastic sheet thrown down onto a sphere that
// rests on a floor. It wraps the sphere (impact zones and proximity contacts against the sphere and the floor,
// bending past its yield curvature: plasticity) and is remeshed at every frame end.
//  - ThreadDeterminismSlow: a ~2300-face sheet, large enough for every parallel loop of the step to run on
//    several threads (assembly and plasticity from 2000 faces, BVH traversal from 8192 tree nodes), gives
//    bit-identical states and byte-identical frame files with 1 and with 2 threads, and the test asserts that
//    contact, plasticity and remeshing actually happened.
//  - CrumpleScene: a small version, a few frames, for the sanitizer suite (acceptance-level run under ASan).
#include <gtest/gtest.h>

#include <omp.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/threads.hpp"
#include "collision/scene_fixtures.hpp"
#include "mesh/validate.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using namespace testing;

constexpr double kSphereRadius = 0.05;  // m, resting on the floor y = 0

// The sheet: `cells` x `cells` cells over `width` (m), 1 cm above the sphere's top, thrown down at 2 m/s;
// remeshed between size_min and size_max (m).
Scene crumple_scene(const TempDir& dir, int cells, double width, double size_min, double size_max, int frames) {
  write_obj(make_grid(cells, cells, width, width, Diagonal::kAlternating), (dir.path / "sheet.obj").string());
  write_plain_obj(make_sphere(kSphereRadius, 2), (dir.path / "sphere.obj").string());
  const std::vector<Vec3> corners{{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  write_plain_obj(Mesh::from_triangles(corners, corners, {0, 1, 2, 3}, {{0, 2, 1}, {0, 3, 2}}),
                  (dir.path / "floor.obj").string());

  Scene scene = base_scene(2e-3, kInfinity);
  scene.frame_steps = 5;
  scene.frame_time = 5 * scene.step_time;
  scene.end_frame = frames;
  scene.disabled.erase("remeshing");
  scene.disabled.erase("plasticity");
  Material m = sheet_material();
  m.yield_curv = 5;  // 1/m: wrapping the 5 cm sphere (curvature 20 1/m) yields
  m.damping = 1e-4;
  scene.cloths.push_back(cloth_spec(dir.path / "sheet.obj",
                                    make_transform(Vec3(-width / 2, 2 * kSphereRadius + 0.01, width / 2), lay_flat()),
                                    m));
  RemeshingParams& r = scene.cloths[0].remeshing;
  r.refine_angle = 0.3;
  r.refine_compression = 0.01;
  r.refine_velocity = 1;
  r.size_min = size_min;
  r.size_max = size_max;
  r.aspect_min = 0.2;
  r.has_size = r.has_aspect_min = r.has_refine_compression = true;
  scene.cloths[0].velocity.linear = Vec3(0, -2, 0);
  scene.obstacles.push_back(obstacle_spec(dir.path / "sphere.obj", make_transform(Vec3(0, kSphereRadius, 0))));
  scene.obstacles.push_back(obstacle_spec(dir.path / "floor.obj", make_transform(Vec3::Zero())));
  return scene;
}

// What the run did, summed over its frames.
struct CrumpleRun {
  std::vector<std::string> states;  // per frame: the raw bytes of the cloth's state
  std::vector<std::string> frames;  // per frame: the frame file (extended OBJ) as written
  long long impacts = 0, zones = 0, proximities = 0;
  int edits = 0, most_faces = 0, fewest_faces = 1 << 30;
  double plastic_work = 0, lowest = kInfinity;
  int intersecting = 0;             // at the end
  std::string mesh_problem;         // check_mesh after the last frame
};

template <typename T>
void append_bytes(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

std::string state_bytes(const Mesh& m) {
  std::string s;
  for (const Node& n : m.nodes) {
    append_bytes(s, n.x);
    append_bytes(s, n.v);
  }
  for (const Vert& v : m.verts) append_bytes(s, v.u);
  for (const Face& f : m.faces) {
    append_bytes(s, f.Fp);
    append_bytes(s, f.Sp);
    append_bytes(s, f.thickness);
  }
  for (const Edge& e : m.edges) append_bytes(s, e.rest_theta);
  return s;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

CrumpleRun run_crumple(const Scene& scene, const TempDir& dir) {
  Simulation sim(scene);
  CrumpleRun r;
  int frame = 0;
  while (!sim.finished()) {
    sim.advance_frame();
    const Mesh& mesh = sim.cloths[0].mesh;
    r.states.push_back(state_bytes(mesh));
    const fs::path file = dir.path / ("frame" + std::to_string(frame++) + ".obj");
    write_obj(mesh, file.string());
    r.frames.push_back(read_file(file));
    const RemeshStats& s = sim.remesh_stats.at(0);
    r.edits += s.splits + s.collapses + s.flips;
    r.plastic_work += sim.plastic_work.at(0);
    r.most_faces = std::max(r.most_faces, static_cast<int>(mesh.faces.size()));
    r.fewest_faces = std::min(r.fewest_faces, static_cast<int>(mesh.faces.size()));
    r.lowest = std::min(r.lowest, lowest_cloth_y(sim));
  }
  r.impacts = sim.collision_totals().impacts;
  r.zones = sim.collision_totals().zones;
  r.proximities = sim.collision_totals().proximities;
  r.intersecting = count_intersecting_pairs(sim);
  r.mesh_problem = check_mesh(sim.cloths[0].mesh);
  return r;
}

// The scene's phenomena: contact in both phases, yielding, remeshing edits, no intersection, nothing through
// the floor.
void expect_crumpled(const CrumpleRun& r) {
  EXPECT_GT(r.impacts, 0);
  EXPECT_GT(r.zones, 0);
  EXPECT_GT(r.proximities, 0);
  EXPECT_GT(r.plastic_work, 0);
  EXPECT_GT(r.edits, 0);
  EXPECT_EQ(r.intersecting, 0);
  EXPECT_EQ(r.mesh_problem, "");
  EXPECT_GT(r.lowest, -1e-4);
}

// Runs with `threads` OpenMP threads (as `arcsim simulate --threads`), restoring the settings afterwards.
CrumpleRun run_with_threads(const Scene& scene, int threads) {
  const int saved = omp_get_max_threads(), saved_dynamic = omp_get_dynamic();
  configure_threads(threads);
  TempDir dir;
  CrumpleRun r = run_crumple(scene, dir);
  omp_set_dynamic(saved_dynamic);
  omp_set_num_threads(saved);
  return r;
}

TEST(ThreadDeterminismSlow, CrumpledSheetIsBitIdenticalWithOneAndTwoThreads) {
  TempDir dir;
  // 34 x 34 cells (2312 faces) over 34 cm: 1 cm cells, remeshed between 1 and 1.5 cm (so that it does not
  // coarsen below the parallel thresholds).
  const Scene scene = crumple_scene(dir, 34, 0.34, 0.01, 0.015, 8);
  const CrumpleRun one = run_with_threads(scene, 1);
  const CrumpleRun two = run_with_threads(scene, 2);
  std::printf("[ result ] %zu frames, faces %d..%d, %lld impacts in %lld zones, %lld proximity contacts, %d edits, "
              "plastic work %.3g J\n",
              one.frames.size(), one.fewest_faces, one.most_faces, one.impacts, one.zones, one.proximities,
              one.edits, one.plastic_work);
  ASSERT_EQ(one.frames.size(), 8u);
  ASSERT_EQ(two.frames.size(), one.frames.size());
  for (size_t f = 0; f < one.frames.size(); ++f) {
    EXPECT_TRUE(one.states[f] == two.states[f]) << "state differs at frame " << f + 1;
    EXPECT_TRUE(one.frames[f] == two.frames[f]) << "frame file differs at frame " << f + 1;
  }
  EXPECT_EQ(two.impacts, one.impacts);
  EXPECT_EQ(two.proximities, one.proximities);
  EXPECT_EQ(two.edits, one.edits);
  expect_crumpled(one);
  // Large enough for the parallel loops: element assembly (cloth_physics.cpp, 2048 elements), plastic flow
  // (plastic_step.cpp, 2000 faces), the BVH self traversal (bvh.cpp, 8192 tree nodes counted twice).
  EXPECT_GT(one.fewest_faces, 2100);
}

TEST(CrumpleScene, FewFramesOfARemeshedCollidingPlasticSheet) {
  // 8 x 8 cells over 24 cm, remeshed between 2 and 8 cm: about 150 faces, 5 frames (25 steps).
  TempDir dir;
  const CrumpleRun r = run_crumple(crumple_scene(dir, 8, 0.24, 0.02, 0.08, 5), dir);
  std::printf("[ result ] faces %d..%d, %lld impacts in %lld zones, %lld proximity contacts, %d edits, plastic "
              "work %.3g J\n",
              r.fewest_faces, r.most_faces, r.impacts, r.zones, r.proximities, r.edits, r.plastic_work);
  expect_crumpled(r);
}

}  // namespace
}  // namespace arcsim
