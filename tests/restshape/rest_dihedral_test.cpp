#include <gtest/gtest.h>

#include <random>

#include "restshape/reference_surface.hpp"
#include "restshape/surface_fixtures.hpp"

namespace arcsim {
namespace {

TEST(RestDihedral, CylinderMeshReferenceGivesTheChordAngleWithTheMeshSignConvention) {
  // 48 segments: neighbouring vertices around the axis are 2 pi / 48 apart; a chord hinge along the axis
  // with wings m segments to either side bends by exactly m * 2 pi / 48 (exterior angle of the chord polygon).
  const int segments = 48;
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  const double R = 0.4, H = 1.0;
  test::cylinder(segments, 8, R, H, points, tris);
  const auto ref = make_mesh_reference(test::mesh_from_soup(points, tris));
  auto on_cylinder = [&](int k, double z, double lift) {
    const double phi = 2 * test::kPi * k / segments;
    return Vec3((R + lift) * std::cos(phi), (R + lift) * std::sin(phi), z);
  };
  for (int m = 1; m <= 6; ++m)
    for (int k = 0; k < segments; k += 7) {
      // Hinge a -> b along +z at angle k; c at k - m, d at k + m: faces (a, b, c) and (b, a, d) face outward.
      // The points start slightly off the surface (radially out, where the closest point is the
      // polygon's vertex line) to exercise the projection.
      const Vec3 a = on_cylinder(k, 0.25, 1e-3), b = on_cylinder(k, 0.75, 1e-3);
      const Vec3 c = on_cylinder(k - m + segments, 0.5, 2e-3), d = on_cylinder(k + m, 0.5, 1.5e-3);
      const double want = m * 2 * test::kPi / segments;
      EXPECT_NEAR(ref->rest_dihedral(a, b, c, d), want, 1e-12) << m << " " << k;
      // Same points with the wings swapped: the faces now face the axis, the sheet bends the other way.
      EXPECT_NEAR(ref->rest_dihedral(a, b, d, c), -want, 1e-12);
      // Agreement with mesh.hpp's convention on the on-surface points.
      EXPECT_NEAR(ref->rest_dihedral(a, b, c, d),
                  dihedral_angle(on_cylinder(k, 0.25, 0), on_cylinder(k, 0.75, 0), on_cylinder(k - m, 0.5, 0),
                                 on_cylinder(k + m, 0.5, 0)),
                  1e-12);
    }
}

// Circumcentre of a triangle: the planes of triangles inscribed in a sphere are perpendicular to the
// directions from the centre to their circumcentres, so the chord dihedral is the angle between those.
Vec3 circumcenter(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, n = ab.cross(ac);
  return a + (ac.squaredNorm() * n.cross(ab) + ab.squaredNorm() * ac.cross(n)) / (2 * n.squaredNorm());
}

TEST(RestDihedral, SphereReferenceGivesTheAngleBetweenInscribedTrianglePlanes) {
  const Vec3 center(0.2, -0.1, 0.4);
  const double R = 0.8;
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  test::icosphere(3, R, center, points, tris);
  const auto sphere = make_sphere_reference(points);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> U(-1, 1);
  int positive = 0, negative = 0;
  for (int k = 0; k < 200; ++k) {
    // A small quad in the tangent plane at p (off the sphere by up to h^2 / 2R), faces oriented outward.
    const Vec3 n = test::random_unit(rng);
    const Vec3 t1 = n.cross(test::random_unit(rng)).normalized(), t2 = n.cross(t1);
    const double h = 0.05 + 0.2 * std::abs(U(rng));
    const Vec3 p = center + R * n;
    const Vec3 a = p - h * t1 + 0.2 * h * U(rng) * t2, b = p + h * t1 + 0.2 * h * U(rng) * t2;
    const Vec3 c = p + h * (1 + 0.5 * U(rng)) * t2 + 0.3 * h * U(rng) * t1;
    const Vec3 d = p - h * (1 + 0.5 * U(rng)) * t2 + 0.3 * h * U(rng) * t1;
    auto radial = [&](const Vec3& x) { return Vec3(center + R * (x - center).normalized()); };
    const Vec3 A = radial(a), B = radial(b), C = radial(c), D = radial(d);
    const Vec3 oc1 = (circumcenter(A, B, C) - center).normalized();
    const Vec3 oc2 = (circumcenter(B, A, D) - center).normalized();
    // Outward plane normals of the two chords, signed about the hinge direction like dihedral_angle. Four
    // points on a sphere can bend either way (zero when they lie on one circle), so both signs occur.
    const double want = std::atan2(oc1.cross(oc2).dot((B - A).normalized()), oc1.dot(oc2));
    (want > 0 ? positive : negative)++;
    EXPECT_NEAR(sphere->rest_dihedral(a, b, c, d), want, 1e-9) << k;
  }
  EXPECT_GT(positive, 20);
  EXPECT_GT(negative, 20);
}

TEST(RestDihedral, MeshReferenceMatchesTheRestMeshsOwnEdgeAngles) {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  test::icosphere(2, 1.3, Vec3(1, 1, 1), points, tris);
  const Mesh mesh = test::mesh_from_soup(points, tris);
  const auto ref = make_mesh_reference(mesh);
  int checked = 0;
  for (size_t e = 0; e < mesh.edges.size(); ++e) {
    const Edge& edge = mesh.edges[e];
    if (edge.is_boundary()) continue;
    const Vec3& a = mesh.nodes[edge.n[0]].x;
    const Vec3& b = mesh.nodes[edge.n[1]].x;
    const Vec3& c = mesh.nodes[mesh.opposite_node(static_cast<int>(e), edge.f[0])].x;
    const Vec3& d = mesh.nodes[mesh.opposite_node(static_cast<int>(e), edge.f[1])].x;
    const double theta = ref->rest_dihedral(a, b, c, d);
    EXPECT_NEAR(theta, mesh.rest_dihedral(static_cast<int>(e)), 1e-12);
    EXPECT_GT(theta, 0);  // outward-oriented convex surface
    ++checked;
  }
  EXPECT_EQ(checked, 480);
}

}  // namespace
}  // namespace arcsim
