#include "remesh/metric.hpp"

#include <algorithm>
#include <cmath>

namespace arcsim {

namespace {

// A metric as a circle: centre (p, q) = deviatoric part, radius m = half the trace (may be negative for an
// indefinite input; the algebra does not care).
struct Circle {
  Vec2 c;
  double r;
};

Circle to_circle(const Mat2& M) {
  const double a = M(0, 0), d = M(1, 1), b = 0.5 * (M(0, 1) + M(1, 0));
  return {Vec2(0.5 * (a - d), b), 0.5 * (a + d)};
}

Mat2 to_metric(const Vec2& c, double r) {
  Mat2 M;
  M << r + c.x(), c.y(), c.y(), r - c.x();
  return M;
}

bool encloses(const Vec2& c, double r, const std::vector<Circle>& circles, double tolerance) {
  for (const Circle& k : circles)
    if (k.r + (c - k.c).norm() > r + tolerance) return false;
  return true;
}

// Circle (centre, radius) internally tangent to three circles: |c - c_i| = R - r_i. Subtracting the first
// equation from the others leaves two linear equations in (c, R); c = P + R Q, and the first equation becomes a
// quadratic in R. Returns the candidates (0, 1 or 2).
std::vector<std::pair<Vec2, double>> tangent_to_three(const Circle& a, const Circle& b, const Circle& k) {
  std::vector<std::pair<Vec2, double>> out;
  Mat2 A;
  Vec2 rhs, g;
  const Circle* others[2] = {&b, &k};
  for (int i = 0; i < 2; ++i) {
    const Circle& o = *others[i];
    A.row(i) = 2 * (a.c - o.c).transpose();
    rhs(i) = a.c.squaredNorm() - o.c.squaredNorm() + o.r * o.r - a.r * a.r;
    g(i) = 2 * (a.r - o.r);
  }
  const double det = A.determinant();
  const double scale = A.cwiseAbs().maxCoeff();
  if (!(std::abs(det) > 1e-12 * scale * scale)) return out;  // collinear centres: two supports suffice
  const Mat2 inv = A.inverse();
  const Vec2 P = inv * rhs, Q = inv * g;
  const Vec2 D = P - a.c;
  const double qa = Q.squaredNorm() - 1, qb = 2 * (D.dot(Q) + a.r), qc = D.squaredNorm() - a.r * a.r;
  auto add = [&](double R) {
    if (std::isfinite(R)) out.emplace_back(P + R * Q, R);
  };
  if (std::abs(qa) < 1e-14) {
    if (qb != 0) add(-qc / qb);
    return out;
  }
  const double disc = qb * qb - 4 * qa * qc;
  if (disc < 0) return out;
  const double s = std::sqrt(disc);
  add((-qb + s) / (2 * qa));
  add((-qb - s) / (2 * qa));
  return out;
}

}  // namespace

Mat2 metric_max(const std::vector<Mat2>& metrics) {
  if (metrics.empty()) return Mat2::Zero();
  if (metrics.size() == 1) return metrics[0];
  std::vector<Circle> circles;
  double scale = 0;
  for (const Mat2& M : metrics) {
    circles.push_back(to_circle(M));
    scale = std::max(scale, M.cwiseAbs().maxCoeff());
  }
  if (!(scale > 0)) return Mat2::Zero();
  const double tolerance = 1e-10 * scale;
  // A circle inside another (M_j <= M_i: a zero term, a weaker criterion) cannot shape the enclosing circle:
  // drop it before the search, which is cubic in the count (sizing passes six terms, most often two or three
  // of them nonzero). Of equal circles the first stays.
  {
    std::vector<Circle> kept;
    for (size_t j = 0; j < circles.size(); ++j) {
      bool inside = false;
      for (size_t i = 0; i < circles.size() && !inside; ++i) {
        if (i == j) continue;
        const double slack = circles[i].r - circles[j].r - (circles[j].c - circles[i].c).norm();
        const bool equal = circles[i].r == circles[j].r && circles[i].c == circles[j].c;
        inside = equal ? i < j : slack >= 0;
      }
      if (!inside) kept.push_back(circles[j]);
    }
    circles.swap(kept);
  }
  const size_t n = circles.size();

  // Always valid fallback: centred at the origin.
  Vec2 best_c = Vec2::Zero();
  double best_r = -kInfinity;
  for (const Circle& k : circles) best_r = std::max(best_r, k.r + k.c.norm());

  auto consider = [&](const Vec2& c, double r) {
    if (r < best_r && encloses(c, r, circles, tolerance)) {
      best_c = c;
      best_r = r;
    }
  };
  for (size_t i = 0; i < n; ++i) consider(circles[i].c, circles[i].r);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      const Vec2 d = circles[j].c - circles[i].c;
      const double dist = d.norm();
      if (!(dist > 0)) continue;
      const double r = 0.5 * (dist + circles[i].r + circles[j].r);
      consider(circles[i].c + (r - circles[i].r) / dist * d, r);
    }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      for (size_t k = j + 1; k < n; ++k)
        for (const auto& [c, r] : tangent_to_three(circles[i], circles[j], circles[k])) consider(c, r);
  // Round up by the tolerance so that M - M_i is PSD despite rounding.
  return to_metric(best_c, best_r + tolerance);
}

Vec2 metric_eigenvalues(const Mat2& M) {
  const double mean = 0.5 * (M(0, 0) + M(1, 1));
  const double half_diff = 0.5 * (M(0, 0) - M(1, 1));
  const double off = 0.5 * (M(0, 1) + M(1, 0));
  const double radius = std::hypot(half_diff, off);
  return Vec2(mean - radius, mean + radius);
}

namespace {

// Applies `f` to the eigenvalues of the symmetric matrix M.
template <typename F>
Mat2 map_eigenvalues(const Mat2& M, F f) {
  Eigen::SelfAdjointEigenSolver<Mat2> eig(0.5 * (M + M.transpose()));
  const Vec2 l = eig.eigenvalues();
  const Mat2 V = eig.eigenvectors();
  return V * Vec2(f(l(0)), f(l(1))).asDiagonal() * V.transpose();
}

bool positive_finite(double x) { return std::isfinite(x) && x > 0; }

}  // namespace

Mat2 metric_positive_part(const Mat2& M) {
  return map_eigenvalues(M, [](double l) { return std::max(l, 0.0); });
}

Mat2 metric_sqrt(const Mat2& M) {
  return map_eigenvalues(M, [](double l) { return std::sqrt(std::max(l, 0.0)); });
}

Mat2 metric_signed_sqrt(const Mat2& M) {
  return map_eigenvalues(M, [](double l) { return std::copysign(std::sqrt(std::abs(l)), l); });
}

Mat2 clamp_metric(const Mat2& M, double size_min, double size_max, double aspect_min) {
  Eigen::SelfAdjointEigenSolver<Mat2> eig(0.5 * (M + M.transpose()));
  Vec2 l = eig.eigenvalues();
  const Mat2 V = eig.eigenvectors();
  const double lo = positive_finite(size_max) ? 1 / (size_max * size_max) : 0.0;
  const double hi = positive_finite(size_min) ? 1 / (size_min * size_min) : kInfinity;
  for (int i = 0; i < 2; ++i) l(i) = std::min(std::max(l(i), lo), hi);
  if (positive_finite(aspect_min)) {
    const double a2 = std::min(aspect_min, 1.0) * std::min(aspect_min, 1.0);
    const double largest = std::max(l(0), l(1));
    for (int i = 0; i < 2; ++i) l(i) = std::max(l(i), a2 * largest);
  }
  return V * l.asDiagonal() * V.transpose();
}

}  // namespace arcsim
