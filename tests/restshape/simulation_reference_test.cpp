// The reference surface chosen when a Simulation loads ARCSim scenes (sim/simulation.cpp load_cloth). Skipped
// when the shared ARCSim scenes are absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "io/scene_parser.hpp"
#include "restshape/sphere_fit.hpp"
#include "sim/simulation.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

fs::path arcsim_scenes() {
  const char* env = std::getenv("ARCSIM_SHARED");
  return fs::path(env && *env ? env : "/work/shared") / "arcsim-0.3-scenes";
}

#define REQUIRE_ARCSIM_SCENES()                                                 \
  do {                                                                          \
    if (!fs::is_directory(arcsim_scenes() / "conf"))                            \
      GTEST_SKIP() << "ARCSim example scenes not found at " << arcsim_scenes(); \
  } while (0)

Simulation load(const std::string& name) { return Simulation(load_scene((arcsim_scenes() / "conf" / name).string())); }

TEST(SimulationReference, SphereBreakPutsRestAndWorldShapesOnTheFittedSphere) {
  REQUIRE_ARCSIM_SCENES();
  // The loaded input, before the start-up remesh (tested below) changes its triangles.
  Scene scene = load_scene((arcsim_scenes() / "conf" / "sphere-break.json").string());
  scene.magic.remesh_at_start = false;
  const Simulation sim(scene);
  const Cloth& cloth = sim.cloths[0];
  ASSERT_TRUE(cloth.reference);
  EXPECT_EQ(cloth.reference->kind(), "sphere");
  const Mesh& mesh = cloth.mesh;
  std::vector<Vec3> u;
  for (const Vert& v : mesh.verts) u.push_back(v.u);
  Sphere s;
  ASSERT_TRUE(fit_sphere(u, s));
  // sphere2.obj has radius ~1 with +-5 % noise (its centre is a few % off the origin), scaled by 0.3 and
  // lifted by 0.3001.
  EXPECT_NEAR(s.radius, 0.3, 0.01);
  EXPECT_NEAR(s.center.y(), 0.3001, 0.03);
  for (const Vert& v : mesh.verts) {
    EXPECT_NEAR((v.u - s.center).norm(), s.radius, 1e-12);
    EXPECT_EQ(mesh.nodes[v.node].x, v.u);
  }
  // The curved rest shape is the bending rest state: every edge's rest angle is its rest dihedral, nonzero.
  for (size_t e = 0; e < mesh.edges.size(); ++e) {
    EXPECT_NEAR(mesh.edges[e].rest_theta, mesh.rest_dihedral(static_cast<int>(e)), 1e-12);
    EXPECT_GT(std::abs(mesh.edges[e].rest_theta), 1e-3);
  }
}

// ARCSim's start-up remesh of the sphere at rest: new and moved verts stay on the fitted sphere in the rest
// shape, and the world shape stays the rest shape (the sheet is at rest, so nothing may strain it).
TEST(SimulationReference, SphereBreakStartUpRemeshKeepsTheRestShapeOnTheSphere) {
  REQUIRE_ARCSIM_SCENES();
  Scene loaded_scene = load_scene((arcsim_scenes() / "conf" / "sphere-break.json").string());
  loaded_scene.magic.remesh_at_start = false;
  const Simulation loaded(loaded_scene);
  const Simulation sim = load("sphere-break.json");
  const Mesh& mesh = sim.cloths[0].mesh;
  EXPECT_NE(mesh.faces.size(), loaded.cloths[0].mesh.faces.size()) << "the start-up remesh edited the sphere";
  std::vector<Vec3> u;
  for (const Vert& v : loaded.cloths[0].mesh.verts) u.push_back(v.u);
  Sphere s;
  ASSERT_TRUE(fit_sphere(u, s));
  double worst_rest = 0, worst_world = 0;
  for (const Vert& v : mesh.verts) {
    worst_rest = std::max(worst_rest, std::abs((v.u - s.center).norm() - s.radius));
    worst_world = std::max(worst_world, (mesh.nodes[v.node].x - v.u).norm());
  }
  std::printf("start-up remesh: %zu -> %zu faces; rest off the sphere %.3g m, world off rest %.3g m\n",
              loaded.cloths[0].mesh.faces.size(), mesh.faces.size(), worst_rest, worst_world);
  EXPECT_LT(worst_rest, 1e-12);
  EXPECT_LT(worst_world, 1e-8);  // 1e-9 measured
}

TEST(SimulationReference, FlatSheetsGetTheLinearReference) {
  REQUIRE_ARCSIM_SCENES();
  for (const char* scene : {"paper-tearing.json", "tshirt.json", "square.json"}) {
    const Simulation sim = load(scene);
    for (const Cloth& cloth : sim.cloths) {
      ASSERT_TRUE(cloth.reference) << scene;
      EXPECT_EQ(cloth.reference->kind(), "linear") << scene;
    }
  }
}

TEST(SimulationReference, CurvedClothWithoutAReferenceKeyGetsTheMeshReference) {
  REQUIRE_ARCSIM_SCENES();
  const fs::path dir = fs::temp_directory_path() / ("arcsim-restshape-sim-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  {
    std::ofstream obj(dir / "roof.obj");
    obj << "v -1 0 0\nv 0 0 0.5\nv 1 0 0\nv -1 1 0\nv 0 1 0.5\nv 1 1 0\nf 1 2 5\nf 1 5 4\nf 2 3 6\nf 2 6 5\n";
    std::ofstream scene(dir / "scene.json");
    scene << R"({"frame_time": 0.04, "frame_steps": 1, "end_time": 1, "cloths": [{"mesh": "roof.obj",
      "transform": {"scale": 2, "translate": [0, 0, 10]},
      "materials": [{"data": ")"
          << (arcsim_scenes() / "materials" / "gray-interlock.json").string() << R"("}],
      "remeshing": {"refine_angle": 0.3, "refine_compression": 0.01, "refine_velocity": 1,
                    "size": [0.01, 0.2], "aspect_min": 0.2}}]})";
  }
  const Simulation sim(load_scene((dir / "scene.json").string()));
  fs::remove_all(dir);
  const Cloth& cloth = sim.cloths[0];
  ASSERT_TRUE(cloth.reference);
  EXPECT_EQ(cloth.reference->kind(), "mesh");
  // The reference is the scaled rest roof (rest coordinates are scaled, not translated): ridge at z = 1.
  EXPECT_LT((cloth.reference->project(Vec3(0.5, 1, 0), Vec3(0, 0, 1), kInfinity) - Vec3(0.5, 1, 0.75)).norm(),
            1e-12);
}

}  // namespace
}  // namespace arcsim
