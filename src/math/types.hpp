// Fixed-size linear-algebra types used throughout arcsim. Units are SI (m, kg, s) unless a comment says otherwise.
#pragma once

#include <Eigen/Dense>

namespace arcsim {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat2 = Eigen::Matrix2d;
using Mat3 = Eigen::Matrix3d;
using Mat32 = Eigen::Matrix<double, 3, 2>;
using Mat23 = Eigen::Matrix<double, 2, 3>;
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using VecX = Eigen::VectorXd;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace arcsim
