// Exact-as-possible point and line queries against single triangles, used by the reference-mesh tree.
#pragma once

#include "math/types.hpp"

namespace arcsim {

// Closest point to p on the closed triangle (a, b, c), correct in all seven Voronoi regions (three corners,
// three edges, interior) and for degenerate (zero-area) triangles, where it is the closest point on the edges.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Closest point to p on the segment a-b (a itself when the segment has zero length).
Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b);

// The line origin + t * direction (t of either sign), prepared for the watertight ray/triangle test of Woop,
// Benthin and Wald (JCGT 2013): the line is sheared into +z so that each triangle edge's side test is computed
// from the two edge endpoints alone. Two triangles sharing an edge then evaluate exactly negated edge functions,
// so a line through a shared edge or vertex hits at least one of them: no misses through cracks.
class LineCaster {
 public:
  // direction must be nonzero and finite.
  LineCaster(const Vec3& origin, const Vec3& direction);

  struct Hit {
    double t = 0;              // line parameter (units of |direction|)
    Vec3 point = Vec3::Zero();  // barycentric combination of the corners: lies on the triangle
  };
  // True if the line meets the closed triangle; hits with the triangle's plane containing the line (grazing,
  // zero determinant) count as misses, neighbouring triangles or the caller's fallback take them.
  bool intersect(const Vec3& a, const Vec3& b, const Vec3& c, Hit& hit) const;

  // Parameter interval [t0, t1] in which the line is inside the box; false if it never is.
  bool clip_to_box(const Vec3& lo, const Vec3& hi, double& t0, double& t1) const;

  const Vec3& origin() const { return origin_; }
  const Vec3& direction() const { return direction_; }

 private:
  Vec3 origin_, direction_;
  Vec3 inverse_direction_;          // componentwise 1 / direction (infinite where a component is 0)
  int kx_ = 0, ky_ = 1, kz_ = 2;   // permuted axes: kz is the dominant direction component
  double sx_ = 0, sy_ = 0, sz_ = 1;  // shear taking the direction to (0, 0, 1)
};

}  // namespace arcsim
