#include "physics/membrane.hpp"

#include <gtest/gtest.h>

#include <random>

#include "mesh/mesh.hpp"
#include "support/eigenvalues.hpp"

namespace arcsim {
namespace {

using testing::symmetric_eigenvalues;

// Rest data of one face exactly as the mesh computes it (material frame, Dm_inv, area).
Face rest_face(const Vec3& u0, const Vec3& u1, const Vec3& u2) {
  Mesh mesh = Mesh::from_triangles({u0, u1, u2}, {u0, u1, u2}, {0, 1, 2}, {{0, 1, 2}});
  return mesh.faces[0];
}

struct Case {
  Vec3 u[3];   // rest positions (3D, any orientation)
  Vec3 x[3];   // world positions
  Mat2 Dm_inv;
  double area = 0;
  MembraneStiffness k;
  double factor = 1;
};

class Random {
 public:
  explicit Random(unsigned seed) : gen_(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(gen_); }
  Vec3 vec3(double lo, double hi) { return Vec3(uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)); }
  Mat3 rotation() {
    Eigen::Quaterniond q(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    return q.normalized().toRotationMatrix();
  }
  // A well-shaped triangle in a random plane of 3D space.
  void triangle(Vec3 u[3]) {
    const Mat3 R = rotation();
    const Vec3 offset = vec3(-1, 1);
    u[0] = offset;
    u[1] = offset + R * Vec3(uniform(0.5, 1.5), uniform(-0.2, 0.2), 0);
    u[2] = offset + R * Vec3(uniform(-0.3, 0.6), uniform(0.5, 1.5), 0);
  }
  MembraneStiffness stiffness() {
    MembraneStiffness k;
    k.k11 = uniform(0.5, 2);
    k.k22 = uniform(0.5, 2);
    k.k12 = uniform(-0.4, 0.4);
    k.k33 = uniform(0.2, 1);
    return k;
  }
  // Random rest triangle, random (possibly compressive, possibly plastic) deformation.
  Case random_case(bool plastic) {
    Case c;
    triangle(c.u);
    const Face f = rest_face(c.u[0], c.u[1], c.u[2]);
    c.Dm_inv = f.Dm_inv;
    c.area = f.rest_area;
    if (plastic) {
      Mat2 P;
      P << uniform(0.7, 1.4), uniform(-0.3, 0.3), uniform(-0.3, 0.3), uniform(0.7, 1.4);
      c.Dm_inv = c.Dm_inv * P;
    }
    Mat3 A = rotation();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) A(i, j) += uniform(-0.4, 0.4);  // general (possibly compressive) map
    const Vec3 t = vec3(-1, 1);
    for (int i = 0; i < 3; ++i) c.x[i] = A * c.u[i] + t + vec3(-0.2, 0.2);
    c.k = stiffness();
    c.factor = uniform(0.5, 2);
    return c;
  }

 private:
  std::mt19937 gen_;
};

Vec9 stack(const Vec3 x[3]) {
  Vec9 q;
  for (int i = 0; i < 3; ++i) q.segment<3>(3 * i) = x[i];
  return q;
}

double energy_at(const Case& c, const Vec9& q) {
  return membrane_energy(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), c.Dm_inv, c.area, c.k, c.factor);
}
Vec9 gradient_at(const Case& c, const Vec9& q) {
  return membrane_gradient(q.segment<3>(0), q.segment<3>(3), q.segment<3>(6), c.Dm_inv, c.area, c.k, c.factor);
}

constexpr double kStep = 1e-6;

TEST(Membrane, GradientMatchesCentralDifferences) {
  Random rnd(11);
  for (int trial = 0; trial < 60; ++trial) {
    const Case c = rnd.random_case(trial % 2 == 1);
    const Vec9 q = stack(c.x);
    const Vec9 g = gradient_at(c, q);
    Vec9 fd;
    for (int i = 0; i < 9; ++i) {
      Vec9 qp = q, qm = q;
      qp(i) += kStep;
      qm(i) -= kStep;
      fd(i) = (energy_at(c, qp) - energy_at(c, qm)) / (2 * kStep);
    }
    ASSERT_GT(g.norm(), 1e-3);
    EXPECT_LT((fd - g).norm(), 1e-6 * g.norm()) << "trial " << trial;
  }
}

TEST(Membrane, HessianMatchesCentralDifferences) {
  Random rnd(12);
  for (int trial = 0; trial < 60; ++trial) {
    const Case c = rnd.random_case(trial % 2 == 1);
    const Vec9 q = stack(c.x);
    const Mat9 H = membrane_hessian(c.x[0], c.x[1], c.x[2], c.Dm_inv, c.area, c.k, c.factor);
    Mat9 fd;
    for (int i = 0; i < 9; ++i) {
      Vec9 qp = q, qm = q;
      qp(i) += kStep;
      qm(i) -= kStep;
      fd.col(i) = (gradient_at(c, qp) - gradient_at(c, qm)) / (2 * kStep);
    }
    EXPECT_LT((fd - H).norm(), 1e-6 * H.norm()) << "trial " << trial;
    EXPECT_LT((H - H.transpose()).norm(), 1e-12 * H.norm());
  }
}

double min_eigenvalue_relative(const Mat9& H) {
  const Vec9 ev = symmetric_eigenvalues<9>(H);
  const double scale = std::max(std::fabs(ev.minCoeff()), std::fabs(ev.maxCoeff()));
  return scale > 0 ? ev.minCoeff() / scale : 0;
}

TEST(Membrane, ProjectedHessianIsPositiveSemiDefinite) {
  Random rnd(13);
  int exact_indefinite = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Case c = rnd.random_case(trial % 3 == 0);
    if (trial % 4 == 0) c.k.k12 = rnd.uniform(-3, -2);  // indefinite stiffness, as in some measured cloths
    const Mat9 P = membrane_hessian_projected(c.x[0], c.x[1], c.x[2], c.Dm_inv, c.area, c.k, c.factor);
    EXPECT_GE(min_eigenvalue_relative(P), -1e-9) << "trial " << trial;
    const Mat9 H = membrane_hessian(c.x[0], c.x[1], c.x[2], c.Dm_inv, c.area, c.k, c.factor);
    if (min_eigenvalue_relative(H) < -1e-6) ++exact_indefinite;
  }
  // The inputs must actually exercise the projection.
  EXPECT_GT(exact_indefinite, 20);
}

TEST(Membrane, ProjectedEqualsExactUnderTension) {
  Random rnd(14);
  for (int trial = 0; trial < 50; ++trial) {
    Vec3 u[3];
    rnd.triangle(u);
    const Face f = rest_face(u[0], u[1], u[2]);
    // Stretch (principal stretches > 1) in the material frame, then a rigid motion: G and S are PSD.
    Mat2 U;
    const double a = rnd.uniform(1.01, 1.3), b = rnd.uniform(1.01, 1.3), angle = rnd.uniform(0, M_PI);
    const Mat2 V = Eigen::Rotation2Dd(angle).toRotationMatrix();
    U = V * Eigen::Vector2d(a, b).asDiagonal() * V.transpose();
    const Mat3 R = rnd.rotation();
    const Vec3 t = rnd.vec3(-1, 1);
    Vec3 x[3];
    for (int i = 0; i < 3; ++i) {
      const Vec2 local = f.rest_frame.transpose() * (u[i] - u[0]);
      x[i] = R * (f.rest_frame * (U * local)) + t;
    }
    MembraneStiffness k;
    const double ks = rnd.uniform(1, 10), nu = rnd.uniform(0, 0.45);
    k.k11 = k.k22 = ks;
    k.k12 = ks * nu;
    k.k33 = ks * (1 - nu);
    const Mat2 S = membrane_stress(membrane_green_strain(x[0], x[1], x[2], f.Dm_inv), k);
    ASSERT_TRUE(S(0, 0) > 0 && S.determinant() > 0);  // positive definite
    const Mat9 H = membrane_hessian(x[0], x[1], x[2], f.Dm_inv, f.rest_area, k);
    const Mat9 P = membrane_hessian_projected(x[0], x[1], x[2], f.Dm_inv, f.rest_area, k);
    EXPECT_LT((H - P).norm(), 1e-12 * H.norm());
  }
  // Under compression the two differ (the projection is not a no-op).
  Vec3 u[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Face f = rest_face(u[0], u[1], u[2]);
  const Vec3 x1(0.8, 0, 0), x2(0, 0.8, 0);
  MembraneStiffness k{1, 0.3, 1, 0.7};
  const Mat9 H = membrane_hessian(u[0], x1, x2, f.Dm_inv, f.rest_area, k);
  const Mat9 P = membrane_hessian_projected(u[0], x1, x2, f.Dm_inv, f.rest_area, k);
  EXPECT_GT((H - P).norm(), 1e-3 * H.norm());
}

TEST(Membrane, RigidMotionOfRestShapeIsStressFree) {
  Random rnd(15);
  for (int trial = 0; trial < 30; ++trial) {
    Vec3 u[3];
    rnd.triangle(u);
    const Face f = rest_face(u[0], u[1], u[2]);
    const Mat3 R = rnd.rotation();
    const Vec3 t = rnd.vec3(-5, 5);
    Vec3 x[3];
    for (int i = 0; i < 3; ++i) x[i] = R * u[i] + t;
    const MembraneStiffness k = rnd.stiffness();
    const MembraneTerms terms = membrane_terms(x[0], x[1], x[2], f.Dm_inv, f.rest_area, k, 1.0,
                                               HessianKind::kExact);
    EXPECT_LT(std::fabs(terms.energy), 1e-25);
    EXPECT_LT(terms.gradient.norm(), 1e-12);
    EXPECT_LT(membrane_green_strain(x[0], x[1], x[2], f.Dm_inv).norm(), 1e-13);
    // The Hessian is still the (nonzero, PSD) stiffness.
    EXPECT_GT(terms.hessian.norm(), 1e-2);
  }
}

TEST(Membrane, PlasticRestShapeIsStressFree) {
  // World = rest stretched in-plane by P; Dm_inv * P^-1 measures that state as the elastic rest state.
  const Vec3 u[3] = {Vec3(0, 0, 0), Vec3(1, 0.1, 0), Vec3(0.2, 0.9, 0)};
  const Face f = rest_face(u[0], u[1], u[2]);
  Mat2 P;
  P << 1.3, 0.1, 0.1, 0.8;
  Vec3 x[3];
  for (int i = 0; i < 3; ++i) x[i] = f.rest_frame * (P * (f.rest_frame.transpose() * u[i])) + Vec3(0, 0, 2);
  const MembraneStiffness k{1, 0.3, 1, 0.7};
  EXPECT_GT(membrane_energy(x[0], x[1], x[2], f.Dm_inv, f.rest_area, k), 1e-3);
  const Mat2 plastic_Dm_inv = f.Dm_inv * P.inverse();
  EXPECT_LT(membrane_energy(x[0], x[1], x[2], plastic_Dm_inv, f.rest_area, k), 1e-25);
  EXPECT_LT(membrane_gradient(x[0], x[1], x[2], plastic_Dm_inv, f.rest_area, k).norm(), 1e-12);
}

TEST(Membrane, UniaxialStretchHasAnalyticStressAndEnergy) {
  // Rest triangle in the xy plane: the material frame is (x, y).
  const Vec3 u[3] = {Vec3(0.1, 0.2, 0), Vec3(1.3, 0.4, 0), Vec3(0.5, 1.1, 0)};
  const Face f = rest_face(u[0], u[1], u[2]);
  ASSERT_NEAR(f.rest_frame.col(0).dot(Vec3::UnitX()), 1, 1e-14);
  const double lambda = 1.2;
  Vec3 x[3];
  for (int i = 0; i < 3; ++i) x[i] = Vec3(lambda * u[i].x(), u[i].y(), u[i].z());
  const MembraneStiffness k{5, 1.5, 4, 2};
  const double factor = 0.5;
  const Mat2 G = membrane_green_strain(x[0], x[1], x[2], f.Dm_inv);
  const double G11 = (lambda * lambda - 1) / 2;
  EXPECT_NEAR(G(0, 0), G11, 1e-14);
  EXPECT_NEAR(G(1, 1), 0, 1e-14);
  EXPECT_NEAR(G(0, 1), 0, 1e-14);
  const Mat2 S = membrane_stress(G, k, factor);
  EXPECT_NEAR(S(0, 0), factor * k.k11 * G11, 1e-13);
  EXPECT_NEAR(S(1, 1), factor * k.k12 * G11, 1e-13);
  EXPECT_NEAR(S(0, 1), 0, 1e-13);
  EXPECT_NEAR(S(1, 0), 0, 1e-13);
  const double area = 0.5 * (u[1] - u[0]).cross(u[2] - u[0]).norm();
  EXPECT_NEAR(f.rest_area, area, 1e-14);
  EXPECT_NEAR(membrane_energy(x[0], x[1], x[2], f.Dm_inv, area, k, factor),
              area * 0.5 * factor * k.k11 * G11 * G11, 1e-14);

  const Vec9 force = -membrane_gradient(x[0], x[1], x[2], f.Dm_inv, area, k, factor);
  Vec3 total = Vec3::Zero(), moment = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    total += force.segment<3>(3 * i);
    moment += x[i].cross(force.segment<3>(3 * i));
  }
  EXPECT_LT(total.norm(), 1e-13);
  EXPECT_LT(moment.norm(), 1e-13);
  // Nodal forces are -A P b_a with the first Piola stress P = F S and b_a the rows of [-1 -1; 1 0; 0 1] Dm_inv.
  const Mat32 F = membrane_deformation_gradient(x[0], x[1], x[2], f.Dm_inv);
  const Mat32 Piola = F * S;
  const Eigen::Matrix<double, 3, 2> shape =
      (Eigen::Matrix<double, 3, 2>() << -1, -1, 1, 0, 0, 1).finished() * f.Dm_inv;
  for (int i = 0; i < 3; ++i)
    EXPECT_LT((force.segment<3>(3 * i) + area * Piola * shape.row(i).transpose()).norm(), 1e-13);
}

TEST(Membrane, SimpleShearHasAnalyticStressAndEnergy) {
  // x = u + gamma * u_y e_x: F = [1 gamma; 0 1], G11 = 0, G12 = gamma / 2, G22 = gamma^2 / 2.
  const Vec3 u[3] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.3, 0.8, 0)};
  const Face f = rest_face(u[0], u[1], u[2]);
  const double gamma = 0.2;
  Vec3 x[3];
  for (int i = 0; i < 3; ++i) x[i] = u[i] + gamma * u[i].y() * Vec3::UnitX();
  const Mat2 G = membrane_green_strain(x[0], x[1], x[2], f.Dm_inv);
  EXPECT_NEAR(G(0, 0), 0, 1e-15);
  EXPECT_NEAR(G(0, 1), gamma / 2, 1e-15);
  EXPECT_NEAR(G(1, 0), gamma / 2, 1e-15);
  EXPECT_NEAR(G(1, 1), gamma * gamma / 2, 1e-15);
  const MembraneStiffness k{5, 1.5, 4, 2};
  const Mat2 S = membrane_stress(G, k);
  EXPECT_NEAR(S(0, 1), k.k33 * gamma / 2, 1e-14);
  EXPECT_NEAR(S(1, 0), k.k33 * gamma / 2, 1e-14);
  EXPECT_NEAR(S(0, 0), k.k12 * gamma * gamma / 2, 1e-14);
  EXPECT_NEAR(S(1, 1), k.k22 * gamma * gamma / 2, 1e-14);
  const double G12 = gamma / 2, G22 = gamma * gamma / 2;
  EXPECT_NEAR(membrane_energy(x[0], x[1], x[2], f.Dm_inv, f.rest_area, k),
              f.rest_area * 0.5 * (k.k22 * G22 * G22 + 2 * k.k33 * G12 * G12), 1e-15);
}

TEST(Membrane, EnergyMatchesDensityFormula) {
  // The documented density, written out term by term from an independently computed Green strain.
  Random rnd(18);
  for (int trial = 0; trial < 20; ++trial) {
    const Case c = rnd.random_case(true);
    Eigen::Matrix<double, 3, 2> Ds;
    Ds << c.x[1] - c.x[0], c.x[2] - c.x[0];
    const Mat32 F = Ds * c.Dm_inv;
    const double G11 = 0.5 * (F.col(0).squaredNorm() - 1), G22 = 0.5 * (F.col(1).squaredNorm() - 1);
    const double G12 = 0.5 * F.col(0).dot(F.col(1));
    const MembraneStiffness& k = c.k;
    const double density =
        0.5 * (k.k11 * G11 * G11 + 2 * k.k12 * G11 * G22 + k.k22 * G22 * G22 + 2 * k.k33 * G12 * G12);
    const double E = membrane_energy(c.x[0], c.x[1], c.x[2], c.Dm_inv, c.area, c.k, c.factor);
    EXPECT_NEAR(E, c.factor * c.area * density, 1e-12 * E);
  }
}

TEST(Membrane, ForcesHaveZeroSumAndZeroMoment) {
  Random rnd(16);
  for (int trial = 0; trial < 50; ++trial) {
    const Case c = rnd.random_case(trial % 2 == 0);
    const Vec9 g = membrane_gradient(c.x[0], c.x[1], c.x[2], c.Dm_inv, c.area, c.k, c.factor);
    Vec3 total = Vec3::Zero(), moment = Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
      total += g.segment<3>(3 * i);
      moment += c.x[i].cross(g.segment<3>(3 * i));
    }
    EXPECT_LT(total.norm(), 1e-12 * g.norm());
    EXPECT_LT(moment.norm(), 1e-11 * g.norm());
  }
}

TEST(Membrane, EnergyIsHalfStrainDotStressAndScalesWithFactor) {
  Random rnd(17);
  for (int trial = 0; trial < 20; ++trial) {
    const Case c = rnd.random_case(false);
    const Mat2 G = membrane_green_strain(c.x[0], c.x[1], c.x[2], c.Dm_inv);
    const Mat2 S = membrane_stress(G, c.k, c.factor);
    const double E = membrane_energy(c.x[0], c.x[1], c.x[2], c.Dm_inv, c.area, c.k, c.factor);
    EXPECT_NEAR(E, 0.5 * c.area * (G.cwiseProduct(S)).sum(), 1e-12 * E);
    EXPECT_NEAR(2 * E, membrane_energy(c.x[0], c.x[1], c.x[2], c.Dm_inv, c.area, c.k, 2 * c.factor),
                1e-12 * E);
    // Combined evaluation agrees with the single ones.
    const MembraneTerms none =
        membrane_terms(c.x[0], c.x[1], c.x[2], c.Dm_inv, c.area, c.k, c.factor, HessianKind::kNone);
    EXPECT_NEAR(none.energy, E, 1e-12 * E);
    EXPECT_EQ(none.hessian.norm(), 0);
    EXPECT_LT((none.gradient - membrane_gradient(c.x[0], c.x[1], c.x[2], c.Dm_inv, c.area, c.k, c.factor))
                  .norm(),
              1e-14 * none.gradient.norm());
  }
}

}  // namespace
}  // namespace arcsim
