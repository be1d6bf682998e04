#include "restshape/triangle_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace arcsim {

Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (!(len2 > 0)) return a;
  const double t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
  return a + t * ab;
}

namespace {

Vec3 closest_point_on_edges(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 candidates[3] = {closest_point_on_segment(p, a, b), closest_point_on_segment(p, b, c),
                              closest_point_on_segment(p, c, a)};
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if ((candidates[i] - p).squaredNorm() < (candidates[best] - p).squaredNorm()) best = i;
  return candidates[best];
}

}  // namespace

// Region classification by the signs of dot products of the corner-to-p vectors with the two edge vectors
// (Ericson, Real-Time Collision Detection §5.1.5), with the degenerate triangle handled by its edges because
// its region tests divide by zero.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a;
  const double area2 = ab.cross(ac).squaredNorm();
  if (!(area2 > 1e-28 * ab.squaredNorm() * ac.squaredNorm())) return closest_point_on_edges(p, a, b, c);

  const Vec3 ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;

  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;

  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);

  // Interior: p's projection, from barycentric weights proportional to the sub-areas.
  const double sum = va + vb + vc;
  if (!(sum > 0)) return closest_point_on_edges(p, a, b, c);  // a sliver that rounding made inconsistent
  return a + (vb / sum) * ab + (vc / sum) * ac;
}

LineCaster::LineCaster(const Vec3& origin, const Vec3& direction)
    : origin_(origin), direction_(direction), inverse_direction_(direction.cwiseInverse()) {
  direction.cwiseAbs().maxCoeff(&kz_);
  kx_ = (kz_ + 1) % 3;
  ky_ = (kx_ + 1) % 3;
  // Keep the sheared frame right-handed so that the edge functions have a consistent sign per winding.
  if (direction[kz_] < 0) std::swap(kx_, ky_);
  sx_ = direction[kx_] / direction[kz_];
  sy_ = direction[ky_] / direction[kz_];
  sz_ = 1 / direction[kz_];
}

bool LineCaster::intersect(const Vec3& a, const Vec3& b, const Vec3& c, Hit& hit) const {
  const Vec3 A = a - origin_, B = b - origin_, C = c - origin_;
  // Corners in the sheared frame, where the line is the z axis.
  const double ax = A[kx_] - sx_ * A[kz_], ay = A[ky_] - sy_ * A[kz_];
  const double bx = B[kx_] - sx_ * B[kz_], by = B[ky_] - sy_ * B[kz_];
  const double cx = C[kx_] - sx_ * C[kz_], cy = C[ky_] - sy_ * C[kz_];
  // Twice the signed areas of the line's foot with each edge; U is the weight of corner a, and so on.
  double U = cx * by - cy * bx;
  double V = ax * cy - ay * cx;
  double W = bx * ay - by * ax;
  // Without FMA contraction a shared edge gives exactly negated values in its two triangles; the tolerance of a
  // few roundings keeps that true if the compiler contracts, at the price of rare double hits (harmless).
  constexpr double kRound = 4 * std::numeric_limits<double>::epsilon();
  const double tu = kRound * (std::abs(cx * by) + std::abs(cy * bx));
  const double tv = kRound * (std::abs(ax * cy) + std::abs(ay * cx));
  const double tw = kRound * (std::abs(bx * ay) + std::abs(by * ax));
  const bool some_negative = U < -tu || V < -tv || W < -tw;
  const bool some_positive = U > tu || V > tv || W > tw;
  if (some_negative && some_positive) return false;
  if (some_negative || (!some_positive && U + V + W < 0)) {
    U = -U;
    V = -V;
    W = -W;
  }
  // Weights within the tolerance of zero are clamped, so the hit is a convex combination of the corners.
  U = std::max(U, 0.0);
  V = std::max(V, 0.0);
  W = std::max(W, 0.0);
  const double det = U + V + W;
  if (!(det > 0)) return false;  // the line lies in the triangle's plane (grazing)
  const double T = U * (sz_ * A[kz_]) + V * (sz_ * B[kz_]) + W * (sz_ * C[kz_]);
  hit.t = T / det;
  hit.point = (U / det) * a + (V / det) * b + (W / det) * c;
  return std::isfinite(hit.t);
}

bool LineCaster::clip_to_box(const Vec3& lo, const Vec3& hi, double& t0, double& t1) const {
  t0 = -kInfinity;
  t1 = kInfinity;
  for (int i = 0; i < 3; ++i) {
    if (direction_[i] == 0) {
      if (origin_[i] < lo[i] || origin_[i] > hi[i]) return false;
      continue;
    }
    const double inv = inverse_direction_[i];
    double ta = (lo[i] - origin_[i]) * inv, tb = (hi[i] - origin_[i]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace arcsim
