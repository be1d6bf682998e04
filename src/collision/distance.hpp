// Closest points between the primitive pairs of collision handling: vertex-face (VF), edge-edge (EE) and, for
// crack lips in the sheet's plane, vertex-edge (VE).
//
// Every result describes the gap as a weighted sum of the primitives' nodes: sum_i w_i x_i is the vector from
// the closest point on the second primitive to the closest point on the first, so that the gap along the
// normal n is n . sum_i w_i x_i. This form is linear in the positions, which is what the penalty forces and the
// impact-zone constraints need.
#pragma once

#include <array>

#include "math/types.hpp"

namespace arcsim {

struct ClosestPoints {
  double distance = 0;                      // m
  Vec3 normal = Vec3::UnitZ();              // unit; from the second primitive toward the first
  std::array<double, 4> weights{0, 0, 0, 0};  // node order of the query (VE uses the first three)
};

// Vertex p against triangle (a, b, c); weights (1, -b_a, -b_b, -b_c) with b the barycentrics of the closest
// point. When p lies on the triangle the normal is the triangle's normal (a x b order), or an arbitrary unit
// vector for a degenerate triangle.
ClosestPoints vertex_face_closest(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Segment (p0, p1) against segment (q0, q1); weights (1 - s, s, -(1 - u), -u) for the closest points
// p0 + s (p1 - p0) and q0 + u (q1 - q0). Parallel and zero-length segments give one of the closest pairs.
// When the segments touch the normal is their cross product's direction (any perpendicular if parallel).
ClosestPoints edge_edge_closest(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

// Vertex p against segment (a, b); weights (1, -(1 - s), -s, 0).
ClosestPoints vertex_edge_closest(const Vec3& p, const Vec3& a, const Vec3& b);

// Barycentric coordinates of the point of triangle (a, b, c) closest to p. A degenerate (zero-area) triangle is
// treated as the union of its edges.
Vec3 closest_triangle_barycentrics(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Parameters (s, u) of the closest points of segments p0 + s (p1 - p0) and q0 + u (q1 - q0), in [0, 1].
Vec2 closest_segment_parameters(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

// True if an edge of either triangle passes through the other (crossing its plane inside it). Coplanar
// overlaps do not count: they show as zero distances between edges or vertices and faces.
bool triangles_cross(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b);

// Smallest distance between triangles (a0, a1, a2) and (b0, b1, b2) (m): 0 when an edge of one crosses the
// other, else the least of the 6 vertex-face and 9 edge-edge distances. Floating point: a crossing within
// rounding of a triangle's border shows as a near-zero edge-edge distance instead.
double triangle_separation(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b);

// Any unit vector perpendicular to d (d nonzero); UnitZ for d = 0.
Vec3 any_perpendicular(const Vec3& d);

}  // namespace arcsim
