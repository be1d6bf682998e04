// Circle fit of a sheet bent about one axis, for the plastic-memory tests: measures a curvature that does not
// depend on the mesh (any set of material points of the bent region gives the same circle).
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "math/types.hpp"

namespace arcsim::testing {

struct CylinderFit {
  Vec3 axis = Vec3::UnitY();  // unit, the sheet's bending axis
  Vec3 centre = Vec3::Zero(); // m, a point of the cylinder's axis
  double radius = 0;          // m

  double curvature() const { return 1 / radius; }
  // Distance (m) of p from the cylinder surface.
  double distance(const Vec3& p) const {
    Vec3 d = p - centre;
    d -= d.dot(axis) * axis;
    return std::abs(d.norm() - radius);
  }
};

// The sheet's points are p(u) = c(u_x) + u_y a, so the column of the least-squares affine map u -> p for u_y
// is the axis a; a Kasa circle fit of the points projected across a gives the circle. `pts[i]` belongs to the
// material point `us[i]` (rest coordinates).
inline CylinderFit fit_cylinder(const std::vector<Vec3>& us, const std::vector<Vec3>& pts) {
  const int n = static_cast<int>(pts.size());
  Eigen::MatrixXd U(n, 3), P(n, 3);
  for (int i = 0; i < n; ++i) {
    U.row(i) << us[i].x(), us[i].y(), 1;
    P.row(i) = pts[i].transpose();
  }
  const Eigen::MatrixXd map = U.colPivHouseholderQr().solve(P);  // 3x3: rows for u_x, u_y, 1
  CylinderFit fit;
  fit.axis = Vec3(map.row(1).transpose()).normalized();
  const Vec3 e1 = fit.axis.unitOrthogonal(), e2 = fit.axis.cross(e1);
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd rhs(n);
  for (int i = 0; i < n; ++i) {
    const double x = pts[i].dot(e1), z = pts[i].dot(e2);
    A.row(i) << 2 * x, 2 * z, 1;
    rhs[i] = x * x + z * z;
  }
  const Eigen::Vector3d p = A.colPivHouseholderQr().solve(rhs);
  fit.centre = p[0] * e1 + p[1] * e2;
  fit.radius = std::sqrt(p[2] + p[0] * p[0] + p[1] * p[1]);
  return fit;
}

}  // namespace arcsim::testing
