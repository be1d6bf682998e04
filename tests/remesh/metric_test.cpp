// The tensor max and the clamp of sizing metrics.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "remesh/metric.hpp"

namespace arcsim {
namespace {

Mat2 random_spd(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1), pos(0.01, 2);
  const double angle = 3.2 * u(rng);
  Mat2 R;
  R << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  return R * Vec2(pos(rng), pos(rng)).asDiagonal() * R.transpose();
}

// Half the trace of the smallest upper bound by direct convex minimisation of f(c) = max_i m_i + |c - c_i|
// over the deviatoric centre c (nested golden-section searches): independent of the circle construction.
double min_half_trace(const std::vector<Mat2>& ms) {
  auto f = [&](double p, double q) {
    double r = -1e300;
    for (const Mat2& M : ms)
      r = std::max(r, 0.5 * M.trace() + std::hypot(p - 0.5 * (M(0, 0) - M(1, 1)), q - M(0, 1)));
    return r;
  };
  auto minimise = [](auto g, double lo, double hi) {
    const double phi = (std::sqrt(5.0) - 1) / 2;
    for (int it = 0; it < 90; ++it) {
      const double a = hi - phi * (hi - lo), b = lo + phi * (hi - lo);
      if (g(a) < g(b)) hi = b; else lo = a;
    }
    return 0.5 * (lo + hi);
  };
  auto over_q = [&](double p) { return f(p, minimise([&](double q) { return f(p, q); }, -10, 10)); };
  const double p = minimise(over_q, -10, 10);
  return over_q(p);
}

TEST(MetricMax, IsAnUpperBoundOfMinimalTrace) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 60; ++trial) {
    std::vector<Mat2> ms;
    const int n = 1 + trial % 6;
    for (int i = 0; i < n; ++i) ms.push_back(random_spd(rng));
    const Mat2 M = metric_max(ms);
    for (const Mat2& A : ms) EXPECT_GE(metric_eigenvalues(M - A)(0), -1e-9) << "trial " << trial;
    EXPECT_NEAR(0.5 * M.trace(), min_half_trace(ms), 1e-7) << "trial " << trial;
  }
}

TEST(MetricMax, DiagonalInputsGiveTheEntrywiseMax) {
  // Any upper bound has M11 >= max a and M22 >= max d, so diag(max a, max d) is the minimal-trace one.
  const Mat2 M = metric_max({Vec2(4, 1).asDiagonal(), Vec2(2, 3).asDiagonal(), Vec2(1, 0.5).asDiagonal()});
  EXPECT_NEAR(M(0, 0), 4, 1e-9);
  EXPECT_NEAR(M(1, 1), 3, 1e-9);
  EXPECT_NEAR(M(0, 1), 0, 1e-9);
}

TEST(MetricMax, DominatedInputsDoNotMatter) {
  const Mat2 big = Vec2(5, 2).asDiagonal();
  const Mat2 M = metric_max({Vec2(1, 1).asDiagonal(), big, Mat2::Zero()});
  EXPECT_LT((M - big).norm(), 1e-9);
  EXPECT_EQ(metric_max({}), Mat2::Zero());
}

TEST(ClampMetric, BoundsEigenvaluesAndAnisotropy) {
  // Sizes 1 mm .. 1 m: eigenvalues in [1, 1e6].
  Mat2 M = Vec2(1e9, 1e-3).asDiagonal();
  Vec2 l = metric_eigenvalues(clamp_metric(M, 1e-3, 1.0, -kInfinity));
  EXPECT_NEAR(l(0), 1, 1e-9);
  EXPECT_NEAR(l(1), 1e6, 1e-3);
  // aspect_min 0.5: the smaller eigenvalue is at least 0.25 of the larger.
  l = metric_eigenvalues(clamp_metric(Vec2(100, 1).asDiagonal(), 1e-3, 1.0, 0.5));
  EXPECT_NEAR(l(0), 25, 1e-9);
  EXPECT_NEAR(l(1), 100, 1e-9);
  // Non-finite bounds are ignored.
  l = metric_eigenvalues(clamp_metric(Vec2(3, 2).asDiagonal(), -kInfinity, kInfinity, -kInfinity));
  EXPECT_NEAR(l(0), 2, 1e-12);
  EXPECT_NEAR(l(1), 3, 1e-12);
}

TEST(MetricPositivePart, ClampsNegativeEigenvalues) {
  Mat2 M;
  M << 1, 2, 2, 1;  // eigenvalues 3, -1 along (1, 1), (1, -1)
  const Mat2 P = metric_positive_part(M);
  EXPECT_NEAR(P(0, 0), 1.5, 1e-12);
  EXPECT_NEAR(P(0, 1), 1.5, 1e-12);
  const Mat2 S = metric_sqrt(Vec2(4, 9).asDiagonal());
  EXPECT_NEAR(S(0, 0), 2, 1e-12);
  EXPECT_NEAR(S(1, 1), 3, 1e-12);
}

TEST(MetricSignedSqrt, KeepsTheSignOfNegativeEigenvalues) {
  Mat2 M;
  M << 0, 2, 2, 0;  // eigenvalues 2, -2 along (1, 1), (1, -1)
  const Mat2 S = metric_signed_sqrt(M);
  EXPECT_NEAR(S(0, 0), 0, 1e-12);
  EXPECT_NEAR(S(0, 1), std::sqrt(2.0), 1e-12);
  const Mat2 P = metric_signed_sqrt(Vec2(-4, 9).asDiagonal());
  EXPECT_NEAR(P(0, 0), -2, 1e-12);
  EXPECT_NEAR(P(1, 1), 3, 1e-12);
  EXPECT_NEAR(metric_sqrt(Vec2(-4, 9).asDiagonal())(0, 0), 0, 1e-12);  // the plain root clamps instead
}

}  // namespace
}  // namespace arcsim
