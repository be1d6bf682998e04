// Triangle-triangle separation (used by the remeshing guard) against the exact intersection test and a sampled
// distance: zero exactly when the triangles cross, else the true distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "collision/distance.hpp"
#include "collision/triangle_intersection.hpp"

namespace arcsim {
namespace {

// Distance between the triangles from dense barycentric samples of both (an upper bound of the true distance,
// tight for these sample counts up to a few percent of the triangle size).
double sampled_distance(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b) {
  const int n = 24;
  std::vector<Vec3> pa, pb;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const double s = double(i) / n, t = double(j) / n;
      pa.push_back(a[0] + s * (a[1] - a[0]) + t * (a[2] - a[0]));
      pb.push_back(b[0] + s * (b[1] - b[0]) + t * (b[2] - b[0]));
    }
  double best = kInfinity;
  for (const Vec3& p : pa)
    best = std::min(best, vertex_face_closest(p, b[0], b[1], b[2]).distance);
  for (const Vec3& p : pb)
    best = std::min(best, vertex_face_closest(p, a[0], a[1], a[2]).distance);
  return best;
}

TEST(TriangleSeparation, ZeroExactlyWhenCrossingElseTheDistance) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  auto random_triangle = [&](double spread) {
    std::array<Vec3, 3> t;
    const Vec3 c(u(rng), u(rng), u(rng));
    for (Vec3& p : t) p = c * spread + Vec3(u(rng), u(rng), u(rng));
    return t;
  };
  int crossing = 0, apart = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const std::array<Vec3, 3> a = random_triangle(0.7), b = random_triangle(0.7);
    const double d = triangle_separation(a, b);
    if (triangles_intersect(a, b)) {
      ++crossing;
      EXPECT_EQ(d, 0) << "trial " << trial;
    } else {
      ++apart;
      EXPECT_GT(d, 0) << "trial " << trial;
      // The sampled distance is never below the true one; the vertex-face and edge-edge candidates contain it.
      const double sampled = sampled_distance(a, b);
      EXPECT_LE(d, sampled + 1e-12) << "trial " << trial;
      EXPECT_GT(d, sampled - 0.05) << "trial " << trial;
    }
  }
  EXPECT_GT(crossing, 100);
  EXPECT_GT(apart, 100);
}

TEST(TriangleSeparation, EdgePiercingTheInteriorIsZero) {
  // Neither a vertex nor an edge of either triangle comes near the other's vertices or edges.
  const std::array<Vec3, 3> a{Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(0, 1, 0)};
  const std::array<Vec3, 3> b{Vec3(0, 0, -1), Vec3(0, 0, 1), Vec3(5, 0, 0.3)};
  EXPECT_EQ(triangle_separation(a, b), 0);
  EXPECT_EQ(triangle_separation(b, a), 0);
  // Lifted just above: the distance is the lift.
  std::array<Vec3, 3> c = b;
  for (Vec3& p : c) p.z() += 1.25;
  c[2].z() = 0.25 + 1.25;
  EXPECT_NEAR(triangle_separation(a, c), 0.25, 1e-12);
}

TEST(TriangleSeparation, ParallelLayers) {
  const std::array<Vec3, 3> a{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const std::array<Vec3, 3> b{Vec3(0.1, 0.1, 1e-4), Vec3(0.9, 0.05, 1e-4), Vec3(0.05, 0.8, 1e-4)};
  EXPECT_NEAR(triangle_separation(a, b), 1e-4, 1e-15);
}

}  // namespace
}  // namespace arcsim
