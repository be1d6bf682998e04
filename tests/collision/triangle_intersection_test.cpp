// The exact triangle-triangle intersection test (collision/triangle_intersection.hpp).
#include <gtest/gtest.h>

#include <random>

#include "collision/triangle_intersection.hpp"

namespace arcsim::testing {
namespace {

using Tri = std::array<Vec3, 3>;

TEST(TriangleIntersection, Orient3dSignsIncludingNearDegenerate) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_EQ(orient3d(a, b, c, Vec3(0.2, 0.2, -1)), 1);
  EXPECT_EQ(orient3d(a, b, c, Vec3(0.2, 0.2, 1)), -1);
  EXPECT_EQ(orient3d(a, b, c, Vec3(0.2, 0.2, 0)), 0);
  // Far from the origin, a hair off the plane: the floating-point determinant is all rounding noise.
  const Vec3 o(1e6, 1e6, 1e6);
  EXPECT_EQ(orient3d(o + a, o + b, o + c, o + Vec3(0.3, 0.3, 0)), 0);
  EXPECT_EQ(orient3d(o + a, o + b, o + c, Vec3(1e6 + 0.3, 1e6 + 0.3, std::nextafter(1e6, 2e6))), -1);
  EXPECT_EQ(orient3d(o + a, o + b, o + c, Vec3(1e6 + 0.3, 1e6 + 0.3, std::nextafter(1e6, 0.0))), 1);
}

TEST(TriangleIntersection, BasicConfigurations) {
  const Tri t{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  // Piercing, separated, touching at a vertex, coplanar overlapping, coplanar disjoint.
  EXPECT_TRUE(triangles_intersect(t, {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(2, 2, 0.5)}));
  EXPECT_FALSE(triangles_intersect(t, {Vec3(0.2, 0.2, 0.1), Vec3(0.3, 0.2, 1), Vec3(2, 2, 0.5)}));
  EXPECT_TRUE(triangles_intersect(t, {Vec3(0.2, 0.2, 0), Vec3(0.3, 0.2, 1), Vec3(2, 2, 0.5)}));
  EXPECT_TRUE(triangles_intersect(t, {Vec3(0.2, 0.2, 0), Vec3(2, 0.2, 0), Vec3(0.2, 2, 0)}));
  EXPECT_FALSE(triangles_intersect(t, {Vec3(1, 1, 0), Vec3(2, 1, 0), Vec3(1, 2, 0)}));
  // Coplanar, one inside the other without edge crossings.
  EXPECT_TRUE(triangles_intersect(t, {Vec3(0.1, 0.1, 0), Vec3(0.2, 0.1, 0), Vec3(0.1, 0.2, 0)}));
  // An edge lying in the other's plane, crossing it.
  EXPECT_TRUE(triangles_intersect(t, {Vec3(-1, 0.3, 0), Vec3(1, 0.3, 0), Vec3(0, 0.3, 1)}));
  // Parallel planes 1e-12 apart.
  EXPECT_FALSE(triangles_intersect(t, {Vec3(0.1, 0.1, 1e-12), Vec3(2, 0.1, 1e-12), Vec3(0.1, 2, 1e-12)}));
}

TEST(TriangleIntersection, AgreesWithSegmentSamplingOnRandomPairs) {
  // Independent check: sample points of each triangle's edges against the other's closed triangle via
  // barycentric solves; only clear cases (well separated or deeply crossing) are compared.
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> U(-1, 1);
  int hits = 0, misses = 0;
  for (int k = 0; k < 800; ++k) {
    Tri s, t;
    for (auto& p : s) p = Vec3(U(rng), U(rng), U(rng));
    for (auto& p : t) p = Vec3(U(rng), U(rng), U(rng));
    // Reference: t's plane cuts s in a segment; intersect when that segment overlaps t (in the plane).
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    std::vector<Vec3> cut;
    for (int e = 0; e < 3; ++e) {
      const double da = n.dot(s[e] - t[0]), db = n.dot(s[(e + 1) % 3] - t[0]);
      if ((da < 0) != (db < 0)) cut.push_back(s[e] + da / (da - db) * (s[(e + 1) % 3] - s[e]));
    }
    if (cut.size() != 2) {
      EXPECT_FALSE(triangles_intersect(s, t));
      ++misses;
      continue;
    }
    // Sample the cut segment; inside t if all barycentrics >= 0.
    bool inside = false;
    double margin = kInfinity;
    for (int i = 0; i <= 400; ++i) {
      const Vec3 p = cut[0] + (cut[1] - cut[0]) * (i / 400.0);
      const Vec3 v0 = t[1] - t[0], v1 = t[2] - t[0], v2 = p - t[0];
      const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
      const double den = d00 * d11 - d01 * d01;
      const double b1 = (d11 * d20 - d01 * d21) / den, b2 = (d00 * d21 - d01 * d20) / den, b0 = 1 - b1 - b2;
      const double m = std::min({b0, b1, b2});
      margin = std::min(margin, std::abs(m));
      inside = inside || m >= 0;
    }
    if (margin < 1e-3) continue;  // grazing: not a clear case for sampling
    EXPECT_EQ(triangles_intersect(s, t), inside) << "pair " << k;
    inside ? ++hits : ++misses;
  }
  EXPECT_GT(hits, 20);
  EXPECT_GT(misses, 200);
}

}  // namespace
}  // namespace arcsim::testing
