// Adaptivity in whole simulations (paper §5.1, issue 4 acceptance 3): the sizing refines where the sheet bends
// and leaves flat parts coarse. A sheet draped over a sphere and a flag in wind, started from coarse uniform
// meshes, with remeshing at every frame end.
//
// What is measured does not come from the sizing: each face's curvature is estimated from the world shape as the
// mean, over its edge neighbours, of the angle between the two face normals divided by the distance between the
// face centroids (1/m; the same for fine and coarse faces on a surface of given curvature). The most curved
// quarter of the faces must have much shorter edges than the flattest quarter. A uniform mesh fails this.
#include <gtest/gtest.h>

#include <unistd.h>

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
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "arcsim-adaptivity-tests";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / (name + "-" + std::to_string(::getpid()) + ".obj")).string();
  write_plain_obj(mesh, path);
  return path;
}

struct CurvatureClasses {
  double curved_edge = 0, flat_edge = 0;  // mean world edge length (m) of the most curved / flattest quarter
  double curved_kappa = 0, flat_kappa = 0;  // mean curvature estimate (1/m) of each quarter
};

CurvatureClasses classify_faces(const Mesh& m) {
  std::vector<std::pair<double, double>> faces;  // (curvature estimate, mean edge length)
  for (size_t f = 0; f < m.faces.size(); ++f) {
    const Face& face = m.faces[f];
    if (face.dead) continue;
    const int fi = static_cast<int>(f);
    auto centroid = [&](int g) {
      return (m.nodes[m.face_node(g, 0)].x + m.nodes[m.face_node(g, 1)].x + m.nodes[m.face_node(g, 2)].x) / 3;
    };
    double kappa = 0, length = 0;
    int neighbours = 0;
    for (int i = 0; i < 3; ++i) {
      length += (m.nodes[m.face_node(fi, (i + 1) % 3)].x - m.nodes[m.face_node(fi, i)].x).norm() / 3;
      const int g = m.other_face(face.e[i], fi);
      if (g == kNone) continue;
      const double cos_angle = std::clamp(m.world_normal(fi).dot(m.world_normal(g)), -1.0, 1.0);
      kappa += std::acos(cos_angle) / (centroid(fi) - centroid(g)).norm();
      ++neighbours;
    }
    if (neighbours > 0) faces.emplace_back(kappa / neighbours, length);
  }
  std::sort(faces.begin(), faces.end());
  CurvatureClasses c;
  const size_t quarter = faces.size() / 4;
  for (size_t i = 0; i < quarter; ++i) {
    c.flat_kappa += faces[i].first / quarter;
    c.flat_edge += faces[i].second / quarter;
    c.curved_kappa += faces[faces.size() - 1 - i].first / quarter;
    c.curved_edge += faces[faces.size() - 1 - i].second / quarter;
  }
  return c;
}

Material stiff_fabric() {
  // 1 mm, 20 MPa, bending stiffness ~2e-3 N m: folds of a few cm, not fine crumples.
  Material m = cotton();
  m.thickness = 1e-3;
  m.youngs_modulus = 2e7;
  return m;
}

Scene base_scene(const std::string& cloth_mesh, Material m, double refine_angle, double size_min,
                 double size_max) {
  Scene scene;
  scene.path = "adaptivity-test.json";
  scene.frame_time = 0.02;
  scene.frame_steps = 4;
  scene.step_time = scene.frame_time / scene.frame_steps;
  ClothSpec cloth;
  cloth.mesh = cloth_mesh;
  m.damping = 1e-3;
  cloth.materials = {m};
  cloth.remeshing.refine_angle = refine_angle;
  cloth.remeshing.size_min = size_min;
  cloth.remeshing.size_max = size_max;
  cloth.remeshing.aspect_min = 0.2;
  cloth.remeshing.has_size = cloth.remeshing.has_aspect_min = true;
  scene.cloths.push_back(cloth);
  scene.disabled = {"plasticity", "fracture"};
  return scene;
}

// A 0.6 m square sheet (0.1 m cells) falls 1 cm onto a sphere of radius 0.12 m and drapes over it for 0.4 s.
// Where it lies on the sphere it bends with curvature 1 / R, so refine_angle asks for edges of about
// refine_angle R = 3.6 cm there; the hanging skirt bends at its folds.
TEST(Adaptivity, SheetDrapedOverASphereIsFinerWhereItBends) {
  const double R = 0.12, refine_angle = 0.3;
  Mesh ball = make_icosphere(R, 3);
  const std::string sheet_path = temp_obj(testing::make_grid(6, 6, 0.6, 0.6), "drape-sheet");
  const std::string ball_path = temp_obj(ball, "drape-ball");
  Scene scene = base_scene(sheet_path, stiff_fabric(), refine_angle, 0.015, 0.2);
  scene.cloths[0].transform.translation = Vec3(-0.3, -0.3, R + 0.01);
  ObstacleSpec obstacle;
  obstacle.mesh = ball_path;
  scene.obstacles.push_back(obstacle);
  scene.gravity = Vec3(0, 0, -9.8);
  scene.magic.repulsion_thickness = 5e-3;
  Simulation sim(scene);
  const int input_faces = live_faces(sim.cloths[0].mesh);
  for (int frame = 0; frame < 15; ++frame) {
    sim.advance_frame();
    ASSERT_EQ(check_mesh(sim.cloths[0].mesh), "") << "frame " << frame;
  }
  const Mesh& m = sim.cloths[0].mesh;
  // On the sphere: nodes within 2 cm of its surface on its upper half.
  std::vector<double> cap_lengths;
  for (const Edge& e : m.edges) {
    const Vec3 mid = 0.5 * (m.nodes[e.n[0]].x + m.nodes[e.n[1]].x);
    if (std::abs(mid.norm() - R) < 0.02 && mid.z() > 0.5 * R)
      cap_lengths.push_back((m.nodes[e.n[1]].x - m.nodes[e.n[0]].x).norm());
  }
  ASSERT_GT(cap_lengths.size(), 20u) << "the sheet does not lie on the sphere";
  std::sort(cap_lengths.begin(), cap_lengths.end());
  const double cap_median = cap_lengths[cap_lengths.size() / 2];
  const CurvatureClasses c = classify_faces(m);
  std::printf("drape: %d -> %d faces; on the sphere median edge %.4f m; most curved quarter %.2f 1/m, edges "
              "%.4f m; flattest quarter %.2f 1/m, edges %.4f m\n",
              input_faces, live_faces(m), cap_median, c.curved_kappa, c.curved_edge, c.flat_kappa, c.flat_edge);
  EXPECT_GT(live_faces(m), 3 * input_faces);
  EXPECT_LT(cap_median, 1.5 * refine_angle * R);  // 10 cm input edges refined to the curvature there
  EXPECT_GT(c.curved_kappa, 4 * c.flat_kappa);
  EXPECT_LT(c.curved_edge, 0.6 * c.flat_edge);
  std::filesystem::remove(sheet_path);
  std::filesystem::remove(ball_path);
}

// A 0.6 m x 0.4 m flag held at the two nodes of its left edge, in a 10 m/s wind along it with gravity across
// (ARCSim's flag scene, smaller and shorter; turned 30 degrees about the pole, so that the wind meets it at an
// angle): the wind raises waves, and the mesh refines at them.
TEST(AdaptivitySlow, FlagInWindRefinesAtItsWaves) {  // ~3 s optimised: not in the sanitizer run
  const double refine_angle = 0.1;  // the waves are gentle (a few 1/m): ask for a few cm at them
  const std::string flag_path = temp_obj(testing::make_grid(6, 4, 0.6, 0.4), "flag");
  Scene scene = base_scene(flag_path, cotton(), refine_angle, 0.01, 0.2);
  scene.cloths[0].transform.rotation = Transform::rotation_from_degrees(30, Vec3::UnitY());
  scene.gravity = Vec3(0, -9.8, 0);
  scene.wind.velocity = Vec3(10, 0, 0);
  scene.wind.density = 1;
  HandleSpec pole;
  pole.nodes = {0, 4 * 7};  // (0, 0) and (0, 0.4) of the 7 x 5 node grid
  scene.handles.push_back(pole);
  Simulation sim(scene);
  const int input_faces = live_faces(sim.cloths[0].mesh);
  for (int frame = 0; frame < 50; ++frame) {
    sim.advance_frame();
    ASSERT_EQ(check_mesh(sim.cloths[0].mesh), "") << "frame " << frame;
  }
  const Mesh& m = sim.cloths[0].mesh;
  const CurvatureClasses c = classify_faces(m);
  std::printf("flag: %d -> %d faces; most curved quarter %.2f 1/m, edges %.4f m; flattest quarter %.2f 1/m, "
              "edges %.4f m\n",
              input_faces, live_faces(m), c.curved_kappa, c.curved_edge, c.flat_kappa, c.flat_edge);
  EXPECT_GT(live_faces(m), 2 * input_faces);
  EXPECT_GT(c.curved_kappa, 4 * c.flat_kappa) << "no waves";
  EXPECT_LT(c.curved_edge, 0.6 * c.flat_edge);
}

}  // namespace
}  // namespace arcsim
