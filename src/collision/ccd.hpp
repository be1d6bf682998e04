// Continuous collision detection of a vertex-face or edge-edge pair whose four nodes move linearly from x0 to
// x1 during the step (normalised time t in [0, 1]).
//
// Contact happens when the distance drops to `contact_distance`. Candidate times are the roots of the cubic
// "the four points are coplanar", its near-tangent critical points, and t = 0 and t = 1 when the pair is that
// close to coplanar there (the distance is never below the height over the shared plane); the first candidate
// at which the closest points are within the contact distance is the impact. When the four points
// stay coplanar (within the contact distance) through the whole step, the cubic carries no information and
// conservative advancement on the true distance is used instead.
//
// Contact at t = 0 counts only if the pair is approaching: a pair that starts in exact contact and moves apart
// (in any direction, including through each other's plane) is not an impact.
#pragma once

#include <array>
#include <optional>

#include "collision/distance.hpp"
#include "math/types.hpp"

namespace arcsim {

struct CcdOptions {
  double contact_distance = 1e-6;  // m
  int max_advancement_steps = 256;  // conservative-advancement iterations for coplanar motion
};

struct Impact {
  double time = 0;          // normalised, in [0, 1]
  // Closest points at `time`. The normal points from the second primitive toward the first on the side the
  // pair came from, so that n . sum_i w_i x_i > 0 means "not crossed".
  ClosestPoints contact;
};

// Nodes in order (vertex, face corner a, b, c).
std::optional<Impact> vertex_face_impact(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1,
                                         const CcdOptions& options = {});
// Nodes in order (edge p0, p1, edge q0, q1).
std::optional<Impact> edge_edge_impact(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1,
                                       const CcdOptions& options = {});

// The coplanarity cubic det[x1 - x0, x2 - x0, x3 - x0](t) of four linearly moving points, as coefficients of
// 1, t, t^2, t^3 (for VF order (a, b, c, p) and EE order (p0, p1, q0, q1) it vanishes exactly when the
// primitives' lines/planes meet).
std::array<double, 4> coplanarity_cubic(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1);

}  // namespace arcsim
