#include <gtest/gtest.h>

#include <random>

#include "math/errors.hpp"
#include "restshape/reference_surface.hpp"
#include "restshape/sphere_fit.hpp"
#include "restshape/surface_fixtures.hpp"

namespace arcsim {
namespace {

std::vector<Vec3> noisy_sphere(const Vec3& center, double radius, double noise, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i) points.push_back(center + radius * (1 + noise * U(rng)) * test::random_unit(rng));
  return points;
}

TEST(SphereFit, RecoversAnExactSphereToRounding) {
  const Vec3 c(10, -20, 30);  // far from the origin: the centred normal equations must stay accurate
  Sphere s;
  ASSERT_TRUE(fit_sphere(noisy_sphere(c, 0.3, 0, 200, 1), s));
  EXPECT_LT((s.center - c).norm(), 1e-12);
  EXPECT_NEAR(s.radius, 0.3, 1e-12);
}

TEST(SphereFit, RecoversANoisySpheresCentreAndRadius) {
  // Like ARCSim's sphere2.obj: radius 1 with +-5 % radial noise.
  const Vec3 c(0.5, 0.3001, -0.2);
  Sphere s;
  ASSERT_TRUE(fit_sphere(noisy_sphere(c, 1.0, 0.05, 2000, 2), s));
  // Uniform radial noise of half-width 5 %: RMS distance is sqrt(1 + 0.05^2 / 3) ~ 1.0004.
  EXPECT_LT((s.center - c).norm(), 5e-3);
  EXPECT_NEAR(s.radius, std::sqrt(1 + 0.05 * 0.05 / 3), 2e-3);
}

TEST(SphereFit, MatchesTheAllPairsCriterionOnASmallCloud) {
  // Direct minimisation of sum over pairs (|p_i - c|^2 - |p_j - c|^2)^2 by its 3x3 normal equations.
  const auto points = noisy_sphere(Vec3(1, 2, 3), 2, 0.2, 30, 3);
  Mat3 A = Mat3::Zero();
  Vec3 b = Vec3::Zero();
  for (size_t i = 0; i < points.size(); ++i)
    for (size_t j = i + 1; j < points.size(); ++j) {
      const Vec3 d = points[i] - points[j];
      const double r = points[i].squaredNorm() - points[j].squaredNorm();
      A += 4 * d * d.transpose();
      b += 2 * r * d;
    }
  const Vec3 center = A.ldlt().solve(b);
  Sphere s;
  ASSERT_TRUE(fit_sphere(points, s));
  EXPECT_LT((s.center - center).norm(), 1e-10);
}

TEST(SphereFit, RejectsTooFewCoplanarOrNonFinitePoints) {
  Sphere s;
  EXPECT_FALSE(fit_sphere({Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}, s));
  std::vector<Vec3> flat;
  for (int i = 0; i < 50; ++i) flat.emplace_back(std::cos(i), std::sin(i * 1.3), 0);
  EXPECT_FALSE(fit_sphere(flat, s));
  auto bad = noisy_sphere(Vec3::Zero(), 1, 0, 20, 4);
  bad[3].x() = std::nan("");
  EXPECT_FALSE(fit_sphere(bad, s));
  EXPECT_THROW(make_sphere_reference(flat), InputError);
}

TEST(SphereReference, ProjectsAlongTheLineToTheNearestOfTheTwoHits) {
  const Vec3 c(0.1, 0.2, 0.3);
  const double R = 0.5;
  const auto ref = make_sphere_reference(noisy_sphere(c, R, 0, 100, 5));
  EXPECT_EQ(ref->kind(), "sphere");
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int k = 0; k < 1000; ++k) {
    const Vec3 u = c + R * (1 + 0.3 * U(rng)) * test::random_unit(rng);
    const Vec3 d = test::random_unit(rng);
    // Both intersections from the quadratic, the nearer in |s| expected.
    const Vec3 w = u - c;
    const double b = w.dot(d), disc = b * b - (w.squaredNorm() - R * R);
    const Vec3 p = ref->project(u, 2 * d, kInfinity);
    EXPECT_NEAR((p - c).norm(), R, 1e-15 * 4);
    if (disc < 0) {
      EXPECT_LT((p - (c + R * w.normalized())).norm(), 1e-14);  // miss: radial closest point
      continue;
    }
    const double s1 = -b - std::sqrt(disc), s2 = -b + std::sqrt(disc);
    const double s = std::abs(s1) < std::abs(s2) ? s1 : s2;
    EXPECT_LT((p - (u + s * d)).norm(), 1e-12) << k;
    // Beyond max_distance: radial fallback.
    EXPECT_LT((ref->project(u, d, 0.5 * std::abs(s)) - ref->closest_point(u)).norm(), 1e-15);
  }
  // From the centre every closest point is equally good; it must still be on the sphere.
  EXPECT_NEAR((ref->closest_point(c) - c).norm(), R, 1e-15);
  EXPECT_NEAR((ref->project(c, Vec3::Zero(), 1) - c).norm(), R, 1e-15);
}

TEST(LinearReference, IsTheIdentityWithZeroRestAngle) {
  const auto ref = make_linear_reference();
  EXPECT_EQ(ref->kind(), "linear");
  const Vec3 u(0.3, -7, 2);
  EXPECT_EQ(ref->project(u, Vec3(0, 0, 1), kInfinity), u);
  EXPECT_EQ(ref->project(u, Vec3::Zero(), 0), u);
  EXPECT_EQ(ref->closest_point(u), u);
  EXPECT_EQ(ref->rest_dihedral(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, -1, 0.3)), 0);
}

}  // namespace
}  // namespace arcsim
