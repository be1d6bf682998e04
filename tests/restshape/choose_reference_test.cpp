#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <unistd.h>

#include "math/errors.hpp"
#include "restshape/reference_surface.hpp"
#include "restshape/sphere_fit.hpp"
#include "restshape/surface_fixtures.hpp"

namespace arcsim {
namespace {

// A flat n x n sheet in an arbitrary (rotated, shifted) plane, optionally bent about its middle line.
Mesh sheet(int n, double bend_angle, const Transform& placement = Transform()) {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      Vec3 p(double(i) / n, double(j) / n, 0);
      if (i > n / 2) {  // fold the right half up by bend_angle about x = 0.5
        const double r = p.x() - 0.5;
        p = Vec3(0.5 + r * std::cos(bend_angle), p.y(), r * std::sin(bend_angle));
      }
      points.push_back(placement.apply(p));
    }
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return test::mesh_from_soup(points, tris);
}

Transform tilted_placement() {
  Transform t;
  t.translation = Vec3(3, -1, 2);
  t.scale = 0.7;
  t.rotation = Transform::rotation_from_degrees(37, Vec3(1, 2, 3));
  return t;
}

TEST(RestShapeIsCurved, FlatSheetsInAnyPlaneAreFlatBentOnesAreNot) {
  EXPECT_FALSE(rest_shape_is_curved(sheet(6, 0)));
  EXPECT_FALSE(rest_shape_is_curved(sheet(6, 0, tilted_placement())));
  EXPECT_TRUE(rest_shape_is_curved(sheet(6, 1e-4, tilted_placement())));
  EXPECT_TRUE(rest_shape_is_curved(sheet(6, 1e-5)));
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  test::icosphere(1, 1, Vec3::Zero(), points, tris);
  EXPECT_TRUE(rest_shape_is_curved(test::mesh_from_soup(points, tris)));
  // Two parallel flat pieces at different heights: every normal agrees, but the verts are not coplanar.
  const std::vector<Vec3> steps = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
  EXPECT_TRUE(rest_shape_is_curved(test::mesh_from_soup(steps, {{0, 1, 2}, {3, 4, 5}})));
}

TEST(ChooseReference, LinearOrDefaultIsLinearForFlatAndMeshForCurvedRestShapes) {
  const Transform none;
  EXPECT_EQ(choose_reference("linear", sheet(4, 0, tilted_placement()), none, "s.json")->kind(), "linear");
  EXPECT_EQ(choose_reference("", sheet(4, 0), none, "s.json")->kind(), "linear");
  const Mesh bent = sheet(4, 0.3);
  const auto ref = choose_reference("linear", bent, none, "s.json");
  EXPECT_EQ(ref->kind(), "mesh");
  // It is the cloth's own rest surface: a point on the folded half projects onto that half.
  const Vec3 on_fold = Vec3(0.5 + 0.25 * std::cos(0.3), 0.5, 0.25 * std::sin(0.3));
  const Vec3 off = on_fold + 0.05 * Vec3(-std::sin(0.3), 0, std::cos(0.3));
  EXPECT_LT((ref->closest_point(off) - on_fold).norm(), 1e-12);
}

TEST(ChooseReference, SphereFitsTheRestVertsAndRejectsAFlatSheet) {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  test::icosphere(2, 0.3, Vec3(0, 0.3001, 0), points, tris);
  const auto ref = choose_reference("sphere", test::mesh_from_soup(points, tris), Transform(), "s.json");
  EXPECT_EQ(ref->kind(), "sphere");
  EXPECT_NEAR((ref->closest_point(Vec3(0, 2, 0)) - Vec3(0, 0.3001, 0)).norm(), 0.3, 1e-3);
  try {
    choose_reference("sphere", sheet(4, 0), Transform(), "scene.json: cloths[0].reference");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("scene.json: cloths[0].reference", 0), 0u) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos);
  }
}

class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() /
            ("arcsim-restshape-" + std::to_string(std::random_device()()) + "-" + std::to_string(::getpid()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

TEST(ChooseReference, MeshPathLoadsTheObjPlacedWithTheClothTransform) {
  const TempDir dir;
  const std::string path = dir.file("roof.obj");
  {
    // A roof: two unit squares meeting at the ridge x = 0 (z = 0.5), sloping down to z = 0 at x = +-1.
    std::ofstream out(path);
    out << "v -1 0 0\nv 0 0 0.5\nv 1 0 0\nv -1 1 0\nv 0 1 0.5\nv 1 1 0\n"
           "f 1 2 5\nf 1 5 4\nf 2 3 6\nf 2 6 5\n";
  }
  Transform placement;
  placement.scale = 2;
  placement.translation = Vec3(0, 0, 10);
  const auto ref = choose_reference(path, sheet(2, 0), placement, "s.json: cloths[0].reference");
  EXPECT_EQ(ref->kind(), "mesh");
  // Placed roof: ridge z = 11 at x = 0, eaves z = 10 at x = +-2, y in [0, 2]. Vertical line through
  // (0.5, 1): z = 11 - 0.5 / 2 on the right slope.
  EXPECT_LT((ref->project(Vec3(0.5, 1, 0), Vec3(0, 0, 1), kInfinity) - Vec3(0.5, 1, 10.75)).norm(), 1e-12);

  EXPECT_THROW(choose_reference(dir.file("missing.obj"), sheet(2, 0), placement, "s.json"), InputError);
  {
    std::ofstream out(dir.file("empty.obj"));
    out << "v 0 0 0\n";
  }
  try {
    choose_reference(dir.file("empty.obj"), sheet(2, 0), placement, "s.json: cloths[1].reference");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("empty.obj"), std::string::npos) << what;
    EXPECT_NE(what.find("cloths[1]"), std::string::npos) << what;
  }
}

TEST(ReprojectRestPositions, SphereMovesRestAndWorldOntoTheFittedSphereAndUpdatesRestData) {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  test::icosphere(2, 1.0, Vec3(0.1, 0.2, 0.3), points, tris);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> U(-1, 1);
  const Vec3 c(0.1, 0.2, 0.3);
  for (Vec3& p : points) p = c + (1 + 0.05 * U(rng)) * (p - c);  // +-5 % radial noise
  Mesh mesh = test::mesh_from_soup(points, tris);
  mesh.edges[7].rest_theta += 0.25;  // a plastic offset that must survive
  const auto ref = choose_reference("sphere", mesh, Transform(), "s.json");
  reproject_rest_positions(mesh, *ref);
  Sphere fitted;  // the fit itself is tested in sphere_reference_test.cpp
  ASSERT_TRUE(fit_sphere(points, fitted));
  const Vec3 center = fitted.center;
  const double radius = fitted.radius;
  for (const Vert& v : mesh.verts) {
    EXPECT_NEAR((v.u - center).norm(), radius, 1e-12);
    EXPECT_EQ(mesh.nodes[v.node].x, v.u);
    EXPECT_EQ(mesh.nodes[v.node].x0, v.u);
  }
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Face& face = mesh.faces[f];
    const Vec3 &a = mesh.verts[face.v[0]].u, &b = mesh.verts[face.v[1]].u, &cc = mesh.verts[face.v[2]].u;
    EXPECT_NEAR(face.rest_area, 0.5 * (b - a).cross(cc - a).norm(), 1e-15);
  }
  for (size_t e = 0; e < mesh.edges.size(); ++e)
    EXPECT_NEAR(mesh.edges[e].rest_theta, mesh.rest_dihedral(static_cast<int>(e)) + (e == 7 ? 0.25 : 0), 1e-12);
}

TEST(ReprojectRestPositions, LeavesLinearAndMeshReferencesAlone) {
  Mesh mesh = sheet(3, 0.4);
  mesh.nodes[2].x += Vec3(0, 0, 1);
  const Mesh before = mesh;
  reproject_rest_positions(mesh, *make_linear_reference());
  reproject_rest_positions(mesh, *make_mesh_reference(mesh));
  for (size_t v = 0; v < mesh.verts.size(); ++v) EXPECT_EQ(mesh.verts[v].u, before.verts[v].u);
  for (size_t n = 0; n < mesh.nodes.size(); ++n) EXPECT_EQ(mesh.nodes[n].x, before.nodes[n].x);
}

}  // namespace
}  // namespace arcsim
