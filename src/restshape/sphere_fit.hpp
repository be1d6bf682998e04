// Least-squares sphere through a point cloud (the "sphere" reference shape of ARCSim scenes).
#pragma once

#include <vector>

#include "math/types.hpp"

namespace arcsim {

struct Sphere {
  Vec3 center = Vec3::Zero();  // m
  double radius = 0;           // m
};

// Centre: the point whose squared distances to every pair of points agree best in the least-squares sense,
// i.e. minimising sum over pairs (i, j) of (|p_i - c|^2 - |p_j - c|^2)^2 (ARCSim's criterion). That sum equals
// n^2 times the variance form used here, so it is solved in O(n) from the points' covariance:
// 2 Cov c' = mean(q |q|^2) with q = p - mean(p), c = mean(p) + c'. Radius: RMS distance to the centre.
// Returns false (sphere untouched) if there are fewer than 4 points, a point is not finite, or the points are
// (nearly) coplanar or collinear, which leaves the centre undetermined.
bool fit_sphere(const std::vector<Vec3>& points, Sphere& sphere);

}  // namespace arcsim
