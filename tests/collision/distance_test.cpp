// Closest points of vertex-face, edge-edge and vertex-edge pairs against brute-force minimisation over the
// primitives' parameters (zooming grids), on random and degenerate configurations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>
#include <random>

#include "collision/distance.hpp"

namespace arcsim {
namespace {

Vec3 weighted(const ClosestPoints& c, const std::array<Vec3, 4>& x) {
  return c.weights[0] * x[0] + c.weights[1] * x[1] + c.weights[2] * x[2] + c.weights[3] * x[3];
}

// Minimum of f(a, b) over a parameter domain: a coarse grid, then four zoom levels around the best sample.
// `clamp` maps any (a, b) into the domain (so that boundary minima are sampled exactly).
template <class F, class Clamp>
double grid_minimum(const F& f, const Clamp& clamp) {
  double best = kInfinity, ba = 0, bb = 0;
  double window = 1;
  Vec2 center(0.5, 0.5);
  for (int level = 0; level < 5; ++level) {
    const int n = 40;
    for (int i = -n; i <= n; ++i)
      for (int j = -n; j <= n; ++j) {
        const Vec2 p = clamp(Vec2(center.x() + window * i / n, center.y() + window * j / n));
        const double d = f(p.x(), p.y());
        if (d < best) best = d, ba = p.x(), bb = p.y();
      }
    center = Vec2(ba, bb);
    window /= 10;
  }
  return best;
}

double brute_vertex_face(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return grid_minimum([&](double u, double v) { return (p - (a + u * (b - a) + v * (c - a))).norm(); },
                      [](Vec2 q) {
                        q = q.cwiseMax(0.0);
                        return q.sum() > 1 ? Vec2(q / q.sum()) : q;
                      });
}

double brute_edge_edge(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  return grid_minimum([&](double s, double u) { return ((p0 + s * (p1 - p0)) - (q0 + u * (q1 - q0))).norm(); },
                      [](const Vec2& q) { return Vec2(q.cwiseMax(0.0).cwiseMin(1.0)); });
}

void expect_consistent(const ClosestPoints& c, const std::array<Vec3, 4>& x) {
  EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
  const Vec3 gap = weighted(c, x);
  EXPECT_NEAR(gap.norm(), c.distance, 1e-12);
  if (c.distance > 1e-9) {
    EXPECT_NEAR(c.normal.dot(gap), c.distance, 1e-12);
  }
  double sum = 0;
  for (double w : c.weights) sum += w;
  EXPECT_NEAR(sum, 0.0, 1e-12);  // point minus point
}

TEST(Distance, VertexFaceMatchesBruteForceOnRandomPairs) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int k = 0; k < 30; ++k) {
    const Vec3 p(U(rng), U(rng), U(rng)), a(U(rng), U(rng), U(rng)), b(U(rng), U(rng), U(rng)),
        c(U(rng), U(rng), U(rng));
    const ClosestPoints r = vertex_face_closest(p, a, b, c);
    expect_consistent(r, {p, a, b, c});
    for (int i = 1; i < 4; ++i) EXPECT_LE(r.weights[i], 1e-15);  // barycentrics >= 0
    const double brute = brute_vertex_face(p, a, b, c);
    EXPECT_LE(r.distance, brute + 1e-12) << "case " << k;
    EXPECT_GE(r.distance, brute - 1e-7) << "case " << k;
  }
}

TEST(Distance, VertexFaceRegions) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  // Above the interior: the height, along +z.
  ClosestPoints r = vertex_face_closest(Vec3(0.2, 0.3, 0.5), a, b, c);
  EXPECT_NEAR(r.distance, 0.5, 1e-15);
  EXPECT_TRUE(r.normal.isApprox(Vec3::UnitZ()));
  EXPECT_NEAR(-r.weights[2], 0.2, 1e-15);
  EXPECT_NEAR(-r.weights[3], 0.3, 1e-15);
  // Below: normal -z.
  r = vertex_face_closest(Vec3(0.2, 0.3, -0.5), a, b, c);
  EXPECT_TRUE(r.normal.isApprox(-Vec3::UnitZ()));
  // Beyond vertex b, and beyond the hypotenuse.
  r = vertex_face_closest(Vec3(2, -1, 0), a, b, c);
  EXPECT_NEAR(r.distance, std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(r.weights[2], -1.0, 1e-15);
  r = vertex_face_closest(Vec3(1, 1, 0), a, b, c);
  EXPECT_NEAR(r.distance, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(r.weights[2], -0.5, 1e-15);
  EXPECT_NEAR(r.weights[3], -0.5, 1e-15);
  // On the face: zero distance, the face normal.
  r = vertex_face_closest(Vec3(0.25, 0.25, 0), a, b, c);
  EXPECT_EQ(r.distance, 0.0);
  EXPECT_NEAR(std::abs(r.normal.z()), 1.0, 1e-15);
}

TEST(Distance, DegenerateTriangleUsesItsEdges) {
  // Collinear corners: the nearest point of the segment they span.
  const ClosestPoints r = vertex_face_closest(Vec3(0.5, 1, 0), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0));
  EXPECT_NEAR(r.distance, 1.0, 1e-14);
  EXPECT_TRUE(r.normal.allFinite());
  expect_consistent(r, {Vec3(0.5, 1, 0), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)});
  const ClosestPoints point = vertex_face_closest(Vec3(0, 0, 3), Vec3(1, 1, 1), Vec3(1, 1, 1), Vec3(1, 1, 1));
  EXPECT_NEAR(point.distance, std::sqrt(6.0), 1e-14);
}

TEST(Distance, EdgeEdgeMatchesBruteForceOnRandomPairs) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int k = 0; k < 30; ++k) {
    const Vec3 p0(U(rng), U(rng), U(rng)), p1(U(rng), U(rng), U(rng)), q0(U(rng), U(rng), U(rng)),
        q1(U(rng), U(rng), U(rng));
    const ClosestPoints r = edge_edge_closest(p0, p1, q0, q1);
    expect_consistent(r, {p0, p1, q0, q1});
    const double brute = brute_edge_edge(p0, p1, q0, q1);
    EXPECT_LE(r.distance, brute + 1e-12) << "case " << k;
    EXPECT_GE(r.distance, brute - 1e-7) << "case " << k;
  }
}

TEST(Distance, ParallelAndNearParallelEdges) {
  // Overlapping parallel segments at distance 1.
  ClosestPoints r = edge_edge_closest(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 1, 0), Vec3(3, 1, 0));
  EXPECT_NEAR(r.distance, 1.0, 1e-14);
  expect_consistent(r, {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 1, 0), Vec3(3, 1, 0)});
  // Disjoint collinear-direction segments: end points.
  r = edge_edge_closest(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(3, 1, 0), Vec3(4, 1, 0));
  EXPECT_NEAR(r.distance, std::sqrt(5.0), 1e-14);
  // Nearly parallel (1e-10 rad), overlapping.
  const double e = 1e-10;
  r = edge_edge_closest(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.2, 0.5, 0), Vec3(1.2, 0.5 + e, 0));
  EXPECT_NEAR(r.distance, 0.5, 1e-9);
  const double brute = brute_edge_edge(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.2, 0.5, 0), Vec3(1.2, 0.5 + e, 0));
  EXPECT_NEAR(r.distance, brute, 1e-9);
  // Zero-length edges: point-point and point-segment.
  r = edge_edge_closest(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(1, 1, 1));
  EXPECT_NEAR(r.distance, std::sqrt(3.0), 1e-14);
  r = edge_edge_closest(Vec3(0.5, 2, 0), Vec3(0.5, 2, 0), Vec3(0, 0, 0), Vec3(1, 0, 0));
  EXPECT_NEAR(r.distance, 2.0, 1e-14);
  // Crossing segments touch: the normal is along the cross product.
  r = edge_edge_closest(Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0, 1, 0));
  EXPECT_EQ(r.distance, 0.0);
  EXPECT_NEAR(std::abs(r.normal.z()), 1.0, 1e-15);
}

TEST(Distance, VertexEdge) {
  ClosestPoints r = vertex_edge_closest(Vec3(0.3, 2, 0), Vec3(0, 0, 0), Vec3(1, 0, 0));
  EXPECT_NEAR(r.distance, 2.0, 1e-15);
  EXPECT_NEAR(r.weights[1], -0.7, 1e-15);
  EXPECT_NEAR(r.weights[2], -0.3, 1e-15);
  EXPECT_TRUE(r.normal.isApprox(Vec3::UnitY()));
  r = vertex_edge_closest(Vec3(-1, 0, 0), Vec3(0, 0, 0), Vec3(1, 0, 0));
  EXPECT_NEAR(r.distance, 1.0, 1e-15);
  EXPECT_EQ(r.weights[2], 0.0);
}

TEST(Distance, VertexEdgeMatchesBruteForceOnRandomAndDegeneratePairs) {
  // Brute force: the segment parameter on a zooming grid (the second grid parameter is unused).
  auto brute = [](const Vec3& p, const Vec3& a, const Vec3& b) {
    return grid_minimum([&](double s, double) { return (p - (a + s * (b - a))).norm(); },
                        [](const Vec2& q) { return Vec2(std::clamp(q.x(), 0.0, 1.0), 0.0); });
  };
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> U(-1, 1);
  std::vector<std::array<Vec3, 3>> cases;
  for (int k = 0; k < 30; ++k) cases.push_back({Vec3(U(rng), U(rng), U(rng)), Vec3(U(rng), U(rng), U(rng)),
                                                Vec3(U(rng), U(rng), U(rng))});
  // Degenerate: vertex on the segment, on its line beyond an end, zero-length segment, vertex at an end.
  cases.push_back({Vec3(0.25, 0.5, 0), Vec3(0, 0, 0), Vec3(0.5, 1, 0)});
  cases.push_back({Vec3(2, 4, 0), Vec3(0, 0, 0), Vec3(0.5, 1, 0)});
  cases.push_back({Vec3(1, 2, 3), Vec3(0.5, 0.5, 0.5), Vec3(0.5, 0.5, 0.5)});
  cases.push_back({Vec3(0.5, 1, 0), Vec3(0, 0, 0), Vec3(0.5, 1, 0)});
  for (size_t k = 0; k < cases.size(); ++k) {
    const auto& [p, a, b] = cases[k];
    const ClosestPoints r = vertex_edge_closest(p, a, b);
    expect_consistent(r, {p, a, b, Vec3::Zero()});
    EXPECT_EQ(r.weights[3], 0.0);
    const double expected = brute(p, a, b);
    EXPECT_LE(r.distance, expected + 1e-12) << "case " << k;
    EXPECT_GE(r.distance, expected - 1e-7) << "case " << k;
  }
}

}  // namespace
}  // namespace arcsim
