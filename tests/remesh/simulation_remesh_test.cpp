// Remeshing inside the simulation loop (frame ends, facts §2.2 step 10): a stiff curved shell at rest stays at
// rest through refinement and coarsening every frame, handles survive and keep their anchors, the fixed
// high-resolution mode refines once, and the per-frame mesh statistics.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include <filesystem>

#include "io/obj.hpp"
#include "mesh/validate.hpp"
#include "remesh/remesh_fixtures.hpp"
#include "sim/remesh_cloth.hpp"
#include "sim/simulation.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using namespace remesh_test;

std::string temp_obj(const Mesh& mesh, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "arcsim-remesh-tests";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / (name + "-" + std::to_string(::getpid()) + ".obj")).string();
  write_plain_obj(mesh, path);
  return path;
}

Scene scene_with(const std::string& mesh_path, const Material& material) {
  Scene scene;
  scene.path = "test-scene.json";
  scene.frame_time = 1e-3;
  scene.frame_steps = 1;
  scene.step_time = 1e-3;
  ClothSpec cloth;
  cloth.mesh = mesh_path;
  cloth.materials = {material};
  cloth.remeshing.refine_angle = kInfinity;
  cloth.remeshing.refine_compression = kInfinity;
  cloth.remeshing.aspect_min = 0.3;
  cloth.remeshing.has_size = cloth.remeshing.has_aspect_min = cloth.remeshing.has_refine_compression = true;
  scene.cloths.push_back(cloth);
  scene.wind.density = 0;
  return scene;
}

double kinetic_energy(const Mesh& m) {
  double e = 0;
  for (const Node& n : m.nodes) e += 0.5 * n.mass * n.v.squaredNorm();
  return e;
}

// A glass hemisphere (E 50 GPa, 2 mm, no gravity), curved rest shape = its world shape, remeshed every frame
// with the target size alternating between 2 cm and 4 cm: splits and collapses every frame, yet no stress
// appears, so it stays at rest; every node (world) and vert (rest) stays on the input surface (within its chord
// sag). `frames` frames of 1 ms.
void check_glass_hemisphere_at_rest(int frames) {
  const double R = 0.1;
  const int rings = 4;
  const std::string path = temp_obj(make_hemisphere(R, rings), "hemisphere");
  Scene scene = scene_with(path, glass());
  // The start-up remesh (magic.remesh_at_start) sizes the input at 4 cm, the size the odd frames return to.
  scene.cloths[0].remeshing.size_min = scene.cloths[0].remeshing.size_max = 0.04;
  Simulation sim(scene);
  Cloth& cloth = sim.cloths[0];
  ASSERT_NE(cloth.reference, nullptr);
  EXPECT_EQ(cloth.reference->kind(), "mesh");
  // Deepest point of the input triangles below the sphere: R minus the distance of a face's plane from the
  // centre, over the faces (the chord sag of the input mesh).
  double sag = 0;
  for (size_t f = 0; f < cloth.mesh.faces.size(); ++f) {
    const Vec3& a = cloth.mesh.nodes[cloth.mesh.face_node(static_cast<int>(f), 0)].x;
    sag = std::max(sag, R - std::abs(cloth.mesh.world_normal(static_cast<int>(f)).dot(a)));
  }
  sag *= 1.001;
  std::vector<int> faces;
  double max_kinetic = 0;
  for (int frame = 0; frame < frames; ++frame) {
    const double size = frame % 2 == 0 ? 0.02 : 0.04;
    cloth.remeshing.size_min = cloth.remeshing.size_max = size;
    sim.advance_frame();
    faces.push_back(live_faces(cloth.mesh));
    // The frame-end pass did the edits the size asks for: splits when refining to 2 cm (from the coarse input
    // or from 4 cm), collapses when coarsening back to 4 cm.
    ASSERT_EQ(sim.remesh_stats.size(), 1u) << "frame " << frame;
    if (size < 0.03)
      EXPECT_GT(sim.remesh_stats[0].splits, 0) << "frame " << frame;
    else
      EXPECT_GT(sim.remesh_stats[0].collapses, 0) << "frame " << frame;
    ASSERT_EQ(check_mesh(cloth.mesh), "") << "frame " << frame;
    ASSERT_EQ(inverted_face(cloth.mesh, [](const Vec3& c) { return c; }), "") << "frame " << frame;
    max_kinetic = std::max(max_kinetic, kinetic_energy(cloth.mesh));
    for (const Node& n : cloth.mesh.nodes) {
      const double below = R - n.x.norm();
      ASSERT_GT(below, -1e-9) << "frame " << frame;
      ASSERT_LT(below, sag) << "frame " << frame;
    }
    for (const Vert& v : cloth.mesh.verts) {
      const double below = R - v.u.norm();
      ASSERT_GT(below, -1e-9) << "frame " << frame;
      ASSERT_LT(below, sag) << "frame " << frame;
    }
  }
  std::printf("%d frames: faces %d to %d, largest kinetic energy %.3g J\n", frames,
              *std::min_element(faces.begin(), faces.end()), *std::max_element(faces.begin(), faces.end()),
              max_kinetic);
  EXPECT_LT(max_kinetic, 1e-9);
  // Refined and coarsened: the face count alternates.
  for (size_t f = 1; f < faces.size(); ++f) EXPECT_NE(faces[f], faces[f - 1]) << f;
  EXPECT_GT(*std::max_element(faces.begin(), faces.end()), 2 * *std::min_element(faces.begin(), faces.end()));
  std::filesystem::remove(path);
}

TEST(SimulationRemesh, GlassHemisphereStaysAtRest) { check_glass_hemisphere_at_rest(16); }
TEST(SimulationRemeshSlowCheck, GlassHemisphereStaysAtRestFor200Frames) { check_glass_hemisphere_at_rest(200); }

// A cloth hanging from two corner handles under gravity, remeshed every frame: the handle nodes survive (they
// are preserved), their indices are remapped through the compaction, and they stay at their anchors.
TEST(SimulationRemesh, HandlesSurviveRemeshing) {
  const std::string path = temp_obj(testing::make_grid(4, 4, 0.5, 0.5), "sheet");
  Scene scene = scene_with(path, cotton());
  scene.cloths[0].remeshing.size_min = 0.02;
  scene.cloths[0].remeshing.size_max = 0.1;
  scene.cloths[0].remeshing.refine_angle = 0.3;
  scene.cloths[0].remeshing.refine_compression = 1e-2;
  scene.gravity = Vec3(0, 0, -9.8);
  scene.step_time = scene.frame_time = 5e-3;
  HandleSpec corners;
  corners.nodes = {20, 24};  // the top corners of the 5 x 5 node grid
  scene.handles.push_back(corners);
  Simulation sim(scene);
  const std::vector<Vec3> anchors = sim.handles[0].anchors;
  for (int frame = 0; frame < 12; ++frame) {
    sim.advance_frame();
    const Mesh& m = sim.cloths[0].mesh;
    ASSERT_EQ(check_mesh(m), "") << frame;
    ASSERT_EQ(sim.handles[0].nodes.size(), 2u);
    for (size_t i = 0; i < 2; ++i) {
      const Node& n = m.nodes[sim.handles[0].nodes[i]];
      EXPECT_TRUE(n.preserve);
      EXPECT_LT((n.x - anchors[i]).norm(), 0.01) << "frame " << frame;  // springs of 1e3 N/m hold it closely
    }
  }
  EXPECT_GT(live_faces(sim.cloths[0].mesh), 32);  // the hanging, bending sheet was refined
  ASSERT_EQ(sim.remesh_stats.size(), 1u);
}

// A sheet clamped along its whole top edge, hanging under gravity and refined below the clamp's spacing: the
// nodes that splits add between clamped nodes join the clamp (preserved, anchored where they lie on the line),
// so that the edge stays clamped along its length instead of being held at its original nodes only. Loose
// nodes between held ones made every held node a point load: a notched sheet pulled apart by two clamped
// borders tore along them before it tore at its notch (conf/demo.json).
void expect_top_edge_clamped(const Simulation& sim, double top, int least_nodes, const std::string& when) {
  SCOPED_TRACE(when);
  const Mesh& m = sim.cloths[0].mesh;
  const Handle& clamp = sim.handles[0];
  ASSERT_EQ(clamp.nodes.size(), clamp.anchors.size());
  int on_line = 0;
  for (size_t n = 0; n < m.nodes.size(); ++n) {
    if (m.nodes[n].dead) continue;
    const Vec3& u = m.verts[m.nodes[n].verts[0]].u;
    if (std::abs(u.y() - top) > 1e-12) continue;
    ++on_line;
    const auto held = std::find(clamp.nodes.begin(), clamp.nodes.end(), static_cast<int>(n));
    ASSERT_NE(held, clamp.nodes.end()) << "node " << n << " at x = " << u.x() << " on the clamped edge is loose";
    EXPECT_TRUE(m.nodes[n].preserve);
    // Flat and static: a node's anchor is its rest position.
    EXPECT_LT((clamp.anchors[held - clamp.nodes.begin()] - u).norm(), 1e-12) << "node " << n;
    EXPECT_LT((m.nodes[n].x - u).norm(), 0.01) << "node " << n;
  }
  EXPECT_EQ(on_line, static_cast<int>(clamp.nodes.size()));
  EXPECT_GE(on_line, least_nodes);
}

TEST(SimulationRemesh, AClampedEdgeStaysClampedWhereRefinementAddsNodes) {
  // The top row of the 5 x 5 node grid (y = 0.5) carries label 1; the handle chooses it by label.
  Mesh grid = testing::make_grid(4, 4, 0.5, 0.5);
  for (int n = 20; n <= 24; ++n) grid.nodes[n].label = 1;
  const std::string path = temp_obj(grid, "clamped");
  write_obj(grid, path);  // with its labels
  Scene scene = scene_with(path, cotton());
  scene.cloths[0].remeshing.size_min = 0.02;
  scene.cloths[0].remeshing.size_max = 0.06;  // the clamp's 0.125 m spacing is split at least twice
  scene.gravity = Vec3(0, 0, -9.8);
  scene.step_time = scene.frame_time = 5e-3;
  HandleSpec top;
  top.label = 1;
  scene.handles.push_back(top);
  Simulation sim(scene);
  for (int frame = 0; frame < 6; ++frame) {
    sim.advance_frame();
    ASSERT_EQ(check_mesh(sim.cloths[0].mesh), "") << frame;
    expect_top_edge_clamped(sim, 0.5, 17, "frame " + std::to_string(frame));
  }

  // The same at the one refinement of ARCSim's fixed high-resolution mode.
  scene.magic.fixed_high_res_mesh = true;
  Simulation fixed(scene);
  expect_top_edge_clamped(fixed, 0.5, 17, "fixed_high_res_mesh");
}

// A handle given as a node list holds exactly those nodes, as in ARCSim: the nodes refinement adds between them
// stay free.
TEST(SimulationRemesh, ANodeListHandleHoldsOnlyItsNodes) {
  const std::string path = temp_obj(testing::make_grid(4, 4, 0.5, 0.5), "listed");
  Scene scene = scene_with(path, cotton());
  scene.cloths[0].remeshing.size_min = 0.02;
  scene.cloths[0].remeshing.size_max = 0.06;
  scene.gravity = Vec3(0, 0, -9.8);
  scene.step_time = scene.frame_time = 5e-3;
  HandleSpec top;
  top.nodes = {20, 21, 22, 23, 24};
  scene.handles.push_back(top);
  Simulation sim(scene);
  for (int frame = 0; frame < 3; ++frame) sim.advance_frame();
  EXPECT_GT(live_faces(sim.cloths[0].mesh), 32);  // refined
  EXPECT_EQ(sim.handles[0].nodes.size(), 5u);
}

TEST(SimulationRemesh, FixedHighResMeshRefinesOnceAtStart) {
  const std::string path = temp_obj(testing::make_grid(2, 2, 0.2, 0.2), "fixed");
  Scene scene = scene_with(path, cotton());
  scene.cloths[0].remeshing.size_min = 0.03;
  scene.cloths[0].remeshing.size_max = 0.5;
  scene.magic.fixed_high_res_mesh = true;
  scene.gravity = Vec3(0, 0, -9.8);
  Simulation sim(scene);
  const Mesh& m = sim.cloths[0].mesh;
  EXPECT_TRUE(m.is_compact());
  EXPECT_EQ(check_mesh(m), "");
  const MeshSizeStats s = mesh_size_stats(m);
  EXPECT_LE(s.rest_edge_max, 0.03 * (1 + 1e-9));
  EXPECT_GT(s.faces, 8 * 8);
  for (int frame = 0; frame < 3; ++frame) sim.advance_frame();
  EXPECT_EQ(mesh_size_stats(sim.cloths[0].mesh).faces, s.faces);  // no remeshing afterwards
}

TEST(SimulationRemesh, MeshSizeStats) {
  const Mesh m = testing::make_grid(2, 1, 2.0, 1.0);  // unit squares, diagonals sqrt(2)
  const MeshSizeStats s = mesh_size_stats(m);
  EXPECT_EQ(s.faces, 4);
  EXPECT_EQ(s.nodes, 6);
  EXPECT_EQ(s.edges, 9);  // 7 axis edges (length 1) and 2 diagonals
  EXPECT_DOUBLE_EQ(s.edge_min, 1);
  EXPECT_DOUBLE_EQ(s.edge_median, 1);
  EXPECT_DOUBLE_EQ(s.edge_max, std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(s.rest_edge_max, std::sqrt(2.0));
}

}  // namespace
}  // namespace arcsim
