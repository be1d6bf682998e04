#include <gtest/gtest.h>

#include <random>

#include "math/errors.hpp"
#include "restshape/reference_surface.hpp"
#include "restshape/surface_fixtures.hpp"
#include "restshape/triangle_geometry.hpp"

namespace arcsim {
namespace {

// Level 4 icosphere: 5120 faces.
struct SphereMesh {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  double radius = 0.7;
  Vec3 center = Vec3(0.3, -1.2, 2.0);
  SphereMesh() { test::icosphere(4, radius, center, points, tris); }
};

TEST(MeshReference, KindAndRejectsEmptyMesh) {
  const SphereMesh s;
  EXPECT_EQ(make_mesh_reference(test::mesh_from_soup(s.points, s.tris))->kind(), "mesh");
  EXPECT_THROW(make_mesh_reference(Mesh()), InputError);
}

TEST(MeshReference, ProjectionsOfPointsNearTheSphereLandOnTheMesh) {
  const SphereMesh s;
  ASSERT_EQ(s.tris.size(), 5120u);
  const auto ref = make_mesh_reference(test::mesh_from_soup(s.points, s.tris));
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int k = 0; k < 300; ++k) {
    const Vec3 n = test::random_unit(rng);
    const Vec3 u = s.center + s.radius * (1 + 0.05 * U(rng)) * n;
    // Along the radial normal, along a tilted direction, and closest point.
    const Vec3 tilted = (n + 0.3 * test::random_unit(rng)).normalized();
    for (const Vec3& p : {ref->project(u, n, kInfinity), ref->project(u, 3 * tilted, kInfinity),
                          ref->closest_point(u)}) {
      const double d = test::distance_if_inside_some_triangle(p, s.points, s.tris, 1e-12);
      ASSERT_LT(d, 1e-12 * s.radius) << "point " << k;
    }
  }
}

TEST(MeshReference, LineProjectionIsTheNearestHitOnEitherSide) {
  const SphereMesh s;
  const auto ref = make_mesh_reference(test::mesh_from_soup(s.points, s.tris));
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> U(-1, 1);
  int behind = 0, ahead = 0, misses = 0;
  for (int k = 0; k < 200; ++k) {
    const Vec3 u = s.center + s.radius * (1 + 0.2 * U(rng)) * test::random_unit(rng);
    const Vec3 d = test::random_unit(rng);
    Vec3 want;
    double t_want;
    if (!test::brute_force_line_hit(u, d, kInfinity, s.points, s.tris, want, t_want)) {
      // The line passes by the sphere: the closest mesh point, found by scanning every triangle.
      ++misses;
      double best = kInfinity;
      for (const auto& f : s.tris) {
        const Vec3 q = closest_point_on_triangle(u, s.points[f[0]], s.points[f[1]], s.points[f[2]]);
        if ((q - u).norm() < best) {
          best = (q - u).norm();
          want = q;
        }
      }
    } else {
      (t_want < 0 ? behind : ahead)++;
    }
    EXPECT_LT((ref->project(u, d, kInfinity) - want).norm(), 1e-10) << k;
    EXPECT_LT((ref->project(u, -2.5 * d, kInfinity) - want).norm(), 1e-10) << k;  // sign and length free
  }
  EXPECT_GT(behind, 20);
  EXPECT_GT(ahead, 20);
  EXPECT_GT(misses, 5);
}

TEST(MeshReference, ConcaveSideFromInsidePicksTheNearHitNotTheFarOne) {
  const SphereMesh s;
  const auto ref = make_mesh_reference(test::mesh_from_soup(s.points, s.tris));
  const Vec3 n = Vec3(1, 2, -0.5).normalized();
  // Inside, 10 % below the surface: the surface along +n is 0.1 R away, along -n 1.9 R away.
  const Vec3 inside = s.center + 0.9 * s.radius * n;
  for (const Vec3& d : {Vec3(n), Vec3(-n)}) {
    const Vec3 p = ref->project(inside, d, kInfinity);
    EXPECT_NEAR((p - s.center).dot(n), s.radius, 0.01 * s.radius);
  }
  // Outside, the nearest hit is behind u along +n.
  const Vec3 outside = s.center + 1.1 * s.radius * n;
  EXPECT_NEAR((ref->project(outside, n, kInfinity) - s.center).dot(n), s.radius, 0.01 * s.radius);
}

TEST(MeshReference, FallsBackToClosestPointWhenTheLineMissesOrTheHitIsTooFar) {
  const SphereMesh s;
  // Open hemisphere z >= centre: the rim is a boundary.
  const auto upper = test::filter_triangles(s.points, s.tris, [&](const Vec3& c) { return c.z() > s.center.z(); });
  const auto ref = make_mesh_reference(test::mesh_from_soup(s.points, upper));
  // Beyond the rim, the vertical line misses entirely: the closest point is on the rim near +x.
  const Vec3 beyond = s.center + Vec3(2 * s.radius, 0, -0.5 * s.radius);
  const Vec3 p = ref->project(beyond, Vec3(0, 0, 1), kInfinity);
  Vec3 brute = ref->closest_point(beyond);
  double best = kInfinity;
  for (const auto& f : upper) {
    const Vec3 q = closest_point_on_triangle(beyond, s.points[f[0]], s.points[f[1]], s.points[f[2]]);
    if ((q - beyond).norm() < best) {
      best = (q - beyond).norm();
      brute = q;
    }
  }
  EXPECT_LT((p - brute).norm(), 1e-12);
  EXPECT_LT((p - (s.center + Vec3(s.radius, 0, 0))).norm(), 0.05 * s.radius);  // on the rim, near +x

  // A line that does hit, but farther than max_distance, also falls back.
  const Vec3 above = s.center + Vec3(0.2 * s.radius, 0, 2 * s.radius);
  const Vec3 hit = ref->project(above, Vec3(0, 0, -1), kInfinity);
  EXPECT_NEAR(hit.z() - s.center.z(), s.radius * std::sqrt(1 - 0.04), 0.01 * s.radius);
  const Vec3 limited = ref->project(above, Vec3(1, 0, -1), 0.1 * s.radius);
  EXPECT_LT((limited - ref->closest_point(above)).norm(), 1e-15);
  // Zero direction: closest point.
  EXPECT_LT((ref->project(above, Vec3::Zero(), kInfinity) - ref->closest_point(above)).norm(), 1e-15);
}

TEST(MeshReference, FlatSheetLinesThroughVerticesAndEdgesHitExactly) {
  // 10 x 10 grid in z = 0 with both diagonal directions present.
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  const int n = 10;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) points.emplace_back(0.1 * i, 0.1 * j, 0);
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if ((i + j) % 2 == 0) {
        tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        tris.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        tris.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  const auto ref = make_mesh_reference(test::mesh_from_soup(points, tris));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0, 1);
  for (int k = 0; k < 2000; ++k) {
    const int i = 1 + static_cast<int>(U(rng) * (n - 2)), j = 1 + static_cast<int>(U(rng) * (n - 2));
    const double s = U(rng);
    const Vec3 base = points[id(i, j)];
    const Vec3 targets[] = {base, base + Vec3(0.1 * s, 0, 0), base + Vec3(0, 0.1 * s, 0),
                            base + Vec3(0.1 * s, 0.1 * s, 0), base + Vec3(0.1 * s, 0.1 * (1 - s), 0)};
    const Vec3& target = targets[k % 5];
    // A slanted line: the closest-point fallback would land elsewhere, so only a real hit passes.
    Vec3 d = test::random_unit(rng);
    if (std::abs(d.z()) < 0.2) d.z() = 0.2;
    const Vec3 u = target + (0.05 + U(rng)) * d;
    EXPECT_LT((ref->project(u, d, kInfinity) - target).norm(), 1e-13) << k;
  }
  // A line lying in the sheet's plane grazes every face: fallback to the closest point, u itself.
  const Vec3 in_plane(0.33, 0.47, 0);
  EXPECT_LT((ref->project(in_plane, Vec3(1, 0.2, 0), kInfinity) - in_plane).norm(), 1e-15);
  // Parallel above the sheet: the closest point below.
  EXPECT_LT((ref->project(Vec3(0.33, 0.47, 0.2), Vec3(1, 0, 0), kInfinity) - in_plane).norm(), 1e-15);
}

TEST(MeshReference, NonFiniteInputsDoNotProduceNaNFromFiniteOnes) {
  const SphereMesh s;
  const auto ref = make_mesh_reference(test::mesh_from_soup(s.points, s.tris));
  const Vec3 u = s.center + Vec3(0, 0, 0.5);
  EXPECT_TRUE(ref->project(u, Vec3(kInfinity, 0, 0), 1).allFinite());
  EXPECT_TRUE(ref->project(u, Vec3(std::nan(""), 0, 0), 1).allFinite());
  EXPECT_TRUE(ref->project(u, Vec3(1, 0, 0), std::nan("")).allFinite());
  EXPECT_TRUE(ref->project(u, Vec3(1, 0, 0), -1).allFinite());
}

}  // namespace
}  // namespace arcsim
