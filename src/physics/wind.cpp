#include "physics/wind.hpp"

#include <cmath>

namespace arcsim {

WindForce wind_force(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& v0, const Vec3& v1,
                     const Vec3& v2, const Vec3& wind_velocity, double density, double drag) {
  WindForce out;
  const Vec3 cross = (x1 - x0).cross(x2 - x0);
  const double twice_area = cross.norm();
  if (!(twice_area > 0)) return out;
  const double area = 0.5 * twice_area;
  const Vec3 n = cross / twice_area;
  const Vec3 v = wind_velocity - (v0 + v1 + v2) / 3;
  const double vn = v.dot(n);
  const Vec3 face_force = density * area * std::fabs(vn) * vn * n + drag * area * (v - vn * n);
  for (int a = 0; a < 3; ++a) out.force.segment<3>(3 * a) = face_force / 3;
  // d face_force / d v = density A 2|v_n| n n^T + drag A (I - n n^T); d v / d v_b = -I/3, and each node gets
  // a third, so every 3x3 block is -1/9 of it.
  const Mat3 nn = n * n.transpose();
  const Mat3 dforce_dv = density * area * 2 * std::fabs(vn) * nn + drag * area * (Mat3::Identity() - nn);
  const Mat3 block = -dforce_dv / 9;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) out.jacobian.block<3, 3>(3 * a, 3 * b) = block;
  return out;
}

}  // namespace arcsim
