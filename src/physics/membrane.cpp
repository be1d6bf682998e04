#include "physics/membrane.hpp"

#include <algorithm>
#include <cmath>

namespace arcsim {

namespace {

using Mat39 = Eigen::Matrix<double, 3, 9>;

// Positive part of a symmetric 2x2 matrix (eigenvalues clamped at 0), in closed form: with eigenvalues
// l1 >= l2, M - l2 I = (l1 - l2) v v^T, so when l1 > 0 > l2 the positive part l1 v v^T needs no eigenvector.
Mat2 positive_part(const Mat2& M) {
  const double mean = 0.5 * (M(0, 0) + M(1, 1));
  const double half_diff = 0.5 * (M(0, 0) - M(1, 1));
  const double radius = std::sqrt(half_diff * half_diff + M(0, 1) * M(0, 1));
  const double l1 = mean + radius, l2 = mean - radius;
  if (l2 >= 0) return M;
  if (l1 <= 0) return Mat2::Zero();
  return (l1 / (l1 - l2)) * (M - l2 * Mat2::Identity());
}

// Stiffness in Voigt form, acting on g = (G11, G22, G12) and giving (S11, S22, 2 S12): the energy density is
// g^T K g / 2, so the shear entry is 2 k33.
Mat3 voigt_stiffness(const MembraneStiffness& k, double factor) {
  Mat3 K;
  K << k.k11, k.k12, 0, k.k12, k.k22, 0, 0, 0, 2 * k.k33;
  return factor * K;
}

Mat3 positive_part_voigt(const Mat3& K) {
  Mat3 P = Mat3::Zero();
  P.topLeftCorner<2, 2>() = positive_part(K.topLeftCorner<2, 2>());
  P(2, 2) = std::max(K(2, 2), 0.0);
  return P;
}

// Per-face kinematics: F = sum_a x_a b_a^T where b_a is row a of `shape`, so dF/dx_a = (.) b_a^T.
struct Kinematics {
  Eigen::Matrix<double, 3, 2> shape;  // rows b_0, b_1, b_2 (1/m)
  Mat32 F;
  Vec3 g;     // Green strain (G11, G22, G12)
  Mat39 J;    // dg/dx
};

Kinematics kinematics(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv) {
  Kinematics kin;
  kin.shape.row(0) = -(Dm_inv.row(0) + Dm_inv.row(1));
  kin.shape.row(1) = Dm_inv.row(0);
  kin.shape.row(2) = Dm_inv.row(1);
  Mat32 Ds;
  Ds.col(0) = x1 - x0;
  Ds.col(1) = x2 - x0;
  kin.F = Ds * Dm_inv;
  const Vec3 f1 = kin.F.col(0), f2 = kin.F.col(1);
  kin.g << 0.5 * (f1.squaredNorm() - 1), 0.5 * (f2.squaredNorm() - 1), 0.5 * f1.dot(f2);
  // dG = sym(F^T dF) with dF = dx_a b_a^T.
  for (int a = 0; a < 3; ++a) {
    const double b1 = kin.shape(a, 0), b2 = kin.shape(a, 1);
    kin.J.block<1, 3>(0, 3 * a) = b1 * f1.transpose();
    kin.J.block<1, 3>(1, 3 * a) = b2 * f2.transpose();
    kin.J.block<1, 3>(2, 3 * a) = 0.5 * (b2 * f1 + b1 * f2).transpose();
  }
  return kin;
}

Mat2 stress_from_voigt(const Vec3& s) {
  Mat2 S;
  S << s(0), 0.5 * s(2), 0.5 * s(2), s(1);
  return S;
}

// A [ J^T K J + (shape S shape^T) (x) I3 ].
Mat9 hessian_from(const Kinematics& kin, const Mat3& K, const Mat2& S, double rest_area) {
  // lazyProduct: a coefficient-wise product; Eigen would otherwise route this 9x3x9 product to its
  // general (blocked, OpenMP-aware) matrix-matrix kernel, which is slower at this size.
  const Eigen::Matrix<double, 9, 3> JtK = kin.J.transpose() * K;
  Mat9 H = JtK.lazyProduct(kin.J);
  const Mat3 geometric = kin.shape * S * kin.shape.transpose();
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) H.block<3, 3>(3 * a, 3 * b).diagonal().array() += geometric(a, b);
  return rest_area * H;
}

}  // namespace

Mat32 membrane_deformation_gradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv) {
  Mat32 Ds;
  Ds.col(0) = x1 - x0;
  Ds.col(1) = x2 - x0;
  return Ds * Dm_inv;
}

Mat2 membrane_green_strain(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv) {
  const Mat32 F = membrane_deformation_gradient(x0, x1, x2, Dm_inv);
  return 0.5 * (F.transpose() * F - Mat2::Identity());
}

Mat2 membrane_stress(const Mat2& G, const MembraneStiffness& k, double stiffness_factor) {
  const Vec3 g(G(0, 0), G(1, 1), 0.5 * (G(0, 1) + G(1, 0)));
  return stress_from_voigt(voigt_stiffness(k, stiffness_factor) * g);
}

MembraneTerms membrane_terms(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv,
                             double rest_area, const MembraneStiffness& k, double stiffness_factor,
                             HessianKind hessian) {
  const Kinematics kin = kinematics(x0, x1, x2, Dm_inv);
  const Mat3 K = voigt_stiffness(k, stiffness_factor);
  const Vec3 s = K * kin.g;  // (S11, S22, 2 S12), N/m
  MembraneTerms out;
  out.energy = 0.5 * rest_area * kin.g.dot(s);
  out.gradient = rest_area * kin.J.transpose() * s;
  if (hessian == HessianKind::kExact) {
    out.hessian = hessian_from(kin, K, stress_from_voigt(s), rest_area);
  } else if (hessian == HessianKind::kProjected) {
    out.hessian = hessian_from(kin, positive_part_voigt(K), positive_part(stress_from_voigt(s)), rest_area);
  }
  return out;
}

double membrane_terms_energy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv, double rest_area,
                             const MembraneStiffness& k, double stiffness_factor) {
  const Kinematics kin = kinematics(x0, x1, x2, Dm_inv);
  const Mat3 K = voigt_stiffness(k, stiffness_factor);
  const Vec3 s = K * kin.g;
  return 0.5 * rest_area * kin.g.dot(s);
}

double membrane_energy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv, double rest_area,
                       const MembraneStiffness& k, double stiffness_factor) {
  const Mat2 G = membrane_green_strain(x0, x1, x2, Dm_inv);
  const Vec3 g(G(0, 0), G(1, 1), G(0, 1));
  return 0.5 * rest_area * g.dot(voigt_stiffness(k, stiffness_factor) * g);
}

Vec9 membrane_gradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv, double rest_area,
                       const MembraneStiffness& k, double stiffness_factor) {
  return membrane_terms(x0, x1, x2, Dm_inv, rest_area, k, stiffness_factor, HessianKind::kNone).gradient;
}

Mat9 membrane_hessian(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv, double rest_area,
                      const MembraneStiffness& k, double stiffness_factor) {
  return membrane_terms(x0, x1, x2, Dm_inv, rest_area, k, stiffness_factor, HessianKind::kExact).hessian;
}

Mat9 membrane_hessian_projected(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv,
                                double rest_area, const MembraneStiffness& k, double stiffness_factor) {
  return membrane_terms(x0, x1, x2, Dm_inv, rest_area, k, stiffness_factor, HessianKind::kProjected).hessian;
}

}  // namespace arcsim
