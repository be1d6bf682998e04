#include "physics/bending.hpp"

#include <cmath>

#include <unsupported/Eigen/AutoDiff>

#include "mesh/mesh.hpp"  // dihedral_angle

namespace arcsim {

namespace {

template <typename T>
using Vec3T = Eigen::Matrix<T, 3, 1>;
template <typename T>
using Vec12T = Eigen::Matrix<T, 12, 1>;

// Wing heights below this fraction of the edge length are floored (degenerate wing guard).
constexpr double kMinHeightRatio = 1e-3;

// Gradient of theta with respect to a wing node: moving the wing by d along its face normal n_hat rotates the
// face about the hinge by d / h (h = wing height), which decreases theta with mesh.cpp's sign convention.
// `n` is the unnormalised face normal (|n| = 2 * face area), `l` the edge length.
template <typename T>
Vec3T<T> wing_gradient(const Vec3T<T>& n, const T& l) {
  using std::sqrt;
  const T twice_area = sqrt(n.dot(n));
  if (!(twice_area > 0)) return Vec3T<T>::Zero();
  T height = twice_area / l;
  const T min_height = kMinHeightRatio * l;
  if (height < min_height) height = min_height;
  return n / (-twice_area * height);
}

// Closed-form d theta / dx. The edge nodes' terms follow from the wings' ones: moving edge node x0 by d moves
// the hinge line at wing A's foot (parameter s2 along the edge) by (1 - s2) d, which is the same as moving the
// wing by -(1 - s2) d; likewise for x1 with s2. The four terms then sum to zero (translation invariance).
template <typename T>
Vec12T<T> theta_gradient(const Vec3T<T>& x0, const Vec3T<T>& x1, const Vec3T<T>& x2, const Vec3T<T>& x3) {
  using std::sqrt;
  Vec12T<T> g = Vec12T<T>::Zero();
  const Vec3T<T> e = x1 - x0;
  const T l2 = e.dot(e);
  if (!(l2 > 0)) return g;
  const T l = sqrt(l2);
  const Vec3T<T> gA = wing_gradient<T>(e.cross(x2 - x0), l);
  const Vec3T<T> gB = wing_gradient<T>((x3 - x0).cross(e), l);
  const T s2 = (x2 - x0).dot(e) / l2;
  const T s3 = (x3 - x0).dot(e) / l2;
  g.template segment<3>(0) = (s2 - 1) * gA + (s3 - 1) * gB;
  g.template segment<3>(3) = -s2 * gA - s3 * gB;
  g.template segment<3>(6) = gA;
  g.template segment<3>(9) = gB;
  return g;
}

}  // namespace

double wrap_angle(double angle) {
  // remainder(angle, 2 pi) is angle itself, exactly, for |angle| <= pi (the quotient rounds to 0): the common
  // case (a dihedral angle and its rest angle) skips the library call.
  const double wrapped = std::abs(angle) <= M_PI ? angle : std::remainder(angle, 2 * M_PI);  // in [-pi, pi]
  return wrapped <= -M_PI ? wrapped + 2 * M_PI : wrapped;
}

Vec12 dihedral_angle_gradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  return theta_gradient<double>(x0, x1, x2, x3);
}

Mat12 dihedral_angle_hessian(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  using AD = Eigen::AutoDiffScalar<Vec12>;
  const Vec3* x[4] = {&x0, &x1, &x2, &x3};
  Vec3T<AD> ad[4];
  for (int node = 0; node < 4; ++node)
    for (int c = 0; c < 3; ++c) ad[node](c) = AD((*x[node])(c), 12, 3 * node + c);
  const Vec12T<AD> g = theta_gradient<AD>(ad[0], ad[1], ad[2], ad[3]);
  Mat12 H;
  for (int r = 0; r < 12; ++r) H.row(r) = g(r).derivatives().transpose();
  // Exact up to round-off; symmetrise so that solvers see a symmetric matrix.
  return 0.5 * (H + H.transpose());
}

}  // namespace arcsim
