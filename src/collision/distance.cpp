#include "collision/distance.hpp"

#include <algorithm>
#include <cmath>

namespace arcsim {

namespace {

double clamp01(double x) { return std::min(1.0, std::max(0.0, x)); }

// Parameter of the point of segment (a, b) closest to p.
double closest_segment_parameter(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double dd = d.squaredNorm();
  return dd > 0 ? clamp01((p - a).dot(d) / dd) : 0.0;
}

// Fills distance and normal from the gap vector; the unit `touching_normal` is used when the gap vanishes
// (`scale` is the primitives' size, m).
ClosestPoints from_gap(const Vec3& gap, const Vec3& touching_normal, double scale,
                       const std::array<double, 4>& weights) {
  ClosestPoints r;
  r.weights = weights;
  r.distance = gap.norm();
  // Below this length the gap's direction is rounding noise; the primitives' own normal is better.
  if (r.distance > 0 && r.distance > 1e-12 * scale) {
    r.normal = gap / r.distance;
  } else {
    r.normal = touching_normal;
  }
  return r;
}

}  // namespace

Vec3 any_perpendicular(const Vec3& d) {
  if (d.squaredNorm() == 0) return Vec3::UnitZ();
  // Cross with the axis least aligned with d.
  Eigen::Index axis;
  d.cwiseAbs().minCoeff(&axis);
  return d.cross(Vec3::Unit(axis)).normalized();
}

Vec3 closest_triangle_barycentrics(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a;
  const double area2 = ab.cross(ac).squaredNorm();
  const double scale2 = std::max({ab.squaredNorm(), ac.squaredNorm(), (c - b).squaredNorm()});
  if (!(area2 > 1e-24 * scale2 * scale2)) {
    // Zero-area triangle: the nearest of its three edges.
    const double s_ab = closest_segment_parameter(p, a, b);
    const double s_bc = closest_segment_parameter(p, b, c);
    const double s_ca = closest_segment_parameter(p, c, a);
    const double d_ab = (a + s_ab * ab - p).squaredNorm();
    const double d_bc = (b + s_bc * (c - b) - p).squaredNorm();
    const double d_ca = (c + s_ca * (a - c) - p).squaredNorm();
    if (d_ab <= d_bc && d_ab <= d_ca) return Vec3(1 - s_ab, s_ab, 0);
    if (d_bc <= d_ca) return Vec3(0, 1 - s_bc, s_bc);
    return Vec3(s_ca, 0, 1 - s_ca);
  }
  // Voronoi regions of the vertices, edges and interior, tested in turn (the classic region walk).
  const Vec3 ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return Vec3(1, 0, 0);
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return Vec3(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double s = d1 / (d1 - d3);  // d1 - d3 = |ab|^2 > 0
    return Vec3(1 - s, s, 0);
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return Vec3(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double s = d2 / (d2 - d6);  // d2 - d6 = |ac|^2 > 0
    return Vec3(1 - s, 0, s);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));  // denominator = |bc|^2 > 0
    return Vec3(0, 1 - s, s);
  }
  const double sum = va + vb + vc;  // = |ab x ac|^2 > 0 here
  const double v = vb / sum, w = vc / sum;
  return Vec3(1 - v - w, v, w);
}

Vec2 closest_segment_parameters(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  if (a == 0 && e == 0) return Vec2(0, 0);
  if (a == 0) return Vec2(0, clamp01(f / e));
  const double c = d1.dot(r);
  if (e == 0) return Vec2(clamp01(-c / a), 0);
  const double b = d1.dot(d2);
  const double denom = a * e - b * b;  // = |d1 x d2|^2 >= 0
  double s;
  if (denom > 1e-14 * a * e) {
    s = clamp01((b * f - c * e) / denom);
  } else {
    // (Nearly) parallel: start from p0; the two clamped projections below then give a closest pair.
    s = 0;
  }
  double u = (b * s + f) / e;
  if (u < 0) {
    u = 0;
    s = clamp01(-c / a);
  } else if (u > 1) {
    u = 1;
    s = clamp01((b - c) / a);
  }
  return Vec2(s, u);
}

ClosestPoints vertex_face_closest(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 bary = closest_triangle_barycentrics(p, a, b, c);
  const Vec3 q = bary[0] * a + bary[1] * b + bary[2] * c;
  const Vec3 n = (b - a).cross(c - a);
  const double scale = std::max({(b - a).norm(), (c - a).norm(), (p - a).norm()});
  const Vec3 face_normal = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitZ();
  return from_gap(p - q, face_normal, scale, {1, -bary[0], -bary[1], -bary[2]});
}

ClosestPoints edge_edge_closest(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec2 su = closest_segment_parameters(p0, p1, q0, q1);
  const double s = su[0], u = su[1];
  const Vec3 gap = (p0 + s * (p1 - p0)) - (q0 + u * (q1 - q0));
  const Vec3 cross = (p1 - p0).cross(q1 - q0);
  const Vec3 touching = cross.squaredNorm() > 0 ? Vec3(cross.normalized()) : any_perpendicular(p1 - p0);
  const double scale = std::max({(p1 - p0).norm(), (q1 - q0).norm(), (q0 - p0).norm()});
  return from_gap(gap, touching, scale, {1 - s, s, -(1 - u), -u});
}

ClosestPoints vertex_edge_closest(const Vec3& p, const Vec3& a, const Vec3& b) {
  const double s = closest_segment_parameter(p, a, b);
  const Vec3 gap = p - (a + s * (b - a));
  const double scale = std::max((b - a).norm(), (p - a).norm());
  return from_gap(gap, any_perpendicular(b - a), scale, {1, -(1 - s), -s, 0});
}

namespace {

// True if segment (p, q) passes through the interior of triangle t (crossing its plane, not lying in it).
bool segment_crosses_triangle(const Vec3& p, const Vec3& q, const std::array<Vec3, 3>& t) {
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  const double dp = n.dot(p - t[0]), dq = n.dot(q - t[0]);
  if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0) || dp == dq) return false;
  const Vec3 r = p + dp / (dp - dq) * (q - p);
  for (int i = 0; i < 3; ++i) {
    const Vec3& a = t[i];
    const Vec3& b = t[(i + 1) % 3];
    if (n.dot((b - a).cross(r - a)) < 0) return false;
  }
  return true;
}

}  // namespace

bool triangles_cross(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b) {
  for (int i = 0; i < 3; ++i)
    if (segment_crosses_triangle(a[i], a[(i + 1) % 3], b) || segment_crosses_triangle(b[i], b[(i + 1) % 3], a))
      return true;
  return false;
}

double triangle_separation(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b) {
  if (triangles_cross(a, b)) return 0;
  double d = kInfinity;
  for (int i = 0; i < 3; ++i) {
    d = std::min(d, vertex_face_closest(a[i], b[0], b[1], b[2]).distance);
    d = std::min(d, vertex_face_closest(b[i], a[0], a[1], a[2]).distance);
    for (int j = 0; j < 3; ++j)
      d = std::min(d, edge_edge_closest(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]).distance);
  }
  return d;
}

}  // namespace arcsim
