#include "collision/triangle_intersection.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace arcsim {


namespace {
namespace exact {

// a + b = x + y exactly.
void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a, av = x - bv;
  y = (a - av) + (b - bv);
}

// a * b = x + y exactly (fused multiply-add gives the rounding error).
void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

// e + b for a non-overlapping expansion e (components by increasing magnitude); keeps the invariant.
void grow(std::vector<double>& e, double b) {
  double q = b;
  std::vector<double> out;
  out.reserve(e.size() + 1);
  for (double c : e) {
    double sum, err;
    two_sum(q, c, sum, err);
    if (err != 0) out.push_back(err);
    q = sum;
  }
  if (q != 0) out.push_back(q);
  e.swap(out);
}

// Sign of the expansion: that of its largest component.
int sign(const std::vector<double>& e) { return e.empty() ? 0 : (e.back() > 0 ? 1 : -1); }

// The exact difference a - b as two doubles.
std::array<double, 2> diff(double a, double b) {
  double x, y;
  two_sum(a, -b, x, y);
  return {x, y};
}

// Adds s * a * b * c exactly to e (a, b, c each an exact two-double value).
void add_triple(std::vector<double>& e, int s, const std::array<double, 2>& a, const std::array<double, 2>& b,
                       const std::array<double, 2>& c) {
  for (double ai : a)
    for (double bj : b)
      for (double ck : c) {
        double p, q;
        two_product(ai, bj, p, q);
        for (double u : {p, q}) {
          double r, t;
          two_product(u, ck, r, t);
          grow(e, s * r);
          grow(e, s * t);
        }
      }
}

}  // namespace exact
}  // namespace

// Sign of det[a - d, b - d, c - d]: positive when d lies below the plane of (a, b, c) seen counter-clockwise.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 u = a - d, v = b - d, w = c - d;
  const double det = u.dot(v.cross(w));
  const double permanent = std::abs(u.x()) * (std::abs(v.y() * w.z()) + std::abs(v.z() * w.y())) +
                           std::abs(u.y()) * (std::abs(v.x() * w.z()) + std::abs(v.z() * w.x())) +
                           std::abs(u.z()) * (std::abs(v.x() * w.y()) + std::abs(v.y() * w.x()));
  // Generous bound on the rounding error of the floating-point determinant (differences included).
  if (std::abs(det) > 1e-14 * permanent) return det > 0 ? 1 : -1;
  std::array<std::array<double, 2>, 3> U, V, W;
  for (int k = 0; k < 3; ++k) {
    U[k] = exact::diff(a[k], d[k]);
    V[k] = exact::diff(b[k], d[k]);
    W[k] = exact::diff(c[k], d[k]);
  }
  std::vector<double> e;
  // u . (v x w) = ux (vy wz - vz wy) + uy (vz wx - vx wz) + uz (vx wy - vy wx)
  exact::add_triple(e, 1, U[0], V[1], W[2]);
  exact::add_triple(e, -1, U[0], V[2], W[1]);
  exact::add_triple(e, 1, U[1], V[2], W[0]);
  exact::add_triple(e, -1, U[1], V[0], W[2]);
  exact::add_triple(e, 1, U[2], V[0], W[1]);
  exact::add_triple(e, -1, U[2], V[1], W[0]);
  return exact::sign(e);
}

// Sign of the 2D orientation of (a, b, c) in the coordinate plane that drops axis `drop`.
int orient2d(const Vec3& a, const Vec3& b, const Vec3& c, int drop) {
  const int i = (drop + 1) % 3, j = (drop + 2) % 3;
  const double l = (a[i] - c[i]) * (b[j] - c[j]), r = (a[j] - c[j]) * (b[i] - c[i]);
  const double det = l - r;
  if (std::abs(det) > 1e-14 * (std::abs(l) + std::abs(r))) return det > 0 ? 1 : -1;
  std::vector<double> e;
  const std::array<double, 2> one{1, 0};
  exact::add_triple(e, 1, exact::diff(a[i], c[i]), exact::diff(b[j], c[j]), one);
  exact::add_triple(e, -1, exact::diff(a[j], c[j]), exact::diff(b[i], c[i]), one);
  return exact::sign(e);
}

namespace {

// Closed segments pq and rs in the plane dropping axis `drop` intersect.
bool segments_intersect_2d(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s, int drop) {
  const int o1 = orient2d(p, q, r, drop), o2 = orient2d(p, q, s, drop);
  const int o3 = orient2d(r, s, p, drop), o4 = orient2d(r, s, q, drop);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  const int i = (drop + 1) % 3, j = (drop + 2) % 3;
  auto on_segment = [&](const Vec3& a, const Vec3& b, const Vec3& c) {  // c collinear with ab: inside?
    return std::min(a[i], b[i]) <= c[i] && c[i] <= std::max(a[i], b[i]) && std::min(a[j], b[j]) <= c[j] &&
           c[j] <= std::max(a[j], b[j]);
  };
  return (o1 == 0 && on_segment(p, q, r)) || (o2 == 0 && on_segment(p, q, s)) ||
         (o3 == 0 && on_segment(r, s, p)) || (o4 == 0 && on_segment(r, s, q));
}

bool point_in_triangle_2d(const Vec3& p, const std::array<Vec3, 3>& t, int drop) {
  const int a = orient2d(t[0], t[1], p, drop), b = orient2d(t[1], t[2], p, drop), c = orient2d(t[2], t[0], p, drop);
  return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

bool coplanar_triangles_intersect(const std::array<Vec3, 3>& s, const std::array<Vec3, 3>& t) {
  const Vec3 n = (s[1] - s[0]).cross(s[2] - s[0]);
  Eigen::Index drop;
  n.cwiseAbs().maxCoeff(&drop);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (segments_intersect_2d(s[a], s[(a + 1) % 3], t[b], t[(b + 1) % 3], static_cast<int>(drop))) return true;
  return point_in_triangle_2d(s[0], t, static_cast<int>(drop)) || point_in_triangle_2d(t[0], s, static_cast<int>(drop));
}

// Segment pq meets triangle t (not coplanar with it).
bool segment_meets_triangle(const Vec3& p, const Vec3& q, const std::array<Vec3, 3>& t) {
  const int op = orient3d(t[0], t[1], t[2], p), oq = orient3d(t[0], t[1], t[2], q);
  if (op * oq > 0 || (op == 0 && oq == 0)) return false;
  const int a = orient3d(p, q, t[0], t[1]), b = orient3d(p, q, t[1], t[2]), c = orient3d(p, q, t[2], t[0]);
  return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

}  // namespace

// Closed triangles s and t share at least one point.
bool triangles_intersect(const std::array<Vec3, 3>& s, const std::array<Vec3, 3>& t) {
  // Quick rejection: every corner of one strictly on one side of the other's plane.
  int side_t[3], side_s[3];
  for (int k = 0; k < 3; ++k) side_t[k] = orient3d(s[0], s[1], s[2], t[k]);
  if ((side_t[0] > 0 && side_t[1] > 0 && side_t[2] > 0) || (side_t[0] < 0 && side_t[1] < 0 && side_t[2] < 0))
    return false;
  for (int k = 0; k < 3; ++k) side_s[k] = orient3d(t[0], t[1], t[2], s[k]);
  if ((side_s[0] > 0 && side_s[1] > 0 && side_s[2] > 0) || (side_s[0] < 0 && side_s[1] < 0 && side_s[2] < 0))
    return false;
  if (side_t[0] == 0 && side_t[1] == 0 && side_t[2] == 0) return coplanar_triangles_intersect(s, t);
  // Not coplanar: the intersection, if any, is a segment whose ends lie on edges of s or t.
  for (int k = 0; k < 3; ++k) {
    if (segment_meets_triangle(s[k], s[(k + 1) % 3], t)) return true;
    if (segment_meets_triangle(t[k], t[(k + 1) % 3], s)) return true;
  }
  return false;
}

// Two closed triangles sharing a corner p meet in a convex set holding p. If it holds a second point q, the
// segment pq leaves through the edge opposite p of one of them (up to collinear edges), and that edge crosses
// the other triangle.
bool triangles_meet_beyond_corner(const std::array<Vec3, 3>& s, int i, const std::array<Vec3, 3>& t, int j) {
  return segment_meets_triangle(s[(i + 1) % 3], s[(i + 2) % 3], t) ||
         segment_meets_triangle(t[(j + 1) % 3], t[(j + 2) % 3], s);
}

}  // namespace arcsim
