#include "restshape/triangle_geometry.hpp"

#include <gtest/gtest.h>

#include <random>

#include "restshape/surface_fixtures.hpp"

namespace arcsim {
namespace {

// Reference closest point without Voronoi regions: the plane projection if it is inside, else the nearest of
// the three edges' closest points.
Vec3 reference_closest(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (n2 > 1e-20 * (b - a).squaredNorm() * (c - a).squaredNorm()) {
    const Vec3 q = p - n * (n.dot(p - a) / n2);
    const double wa = (b - q).cross(c - q).dot(n), wb = (c - q).cross(a - q).dot(n),
                 wc = (a - q).cross(b - q).dot(n);
    if (wa >= 0 && wb >= 0 && wc >= 0) return q;
  }
  Vec3 best = a;
  for (const auto& [s, e] : {std::pair<Vec3, Vec3>{a, b}, {b, c}, {c, a}}) {
    const Vec3 q = closest_point_on_segment(p, s, e);
    if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
  }
  return best;
}

TEST(ClosestPointOnTriangle, EverySevenRegionsOfAUnitTriangle) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  struct Case {
    Vec3 p, expected;
  };
  const Case cases[] = {
      {{-1, -1, 5}, a},                    // corner a
      {{2, -1, 3}, b},                     // corner b
      {{-1, 3, -2}, c},                    // corner c
      {{0.5, -1, 1}, {0.5, 0, 0}},         // edge ab
      {{-2, 0.25, 1}, {0, 0.25, 0}},       // edge ca
      {{1, 1, 2}, {0.5, 0.5, 0}},          // edge bc
      {{0.2, 0.3, -7}, {0.2, 0.3, 0}},     // interior
  };
  for (const Case& k : cases)
    EXPECT_LT((closest_point_on_triangle(k.p, a, b, c) - k.expected).norm(), 1e-15) << k.p.transpose();
}

TEST(ClosestPointOnTriangle, MatchesPlaneOrEdgeReferenceForRandomTriangles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec3 a(U(rng), U(rng), U(rng)), b(U(rng), U(rng), U(rng)), c(U(rng), U(rng), U(rng));
    const Vec3 p = 3 * Vec3(U(rng), U(rng), U(rng));
    const Vec3 got = closest_point_on_triangle(p, a, b, c);
    const Vec3 want = reference_closest(p, a, b, c);
    ASSERT_NEAR((got - p).norm(), (want - p).norm(), 1e-12) << trial;
    ASSERT_LT((got - want).norm(), 1e-9) << trial;
  }
}

TEST(ClosestPointOnTriangle, DegenerateTrianglesGiveTheClosestEdgePoint) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 a(U(rng), U(rng), U(rng)), b(U(rng), U(rng), U(rng));
    const Vec3 p = 2 * Vec3(U(rng), U(rng), U(rng));
    // Collinear corners, two coincident corners, all coincident.
    const Vec3 on_line = a + U(rng) * 2 * (b - a);
    const Vec3 got_line = closest_point_on_triangle(p, a, b, on_line);
    const Vec3 hull_lo = on_line.dot(b - a) < a.dot(b - a) ? on_line : a;
    const Vec3 hull_hi = on_line.dot(b - a) > b.dot(b - a) ? on_line : b;
    ASSERT_TRUE(got_line.allFinite());
    ASSERT_LT((got_line - closest_point_on_segment(p, hull_lo, hull_hi)).norm(), 1e-12) << trial;
    ASSERT_LT((closest_point_on_triangle(p, a, b, b) - closest_point_on_segment(p, a, b)).norm(), 1e-12);
    ASSERT_EQ(closest_point_on_triangle(p, a, a, a), a);
  }
}

// A tilted, rotated triangulated sheet: corner coordinates are inexact in every axis.
struct TiltedGrid {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  int n = 12;
  Vec3 at(double i, double j) const {
    const Vec3 e1 = Vec3(1, 0.3, 0.7).normalized();
    const Vec3 e2 = e1.cross(Vec3(0.2, 1, -0.4)).normalized();
    return Vec3(0.1, -0.2, 0.3) + 0.37 * (i * e1 + j * e2);
  }
  TiltedGrid() {
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) points.push_back(at(i, j));
    auto id = [&](int i, int j) { return j * (n + 1) + i; };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
  }
};

TEST(LineCaster, LinesThroughSharedVerticesAndEdgesNeverSlipThrough) {
  const TiltedGrid grid;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(0, 1);
  int lines = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    // Interior vertex, point on an axis edge, or point on a diagonal edge.
    const int i = 1 + static_cast<int>(U(rng) * (grid.n - 2)), j = 1 + static_cast<int>(U(rng) * (grid.n - 2));
    const double s = U(rng);
    Vec3 target;
    switch (trial % 3) {
      case 0: target = grid.points[j * (grid.n + 1) + i]; break;
      case 1: target = (1 - s) * grid.at(i, j) + s * grid.at(i + 1, j); break;
      default: target = (1 - s) * grid.at(i, j) + s * grid.at(i + 1, j + 1); break;
    }
    const Vec3 direction = test::random_unit(rng);
    const Vec3 origin = target - (0.5 + U(rng)) * direction;
    const LineCaster line(origin, direction);
    int hits = 0;
    for (const auto& f : grid.tris) {
      LineCaster::Hit hit;
      if (!line.intersect(grid.points[f[0]], grid.points[f[1]], grid.points[f[2]], hit)) continue;
      ++hits;
      EXPECT_LT((hit.point - target).norm(), 1e-9) << trial;
      EXPECT_LT((origin + hit.t * direction - target).norm(), 1e-9) << trial;
    }
    // Grazing lines (almost in the sheet's plane) may legitimately miss; all others must hit.
    const Vec3 normal = (grid.at(1, 0) - grid.at(0, 0)).cross(grid.at(0, 1) - grid.at(0, 0)).normalized();
    if (std::abs(direction.dot(normal)) > 1e-6) {
      EXPECT_GE(hits, 1) << "line slipped through at trial " << trial;
      ++lines;
    }
  }
  EXPECT_GT(lines, 2900);
}

TEST(LineCaster, ExactlyRepresentableLinesThroughVerticesAndEdgesHitAtLeastOneTriangle) {
  // Integer grid and directions whose shear factors are powers of two: every edge function is computed
  // exactly, so lines through vertices and edges give exact zeros, the case a non-watertight test drops.
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> tris;
  const int n = 4;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) points.emplace_back(i, j, 0);
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  for (const Vec3& d : {Vec3(1, 2, -4), Vec3(-2, 1, 4), Vec3(0, 0, 1), Vec3(0.5, -0.25, -1)})
    for (double y = 1; y <= 3; y += 0.5)
      for (double x = 1; x <= 3; x += 0.5) {
        const Vec3 target(x, y, 0);
        const LineCaster line(target - 2 * d, d);
        int hits = 0;
        for (const auto& f : tris) {
          LineCaster::Hit hit;
          if (!line.intersect(points[f[0]], points[f[1]], points[f[2]], hit)) continue;
          ++hits;
          EXPECT_EQ(hit.point, target);
          EXPECT_EQ(hit.t, 2);
        }
        EXPECT_GE(hits, 1) << "through " << target.transpose() << " along " << d.transpose();
      }
}

TEST(LineCaster, ReportsHitsBehindTheOriginWithNegativeParameter) {
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  LineCaster::Hit hit;
  ASSERT_TRUE(LineCaster(Vec3(0.5, 0.5, 3), Vec3(0, 0, 2)).intersect(a, b, c, hit));
  EXPECT_NEAR(hit.t, -1.5, 1e-15);
  EXPECT_LT((hit.point - Vec3(0.5, 0.5, 0)).norm(), 1e-15);
  ASSERT_TRUE(LineCaster(Vec3(0.5, 0.5, -3), Vec3(0, 0, 2)).intersect(a, c, b, hit));  // either winding
  EXPECT_NEAR(hit.t, 1.5, 1e-15);
  EXPECT_FALSE(LineCaster(Vec3(1.5, 1.5, -3), Vec3(0, 0, 1)).intersect(a, b, c, hit));  // beyond edge bc
}

TEST(LineCaster, GrazingLinesInOrParallelToThePlaneMiss) {
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  LineCaster::Hit hit;
  EXPECT_FALSE(LineCaster(Vec3(-1, 0.5, 0), Vec3(1, 0, 0)).intersect(a, b, c, hit));
  EXPECT_FALSE(LineCaster(Vec3(-1, 0.5, 1e-3), Vec3(1, 0.1, 0)).intersect(a, b, c, hit));
}

TEST(LineCaster, ClipsToBoxesIncludingAxisParallelLinesOnAFace) {
  const Vec3 lo(0, 0, 0), hi(1, 2, 3);
  double t0, t1;
  ASSERT_TRUE(LineCaster(Vec3(0.5, 1, -1), Vec3(0, 0, 1)).clip_to_box(lo, hi, t0, t1));
  EXPECT_DOUBLE_EQ(t0, 1);
  EXPECT_DOUBLE_EQ(t1, 4);
  ASSERT_TRUE(LineCaster(Vec3(1, 1, -1), Vec3(0, 0, -2)).clip_to_box(lo, hi, t0, t1));  // on the x = 1 face
  EXPECT_DOUBLE_EQ(t0, -2);
  EXPECT_DOUBLE_EQ(t1, -0.5);
  EXPECT_FALSE(LineCaster(Vec3(1.5, 1, -1), Vec3(0, 0, 1)).clip_to_box(lo, hi, t0, t1));
  EXPECT_FALSE(LineCaster(Vec3(2, 0, 0), Vec3(1, 1, 0)).clip_to_box(lo, hi, t0, t1));
}

}  // namespace
}  // namespace arcsim
