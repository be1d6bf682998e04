#include "restshape/sphere_fit.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>

namespace arcsim {

bool fit_sphere(const std::vector<Vec3>& points, Sphere& sphere) {
  if (points.size() < 4) return false;
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : points) {
    if (!p.allFinite()) return false;
    mean += p;
  }
  const double n = static_cast<double>(points.size());
  mean /= n;
  // Centred sums keep the normal equations well conditioned for a sphere far from the origin.
  Mat3 covariance = Mat3::Zero();
  Vec3 rhs = Vec3::Zero();
  for (const Vec3& p : points) {
    const Vec3 q = p - mean;
    covariance += q * q.transpose();
    rhs += q * q.squaredNorm();
  }
  covariance /= n;
  rhs /= n;
  // Pairwise differences must span 3D: a flat cloud's smallest covariance eigenvalue is (relatively) zero.
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(covariance);
  const Vec3 lambda = eigen.eigenvalues();  // ascending
  if (!(lambda[2] > 0) || !(lambda[0] > 1e-10 * lambda[2])) return false;
  const Vec3 offset = eigen.eigenvectors() * (eigen.eigenvectors().transpose() * rhs).cwiseQuotient(2 * lambda);
  const Vec3 center = mean + offset;
  double sum_squares = 0;
  for (const Vec3& p : points) sum_squares += (p - center).squaredNorm();
  const double radius = std::sqrt(sum_squares / n);
  if (!center.allFinite() || !(radius > 0) || !std::isfinite(radius)) return false;
  sphere.center = center;
  sphere.radius = radius;
  return true;
}

}  // namespace arcsim
