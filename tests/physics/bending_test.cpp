// The dihedral angle's derivatives (physics/bending.hpp), which the plate bending energy and the world-space
// reprojection build on: closed-form gradient and AutoDiff Hessian against central differences, invariance
// under rigid motions and under relabelling the hinge, the sign convention, angle wrapping, degenerate hinges,
// and the angle of an equilateral pair on a cylinder.
#include "physics/bending.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "mesh/mesh.hpp"

namespace arcsim {
namespace {

class Random {
 public:
  explicit Random(unsigned seed) : gen_(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(gen_); }
  Vec3 vec3(double lo, double hi) { return Vec3(uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)); }
  Mat3 rotation() {
    Eigen::Quaterniond q(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    return q.normalized().toRotationMatrix();
  }

 private:
  std::mt19937 gen_;
};

struct Hinge {
  Vec3 x[4];
};

// A random non-degenerate hinge with |theta| away from pi (where the angle wraps).
Hinge random_hinge(Random& rnd) {
  for (;;) {
    Hinge h;
    const Mat3 R = rnd.rotation();
    const Vec3 t = rnd.vec3(-1, 1);
    const double l = rnd.uniform(0.5, 1.5);
    const double fold_a = rnd.uniform(-1.2, 1.2), fold_b = rnd.uniform(-1.2, 1.2);
    const double ha = rnd.uniform(0.3, 1.2), hb = rnd.uniform(0.3, 1.2);
    h.x[0] = t;
    h.x[1] = t + R * Vec3(l, 0, 0);
    h.x[2] = t + R * Vec3(rnd.uniform(-0.5, 1.5) * l, ha * std::cos(fold_a), ha * std::sin(fold_a));
    h.x[3] = t + R * Vec3(rnd.uniform(-0.5, 1.5) * l, -hb * std::cos(fold_b), hb * std::sin(fold_b));
    if (std::fabs(dihedral_angle(h.x[0], h.x[1], h.x[2], h.x[3])) < 2.8) return h;
  }
}

Vec12 stack(const Vec3 x[4]) {
  Vec12 q;
  for (int i = 0; i < 4; ++i) q.segment<3>(3 * i) = x[i];
  return q;
}
Vec3 node(const Vec12& q, int i) { return q.segment<3>(3 * i); }

constexpr double kStep = 1e-6;

TEST(DihedralAngle, GradientMatchesCentralDifferences) {
  Random rnd(21);
  for (int trial = 0; trial < 60; ++trial) {
    const Hinge h = random_hinge(rnd);
    const Vec12 q = stack(h.x);
    const Vec12 g = dihedral_angle_gradient(h.x[0], h.x[1], h.x[2], h.x[3]);
    Vec12 fd;
    for (int i = 0; i < 12; ++i) {
      Vec12 qp = q, qm = q;
      qp(i) += kStep;
      qm(i) -= kStep;
      fd(i) = (dihedral_angle(node(qp, 0), node(qp, 1), node(qp, 2), node(qp, 3)) -
               dihedral_angle(node(qm, 0), node(qm, 1), node(qm, 2), node(qm, 3))) /
              (2 * kStep);
    }
    EXPECT_LT((fd - g).norm(), 1e-6 * g.norm()) << "trial " << trial;
  }
}

TEST(DihedralAngle, HessianMatchesCentralDifferencesOfGradient) {
  Random rnd(23);
  for (int trial = 0; trial < 60; ++trial) {
    const Hinge h = random_hinge(rnd);
    const Vec12 q = stack(h.x);
    const Mat12 H = dihedral_angle_hessian(h.x[0], h.x[1], h.x[2], h.x[3]);
    Mat12 fd;
    for (int i = 0; i < 12; ++i) {
      Vec12 qp = q, qm = q;
      qp(i) += kStep;
      qm(i) -= kStep;
      fd.col(i) = (dihedral_angle_gradient(node(qp, 0), node(qp, 1), node(qp, 2), node(qp, 3)) -
                   dihedral_angle_gradient(node(qm, 0), node(qm, 1), node(qm, 2), node(qm, 3))) /
                  (2 * kStep);
    }
    EXPECT_LT((fd - H).norm(), 1e-6 * H.norm()) << "trial " << trial;
    EXPECT_EQ((H - H.transpose()).norm(), 0) << "trial " << trial;
  }
}

TEST(DihedralAngle, InvariantUnderRigidMotion) {
  Random rnd(25);
  for (int trial = 0; trial < 30; ++trial) {
    const Hinge h = random_hinge(rnd);
    const Mat3 R = rnd.rotation();
    const Vec3 t = rnd.vec3(-10, 10);
    Vec3 y[4];
    for (int i = 0; i < 4; ++i) y[i] = R * h.x[i] + t;
    EXPECT_NEAR(dihedral_angle(h.x[0], h.x[1], h.x[2], h.x[3]), dihedral_angle(y[0], y[1], y[2], y[3]), 1e-12);
    const Vec12 a = dihedral_angle_gradient(h.x[0], h.x[1], h.x[2], h.x[3]);
    const Vec12 b = dihedral_angle_gradient(y[0], y[1], y[2], y[3]);
    Vec3 total = Vec3::Zero(), moment = Vec3::Zero();
    for (int i = 0; i < 4; ++i) {
      EXPECT_LT((b.segment<3>(3 * i) - R * a.segment<3>(3 * i)).norm(), 1e-10 * a.norm());
      total += a.segment<3>(3 * i);
      moment += h.x[i].cross(a.segment<3>(3 * i));
    }
    // theta does not change under translations and rotations: its gradient has no net force or moment.
    EXPECT_LT(total.norm(), 1e-12 * a.norm());
    EXPECT_LT(moment.norm(), 1e-11 * a.norm());
  }
}

TEST(DihedralAngle, SymmetricUnderSwappingEdgeEndsAndWings) {
  // Hinge (x1, x0, x3, x2) is the same hinge seen from face B: same angle, permuted derivatives.
  Random rnd(26);
  const int perm[4] = {1, 0, 3, 2};
  for (int trial = 0; trial < 30; ++trial) {
    const Hinge h = random_hinge(rnd);
    EXPECT_NEAR(dihedral_angle(h.x[0], h.x[1], h.x[2], h.x[3]), dihedral_angle(h.x[1], h.x[0], h.x[3], h.x[2]),
                1e-13);
    const Vec12 ga = dihedral_angle_gradient(h.x[0], h.x[1], h.x[2], h.x[3]);
    const Vec12 gb = dihedral_angle_gradient(h.x[1], h.x[0], h.x[3], h.x[2]);
    const Mat12 Ha = dihedral_angle_hessian(h.x[0], h.x[1], h.x[2], h.x[3]);
    const Mat12 Hb = dihedral_angle_hessian(h.x[1], h.x[0], h.x[3], h.x[2]);
    for (int i = 0; i < 4; ++i) {
      EXPECT_LT((gb.segment<3>(3 * i) - ga.segment<3>(3 * perm[i])).norm(), 1e-12 * ga.norm());
      for (int j = 0; j < 4; ++j)
        EXPECT_LT((Hb.block<3, 3>(3 * i, 3 * j) - Ha.block<3, 3>(3 * perm[i], 3 * perm[j])).norm(),
                  1e-11 * Ha.norm());
    }
  }
}

TEST(DihedralAngle, SignConvention) {
  // Flat hinge in the xy plane with both face normals +z; lifting the wings (+z) folds to negative theta.
  const Vec3 x0(0, 0, 0), x1(1, 0, 0), x2(0.5, 1, 0), x3(0.4, -1, 0);
  const Vec12 g = dihedral_angle_gradient(x0, x1, x2, x3);
  EXPECT_NEAR(g(8), -1, 1e-14);   // d theta / d x2.z = -1 / height
  EXPECT_NEAR(g(11), -1, 1e-14);  // d theta / d x3.z
  EXPECT_LT(dihedral_angle(x0, x1, Vec3(0.5, 1, 0.1), x3), 0);
}

TEST(DihedralAngle, AngleDifferencesAreWrapped) {
  EXPECT_NEAR(wrap_angle(0.3), 0.3, 1e-15);
  EXPECT_NEAR(wrap_angle(-2 * M_PI + 0.3), 0.3, 1e-15);
  EXPECT_NEAR(wrap_angle(2 * M_PI - 0.3), -0.3, 1e-15);
  EXPECT_NEAR(wrap_angle(M_PI), M_PI, 1e-15);
  EXPECT_NEAR(wrap_angle(-M_PI), M_PI, 1e-15);
  EXPECT_NEAR(wrap_angle(5 * M_PI + 0.1), -M_PI + 0.1, 1e-13);
}

TEST(DihedralAngle, DegenerateHingesStayFinite) {
  const Vec3 x0(0, 0, 0), x1(1, 0, 0), x3(0.5, -1, 0.2);
  const Vec3 wings[] = {
      Vec3(0.5, 0, 0),      // on the edge: zero-area face
      Vec3(0, 0, 0),        // on an edge node
      Vec3(3, 0, 0),        // on the edge line, outside the edge
      Vec3(0.5, 1e-12, 0),  // sliver: height far below the floor
      Vec3(0.5, 0, 1e-9),
  };
  for (const Vec3& x2 : wings) {
    const Vec12 g = dihedral_angle_gradient(x0, x1, x2, x3);
    EXPECT_TRUE(g.allFinite()) << x2.transpose();
    EXPECT_TRUE(dihedral_angle_hessian(x0, x1, x2, x3).allFinite()) << x2.transpose();
    // The floored wing height (1e-3 edge length) bounds d theta / d x2 by 1 / (1e-3 * l).
    EXPECT_LE(g.segment<3>(6).norm(), 1e3 * (1 + 1e-12)) << x2.transpose();
    EXPECT_TRUE(dihedral_angle_gradient(x1, x0, x3, x2).allFinite()) << x2.transpose();
  }
  // Zero-length edge and fully collapsed hinge.
  for (const Vec3& y1 : {x0, Vec3(1e-200, 0, 0)}) {
    EXPECT_TRUE(dihedral_angle_gradient(x0, y1, Vec3(0.5, 1, 0), x3).allFinite());
    EXPECT_TRUE(dihedral_angle_hessian(x0, y1, Vec3(0.5, 1, 0), x3).allFinite());
  }
  EXPECT_EQ(dihedral_angle_gradient(x0, x0, x0, x0).norm(), 0);
  EXPECT_EQ(dihedral_angle_hessian(x0, x0, x0, x0).norm(), 0);
}

TEST(DihedralAngle, EquilateralPairOnCylinder) {
  // theta = h (kappa_nn - kappa_tt / 3) for an equilateral pair (height h) whose edge normal n makes angle psi
  // with the curvature direction of a cylinder of radius R.
  const double R = 2, a = 0.01, h = a * std::sqrt(3.0) / 2;
  auto on_cylinder = [R](const Vec2& p) {
    return Vec3(R * std::sin(p.x() / R), p.y(), R * (1 - std::cos(p.x() / R)));
  };
  for (double psi : {0.0, 0.4, 1.0, M_PI / 3, 1.3, M_PI / 2}) {
    const Vec2 n(std::cos(psi), std::sin(psi)), t(-std::sin(psi), std::cos(psi));
    const Vec2 p0 = Vec2(0.1, 0.2) - 0.5 * a * t, p1 = Vec2(0.1, 0.2) + 0.5 * a * t;
    const double theta = dihedral_angle(on_cylinder(p0), on_cylinder(p1), on_cylinder(Vec2(0.1, 0.2) - h * n),
                                        on_cylinder(Vec2(0.1, 0.2) + h * n));
    const double c2 = n.x() * n.x(), s2 = t.x() * t.x();
    EXPECT_NEAR(std::fabs(theta), h / R * std::fabs(c2 - s2 / 3), 1e-3 * h / R) << "psi " << psi;
  }
}

}  // namespace
}  // namespace arcsim
