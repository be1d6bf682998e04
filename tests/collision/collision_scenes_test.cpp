// Whole simulations with contact: sheets dropped on a floor (obstacle mesh, and floor proxy), on a sphere, a
// strip folding onto itself, and Coulomb friction on a tilted plane. Checked every step: no cloth vertex
// under the floor beyond 0.1 mm; at checkpoints: no intersecting pair of non-adjacent triangles (exact test).
// The full scenarios take 0.1-0.8 s optimised but 1-8 s under the sanitizers, so they are in the Slow suite;
// CollisionScenes keeps a small version of the floor drop and of the module switches for the sanitizer run.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <set>
#include <string>

#include "collision/scene_fixtures.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using namespace testing;

struct RunReport {
  double lowest = kInfinity;  // lowest cloth y over the run (m)
  int intersecting = 0;       // intersecting triangle pairs summed over the checkpoints
  double seconds = 0, collision_seconds = 0;
};

RunReport run(Simulation& sim, int check_every) {
  RunReport r;
  const auto t0 = std::chrono::steady_clock::now();
  while (!sim.finished()) {
    sim.advance_step();
    r.lowest = std::min(r.lowest, lowest_cloth_y(sim));
    if (sim.step() % check_every == 0) r.intersecting += count_intersecting_pairs(sim);
  }
  r.intersecting += count_intersecting_pairs(sim);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.collision_seconds = sim.times.collision;
  return r;
}

void print(const char* name, const Simulation& sim, const RunReport& r) {
  std::printf("[ timing ] %s: %d steps, %.3f s total, %.3f s collision (proximity + impact zones), %.3f s physics\n",
              name, sim.step(), r.seconds, sim.times.collision, sim.times.physics);
}

TEST(CollisionScenesSlow, SheetDroppedOnFloorObstacle) {
  const fs::path meshes = project_meshes();
  ASSERT_FALSE(meshes.empty()) << "meshes/square.obj not found";
  // 2 cm above the floor at 2 m/s: it crosses the repulsion layer within one step (impact zones act), then
  // settles.
  Scene scene = base_scene(2e-3, 0.1);
  scene.cloths.push_back(cloth_spec(meshes / "square.obj", make_transform(Vec3(0, 0.02, 0), lay_flat())));
  scene.cloths[0].velocity.linear = Vec3(0, -2, 0);
  scene.obstacles.push_back(obstacle_spec(meshes / "square.obj", make_transform(Vec3(-1, 0, 1), lay_flat(), 3)));
  Simulation sim(scene);
  const RunReport r = run(sim, 10);
  print("sheet on floor obstacle", sim, r);
  EXPECT_GT(r.lowest, -1e-4);
  EXPECT_EQ(r.intersecting, 0);
  // It landed: every node rests within a few repulsion thicknesses of the floor.
  double highest = -kInfinity;
  for (const Node& n : sim.cloths[0].mesh.nodes) highest = std::max(highest, n.x.y());
  EXPECT_LT(highest, 5e-3);
}

TEST(CollisionScenesSlow, SheetDroppedOnFloorProxy) {
  // The floor obstacle is flagged `proxy: "floor"`: the plane y = floor adds a penalty for every cloth node
  // and takes part in CCD.
  const fs::path meshes = project_meshes();
  ASSERT_FALSE(meshes.empty()) << "meshes/square.obj not found";
  Scene scene = base_scene(2e-3, 0.1);
  scene.cloths.push_back(cloth_spec(meshes / "square.obj", make_transform(Vec3(0, 0.02, 0), lay_flat())));
  scene.cloths[0].velocity.linear = Vec3(0.3, -2, 0.2);
  scene.obstacles.push_back(obstacle_spec(meshes / "square.obj", make_transform(Vec3(-1, 0, 1), lay_flat(), 3),
                                          "floor"));
  Simulation sim(scene);
  const RunReport r = run(sim, 10);
  print("sheet on floor proxy", sim, r);
  EXPECT_GT(r.lowest, -1e-4);
  EXPECT_EQ(r.intersecting, 0);
}

// Nodes of one strip that lie within `distance` of a node at least `apart` nodes away along the strip.
int folded_node_pairs(const Mesh& m, double distance, double apart_length) {
  int n = 0;
  for (size_t i = 0; i < m.nodes.size(); ++i)
    for (size_t j = i + 1; j < m.nodes.size(); ++j)
      if ((m.verts[m.nodes[i].verts[0]].u - m.verts[m.nodes[j].verts[0]].u).norm() > apart_length &&
          (m.nodes[i].x - m.nodes[j].x).norm() < distance)
        ++n;
  return n;
}

TEST(CollisionScenesSlow, StripFoldsOntoItselfOnFloor) {
  const fs::path meshes = project_meshes();
  ASSERT_FALSE(meshes.empty()) << "meshes/strip.obj not found";
  Scene scene = base_scene(2e-3, 0.5);
  // The 1 m strip lies flat 5 mm above the floor and spins about its middle: the right half swings up and
  // over and lands on the left half.
  scene.cloths.push_back(cloth_spec(meshes / "strip.obj", make_transform(Vec3(0, 0.005, 0), lay_flat())));
  scene.cloths[0].velocity.angular = Vec3(0, 0, 11);
  scene.cloths[0].velocity.origin = Vec3(0.5, 0.005, 0);
  scene.obstacles.push_back(obstacle_spec(meshes / "square.obj", make_transform(Vec3(-1.5, 0, 1.5), lay_flat(), 3),
                                          "floor"));
  Simulation sim(scene);
  const RunReport r = run(sim, 10);
  print("strip folding on floor", sim, r);
  EXPECT_GT(r.lowest, -1e-4);
  EXPECT_EQ(r.intersecting, 0);
  // Folded: many nodes lie within 4 cm (the mesh spacing is 5 cm) of nodes 30 cm or more away along the strip,
  // one layer resting on the other.
  EXPECT_GT(folded_node_pairs(sim.cloths[0].mesh, 0.04, 0.3), 20);
  double top = -kInfinity;
  for (const Node& n : sim.cloths[0].mesh.nodes) top = std::max(top, n.x.y());
  EXPECT_LT(top, 0.08);
}

TEST(CollisionScenesSlow, SheetFallingOnSphere) {
  const fs::path meshes = project_meshes();
  ASSERT_FALSE(meshes.empty()) << "meshes/square.obj not found";
  TempDir dir;
  const double radius = 0.3;
  const Vec3 center(0.5, 0, -0.5);
  Mesh sphere = make_sphere(radius, 2);
  write_plain_obj(sphere, (dir.path / "sphere.obj").string());
  // Inscribed radius of the polyhedron: the nearest face plane.
  double inscribed = radius;
  for (int f = 0; f < static_cast<int>(sphere.faces.size()); ++f) {
    const auto t = world_triangle(sphere, f);
    inscribed = std::min(inscribed, std::abs((t[1] - t[0]).cross(t[2] - t[0]).normalized().dot(t[0])));
  }
  Scene scene = base_scene(2e-3, 0.15);
  scene.cloths.push_back(cloth_spec(meshes / "square.obj", make_transform(Vec3(0, radius + 0.01, 0), lay_flat())));
  scene.cloths[0].velocity.linear = Vec3(0, -1.5, 0);
  scene.obstacles.push_back(obstacle_spec(dir.path / "sphere.obj", make_transform(center)));
  Simulation sim(scene);
  double closest = kInfinity;
  int intersecting = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (!sim.finished()) {
    sim.advance_step();
    for (const Node& n : sim.cloths[0].mesh.nodes) closest = std::min(closest, (n.x - center).norm());
    if (sim.step() % 10 == 0) intersecting += count_intersecting_pairs(sim);
  }
  RunReport r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  print("sheet on sphere", sim, r);
  EXPECT_EQ(intersecting, 0);
  EXPECT_GT(closest, inscribed - 1e-4);
  // It is draped over the sphere: the middle node rests on top (within a few repulsion thicknesses).
  const Node& middle = sim.cloths[0].mesh.nodes[60];
  EXPECT_NEAR((middle.x - center).norm(), radius, 5e-3);
}

// A 20 cm sheet resting on a plane tilted by `degrees` (obstacle friction mu = 0.5), released at rest just
// inside the repulsion distance. Returns the sheet's mean position along the slope (m) at the given times.
std::vector<double> slide_on_tilted_plane(double degrees, const std::vector<double>& times) {
  TempDir dir;
  const double theta = degrees * M_PI / 180;
  const Vec3 down(std::cos(theta), -std::sin(theta), 0), normal(std::sin(theta), std::cos(theta), 0), side = Vec3::UnitZ();
  // The plane: two triangles spanning 6 m x 6 m; its diagonal runs away from the sheet's path.
  const double L = 3;
  const std::vector<Vec3> corners{-L * down - L * side, L * down - L * side, L * down + L * side, -L * down + L * side};
  std::vector<int> ids{0, 1, 2, 3};
  const Mesh plane = Mesh::from_triangles(corners, corners, ids, {{0, 1, 2}, {0, 2, 3}});
  write_plain_obj(plane, (dir.path / "plane.obj").string());
  // The sheet: 4 x 4 cells placed on the plane at the repulsion thickness (1 mm).
  Mesh sheet = make_grid(4, 4, 0.2, 0.2);
  for (Node& n : sheet.nodes) n.x = n.x.x() * down + (n.x.y() - 0.6) * side + 1e-3 * normal;
  write_obj(sheet, (dir.path / "sheet.obj").string());

  Scene scene = base_scene(4e-3, times.back() + 1e-9);
  scene.obs_friction = 0.5;
  scene.cloths.push_back(cloth_spec(dir.path / "sheet.obj", make_transform(Vec3::Zero())));
  scene.obstacles.push_back(obstacle_spec(dir.path / "plane.obj", make_transform(Vec3::Zero())));
  Simulation sim(scene);
  std::vector<double> along;
  for (double t : times) {
    while (sim.time() < t - 1e-9) sim.advance_step();
    double sum = 0;
    for (const Node& n : sim.cloths[0].mesh.nodes) sum += n.x.dot(down);
    along.push_back(sum / sim.cloths[0].mesh.nodes.size());
  }
  EXPECT_EQ(count_intersecting_pairs(sim), 0);
  return along;
}

TEST(CollisionScenesSlow, FrictionHoldsSheetBelowFrictionAngle) {
  // tan(15 deg) = 0.27 < mu = 0.5: static friction holds the sheet.
  const auto s = slide_on_tilted_plane(15, {0.0, 1.0});
  std::printf("[ result ] drift over 1 s on a 15 degree slope (mu = 0.5): %.3e m\n", std::abs(s[1] - s[0]));
  EXPECT_LT(std::abs(s[1] - s[0]), 1e-3);
}

TEST(CollisionScenesSlow, FrictionSlidingAccelerationAboveFrictionAngle) {
  // tan(40 deg) = 0.84 > mu = 0.5: the sheet slides with a = g (sin t - mu cos t).
  const double theta = 40 * M_PI / 180;
  const double expected = 9.8 * (std::sin(theta) - 0.5 * std::cos(theta));
  const auto s = slide_on_tilted_plane(40, {0.2, 0.4, 0.6});
  const double a = (s[2] - 2 * s[1] + s[0]) / (0.2 * 0.2);
  std::printf("[ result ] sliding acceleration on a 40 degree slope (mu = 0.5): %.4f m/s^2, analytic %.4f\n", a,
              expected);
  EXPECT_NEAR(a, expected, 0.05 * expected);
}

// The floor scene of SheetDroppedOnFloorObstacle with modules switched off.
Simulation floor_scene(const std::set<std::string>& disabled) {
  const fs::path meshes = project_meshes();
  Scene scene = base_scene(2e-3, 0.08);
  scene.cloths.push_back(cloth_spec(meshes / "square.obj", make_transform(Vec3(0, 0.02, 0), lay_flat())));
  scene.cloths[0].velocity.linear = Vec3(0, -2, 0);
  scene.obstacles.push_back(obstacle_spec(meshes / "square.obj", make_transform(Vec3(-1, 0, 1), lay_flat(), 3)));
  scene.disabled.insert(disabled.begin(), disabled.end());
  return Simulation(scene);
}

TEST(CollisionScenesSlow, DisabledModulesAreSkipped) {
  ASSERT_FALSE(project_meshes().empty()) << "meshes/square.obj not found";
  // Both off: the sheet falls through the floor and neither phase runs.
  Simulation none = floor_scene({"proximity", "collision"});
  const RunReport r = run(none, 1000);
  EXPECT_LT(r.lowest, -0.05);  // 2 cm above at 2 m/s: 13 cm below after 0.08 s
  EXPECT_EQ(none.collision_totals().proximities, 0);
  EXPECT_EQ(none.collision_totals().steps, 0);
  // Impact zones alone (no repulsion forces) still keep it above the floor: they resolved impacts, and no
  // proximity contact was made.
  Simulation ccd_only = floor_scene({"proximity"});
  const RunReport c = run(ccd_only, 10);
  EXPECT_GT(c.lowest, -1e-4);
  EXPECT_EQ(c.intersecting, 0);
  EXPECT_GT(ccd_only.collision_totals().impacts, 0);
  EXPECT_GT(ccd_only.collision_totals().zones, 0);
  EXPECT_EQ(ccd_only.collision_totals().proximities, 0);
  // Repulsion alone: at 4 mm per step the sheet crosses the 1 mm repulsion layer within one step, so without
  // the impact zones it ends up under the floor (the repulsion acted, but too late).
  Simulation repulsion_only = floor_scene({"collision"});
  EXPECT_LT(run(repulsion_only, 1000).lowest, -1e-3);
  EXPECT_GT(repulsion_only.collision_totals().proximities, 0);
  EXPECT_EQ(repulsion_only.collision_totals().steps, 0);
}

// A 3 x 3 sheet (20 cm) over a two-triangle floor with the floor proxy, thrown down at 2 m/s from 1 cm.
Scene small_floor_scene(const TempDir& dir) {
  Mesh sheet = make_grid(3, 3, 0.2, 0.2, Diagonal::kAlternating);
  write_obj(sheet, (dir.path / "sheet.obj").string());
  const std::vector<Vec3> corners{{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  const Mesh floor = Mesh::from_triangles(corners, corners, {0, 1, 2, 3}, {{0, 2, 1}, {0, 3, 2}});
  write_plain_obj(floor, (dir.path / "floor.obj").string());
  Scene scene = base_scene(2e-3, 0.04);
  scene.cloths.push_back(cloth_spec(dir.path / "sheet.obj", make_transform(Vec3(-0.1, 0.01, 0.1), lay_flat())));
  scene.cloths[0].velocity.linear = Vec3(0.2, -2, 0);
  scene.obstacles.push_back(obstacle_spec(dir.path / "floor.obj", make_transform(Vec3::Zero()), "floor"));
  return scene;
}

TEST(CollisionScenes, SmallSheetStopsOnFloor) {
  TempDir dir;
  Simulation sim(small_floor_scene(dir));
  const RunReport r = run(sim, 5);
  EXPECT_GT(r.lowest, -1e-4);
  EXPECT_EQ(r.intersecting, 0);
  // Both phases acted: impacts were resolved in zones, and proximity contacts held the sheet afterwards.
  const ImpactZoneTotals& totals = sim.collision_totals();
  EXPECT_GT(totals.impacts, 0);
  EXPECT_GT(totals.zones, 0);
  EXPECT_GT(totals.proximities, 0);
  EXPECT_EQ(totals.unresolved_steps, 0);
  // Without the impact zones it tunnels through (4 mm per step against a 1 mm repulsion layer).
  Scene off = small_floor_scene(dir);
  off.disabled.insert("collision");
  Simulation through(off);
  EXPECT_LT(run(through, 1000).lowest, -1e-3);
}

TEST(CollisionScenes, ModulesOffDoNoCollisionWork) {
  TempDir dir;
  Scene scene = small_floor_scene(dir);
  scene.disabled.insert("collision");
  scene.disabled.insert("proximity");
  Simulation sim(scene);
  const RunReport r = run(sim, 1000);
  EXPECT_LT(r.lowest, -0.05);
  // Neither phase ran: no collision response in any step, no proximity contact.
  EXPECT_EQ(sim.collision_totals().steps, 0);
  EXPECT_EQ(sim.collision_totals().proximities, 0);
}

}  // namespace
}  // namespace arcsim
