// Exact triangle-triangle intersection, for checking results (tests, `arcsim inspect`), not for the time step:
// orientation predicates evaluated in floating point with an error bound, and exactly (expansion arithmetic:
// sums and products of doubles kept as unevaluated sums of non-overlapping doubles) when the bound cannot decide
// the sign. Touching counts as intersecting.
#pragma once

#include <array>

#include "math/types.hpp"

namespace arcsim {

// Sign of det[a - d, b - d, c - d]: positive when d lies below the plane of (a, b, c) seen counter-clockwise.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// Sign of the 2D orientation of (a, b, c) in the coordinate plane that drops axis `drop` (0, 1 or 2).
int orient2d(const Vec3& a, const Vec3& b, const Vec3& c, int drop);

// Closed triangles s and t share at least one point.
bool triangles_intersect(const std::array<Vec3, 3>& s, const std::array<Vec3, 3>& t);

// Triangles s and t that share the corner s[i] == t[j] (the same point) meet somewhere else too: the surface
// folds through itself there (an edge of one crosses the other). Coplanar triangles count as not meeting.
bool triangles_meet_beyond_corner(const std::array<Vec3, 3>& s, int i, const std::array<Vec3, 3>& t, int j);

}  // namespace arcsim
