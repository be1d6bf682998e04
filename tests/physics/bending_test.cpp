#include "physics/bending.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "mesh/mesh.hpp"
#include "support/eigenvalues.hpp"

namespace arcsim {
namespace {

using testing::symmetric_eigenvalues;

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
  double theta_bar = 0;
  double weight = 1;
};

// A random non-degenerate hinge with |theta| and |theta - theta_bar| away from pi (where the angle wraps).
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
    h.theta_bar = rnd.uniform(-1.5, 1.5);
    h.weight = rnd.uniform(0.1, 3);
    const double theta = dihedral_angle(h.x[0], h.x[1], h.x[2], h.x[3]);
    if (std::fabs(theta) < 2.8 && std::fabs(theta - h.theta_bar) < 2.8) return h;
  }
}

Vec12 stack(const Vec3 x[4]) {
  Vec12 q;
  for (int i = 0; i < 4; ++i) q.segment<3>(3 * i) = x[i];
  return q;
}
Vec3 node(const Vec12& q, int i) { return q.segment<3>(3 * i); }

double energy_at(const Hinge& h, const Vec12& q) {
  return hinge_energy(node(q, 0), node(q, 1), node(q, 2), node(q, 3), h.theta_bar, h.weight);
}
Vec12 gradient_at(const Hinge& h, const Vec12& q) {
  return hinge_gradient(node(q, 0), node(q, 1), node(q, 2), node(q, 3), h.theta_bar, h.weight);
}

constexpr double kStep = 1e-6;

TEST(HingeBending, ThetaGradientMatchesCentralDifferencesOfDihedralAngle) {
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

TEST(HingeBending, GradientMatchesCentralDifferences) {
  Random rnd(22);
  for (int trial = 0; trial < 60; ++trial) {
    const Hinge h = random_hinge(rnd);
    const Vec12 q = stack(h.x);
    const Vec12 g = gradient_at(h, q);
    Vec12 fd;
    for (int i = 0; i < 12; ++i) {
      Vec12 qp = q, qm = q;
      qp(i) += kStep;
      qm(i) -= kStep;
      fd(i) = (energy_at(h, qp) - energy_at(h, qm)) / (2 * kStep);
    }
    ASSERT_GT(g.norm(), 1e-4);
    EXPECT_LT((fd - g).norm(), 1e-6 * g.norm()) << "trial " << trial;
  }
}

TEST(HingeBending, HessianMatchesCentralDifferences) {
  Random rnd(23);
  for (int trial = 0; trial < 60; ++trial) {
    const Hinge h = random_hinge(rnd);
    const Vec12 q = stack(h.x);
    const Mat12 H = hinge_hessian(h.x[0], h.x[1], h.x[2], h.x[3], h.theta_bar, h.weight);
    Mat12 fd;
    for (int i = 0; i < 12; ++i) {
      Vec12 qp = q, qm = q;
      qp(i) += kStep;
      qm(i) -= kStep;
      fd.col(i) = (gradient_at(h, qp) - gradient_at(h, qm)) / (2 * kStep);
    }
    EXPECT_LT((fd - H).norm(), 1e-6 * H.norm()) << "trial " << trial;
    // The theta Hessian alone (the part AutoDiff computes).
    const Mat12 Ht = dihedral_angle_hessian(h.x[0], h.x[1], h.x[2], h.x[3]);
    Mat12 fd_theta;
    for (int i = 0; i < 12; ++i) {
      Vec12 qp = q, qm = q;
      qp(i) += kStep;
      qm(i) -= kStep;
      fd_theta.col(i) = (dihedral_angle_gradient(node(qp, 0), node(qp, 1), node(qp, 2), node(qp, 3)) -
                         dihedral_angle_gradient(node(qm, 0), node(qm, 1), node(qm, 2), node(qm, 3))) /
                        (2 * kStep);
    }
    EXPECT_LT((fd_theta - Ht).norm(), 1e-6 * Ht.norm()) << "trial " << trial;
  }
}

TEST(HingeBending, GaussNewtonHessianIsPsdAndExactAtRest) {
  Random rnd(24);
  for (int trial = 0; trial < 30; ++trial) {
    Hinge h = random_hinge(rnd);
    const Mat12 gn = hinge_hessian_gauss_newton(h.x[0], h.x[1], h.x[2], h.x[3], h.weight);
    const Vec12 gt = dihedral_angle_gradient(h.x[0], h.x[1], h.x[2], h.x[3]);
    EXPECT_LT((gn - 2 * h.weight * gt * gt.transpose()).norm(), 1e-12 * gn.norm());
    const Vec12 ev = symmetric_eigenvalues<12>(gn);
    EXPECT_GE(ev.minCoeff(), -1e-12 * ev.maxCoeff());
    const HingeTerms projected =
        hinge_terms(h.x[0], h.x[1], h.x[2], h.x[3], h.theta_bar, h.weight, HessianKind::kProjected);
    EXPECT_LT((projected.hessian - gn).norm(), 1e-12 * gn.norm());
    // At the rest angle the exact Hessian reduces to Gauss-Newton, energy and force vanish.
    h.theta_bar = dihedral_angle(h.x[0], h.x[1], h.x[2], h.x[3]);
    const HingeTerms rest =
        hinge_terms(h.x[0], h.x[1], h.x[2], h.x[3], h.theta_bar, h.weight, HessianKind::kExact);
    EXPECT_EQ(rest.energy, 0);
    EXPECT_EQ(rest.gradient.norm(), 0);
    EXPECT_LT((rest.hessian - gn).norm(), 1e-12 * gn.norm());
  }
}

TEST(HingeBending, InvariantUnderRigidMotion) {
  Random rnd(25);
  for (int trial = 0; trial < 30; ++trial) {
    const Hinge h = random_hinge(rnd);
    const Mat3 R = rnd.rotation();
    const Vec3 t = rnd.vec3(-10, 10);
    Vec3 y[4];
    for (int i = 0; i < 4; ++i) y[i] = R * h.x[i] + t;
    const HingeTerms a =
        hinge_terms(h.x[0], h.x[1], h.x[2], h.x[3], h.theta_bar, h.weight, HessianKind::kExact);
    const HingeTerms b = hinge_terms(y[0], y[1], y[2], y[3], h.theta_bar, h.weight, HessianKind::kExact);
    EXPECT_NEAR(a.theta, b.theta, 1e-12);
    EXPECT_NEAR(a.energy, b.energy, 1e-12 * (1 + a.energy));
    Vec3 total = Vec3::Zero(), moment = Vec3::Zero();
    for (int i = 0; i < 4; ++i) {
      EXPECT_LT((b.gradient.segment<3>(3 * i) - R * a.gradient.segment<3>(3 * i)).norm(),
                1e-10 * a.gradient.norm());
      total += a.gradient.segment<3>(3 * i);
      moment += h.x[i].cross(a.gradient.segment<3>(3 * i));
    }
    // Translation and rotation invariance of the energy: zero net force and zero net moment.
    EXPECT_LT(total.norm(), 1e-12 * a.gradient.norm());
    EXPECT_LT(moment.norm(), 1e-11 * a.gradient.norm());
  }
}

TEST(HingeBending, SymmetricUnderSwappingEdgeEndsAndWings) {
  // Hinge (x1, x0, x3, x2) is the same hinge seen from face B: same angle, permuted gradient.
  Random rnd(26);
  const int perm[4] = {1, 0, 3, 2};
  for (int trial = 0; trial < 30; ++trial) {
    const Hinge h = random_hinge(rnd);
    const HingeTerms a =
        hinge_terms(h.x[0], h.x[1], h.x[2], h.x[3], h.theta_bar, h.weight, HessianKind::kExact);
    const HingeTerms b =
        hinge_terms(h.x[1], h.x[0], h.x[3], h.x[2], h.theta_bar, h.weight, HessianKind::kExact);
    EXPECT_NEAR(a.theta, b.theta, 1e-13);
    EXPECT_NEAR(a.energy, b.energy, 1e-13 * (1 + a.energy));
    for (int i = 0; i < 4; ++i) {
      EXPECT_LT((b.gradient.segment<3>(3 * i) - a.gradient.segment<3>(3 * perm[i])).norm(),
                1e-12 * a.gradient.norm());
      for (int j = 0; j < 4; ++j)
        EXPECT_LT((b.hessian.block<3, 3>(3 * i, 3 * j) - a.hessian.block<3, 3>(3 * perm[i], 3 * perm[j])).norm(),
                  1e-11 * a.hessian.norm());
    }
  }
}

TEST(HingeBending, SignConventionFollowsDihedralAngle) {
  // Flat hinge in the xy plane with both face normals +z; lifting the wings (+z) folds to negative theta.
  const Vec3 x0(0, 0, 0), x1(1, 0, 0), x2(0.5, 1, 0), x3(0.4, -1, 0);
  const Vec12 g = dihedral_angle_gradient(x0, x1, x2, x3);
  EXPECT_NEAR(g(8), -1, 1e-14);   // d theta / d x2.z = -1 / height
  EXPECT_NEAR(g(11), -1, 1e-14);  // d theta / d x3.z
  EXPECT_LT(dihedral_angle(x0, x1, Vec3(0.5, 1, 0.1), x3), 0);
  // The energy pulls a folded hinge back towards its rest angle.
  const Vec3 lifted(0.5, 1, 0.3);
  const Vec12 grad = hinge_gradient(x0, x1, lifted, x3, 0, 1);
  EXPECT_GT(grad(8), 0);  // force -grad pushes the lifted wing back down
}

TEST(HingeBending, AngleDifferenceIsWrapped) {
  EXPECT_NEAR(wrap_angle(0.3), 0.3, 1e-15);
  EXPECT_NEAR(wrap_angle(-2 * M_PI + 0.3), 0.3, 1e-15);
  EXPECT_NEAR(wrap_angle(2 * M_PI - 0.3), -0.3, 1e-15);
  EXPECT_NEAR(wrap_angle(M_PI), M_PI, 1e-15);
  EXPECT_NEAR(wrap_angle(-M_PI), M_PI, 1e-15);
  EXPECT_NEAR(wrap_angle(5 * M_PI + 0.1), -M_PI + 0.1, 1e-13);
  // A hinge at theta with rest angle theta + 2 pi - 0.3 is 0.3 rad from rest, not 2 pi - 0.3.
  Random rnd(27);
  const Hinge h = random_hinge(rnd);
  const double theta = dihedral_angle(h.x[0], h.x[1], h.x[2], h.x[3]);
  const double theta_bar = theta + 2 * M_PI - 0.3;
  EXPECT_NEAR(hinge_energy(h.x[0], h.x[1], h.x[2], h.x[3], theta_bar, 2.0), 2.0 * 0.09, 1e-12);
  const Vec12 expected = 2 * 2.0 * 0.3 * dihedral_angle_gradient(h.x[0], h.x[1], h.x[2], h.x[3]);
  EXPECT_LT((hinge_gradient(h.x[0], h.x[1], h.x[2], h.x[3], theta_bar, 2.0) - expected).norm(),
            1e-12 * expected.norm());
}

bool all_finite(const HingeTerms& t) {
  return std::isfinite(t.theta) && std::isfinite(t.energy) && t.gradient.allFinite() && t.hessian.allFinite();
}

TEST(HingeBending, DegenerateHingesStayFinite) {
  const Vec3 x0(0, 0, 0), x1(1, 0, 0), x3(0.5, -1, 0.2);
  const double weight = 1.5, theta_bar = 0.4;
  const Vec3 wings[] = {
      Vec3(0.5, 0, 0),      // on the edge: zero-area face
      Vec3(0, 0, 0),        // on an edge node
      Vec3(3, 0, 0),        // on the edge line, outside the edge
      Vec3(0.5, 1e-12, 0),  // sliver: height far below the floor
      Vec3(0.5, 0, 1e-9),
  };
  for (const Vec3& x2 : wings) {
    for (HessianKind kind : {HessianKind::kExact, HessianKind::kProjected}) {
      const HingeTerms t = hinge_terms(x0, x1, x2, x3, theta_bar, weight, kind);
      EXPECT_TRUE(all_finite(t)) << x2.transpose();
      // The floored wing height (1e-3 edge length) bounds d theta / d x2 by 1 / (1e-3 * l).
      EXPECT_LE(t.gradient.segment<3>(6).norm(), 2 * weight * std::fabs(wrap_angle(t.theta - theta_bar)) * 1e3 *
                                                      (1 + 1e-12));
    }
    const HingeTerms swapped = hinge_terms(x1, x0, x3, x2, theta_bar, weight, HessianKind::kExact);
    EXPECT_TRUE(all_finite(swapped));
  }
  // Zero-length edge and fully collapsed hinge.
  for (const Vec3& y1 : {x0, Vec3(1e-200, 0, 0)}) {
    const HingeTerms t = hinge_terms(x0, y1, Vec3(0.5, 1, 0), x3, theta_bar, weight, HessianKind::kExact);
    EXPECT_TRUE(all_finite(t));
  }
  const HingeTerms collapsed = hinge_terms(x0, x0, x0, x0, theta_bar, weight, HessianKind::kExact);
  EXPECT_TRUE(all_finite(collapsed));
  EXPECT_EQ(collapsed.gradient.norm(), 0);
}

TEST(HingeBending, HingeWeight) {
  EXPECT_NEAR(hinge_weight(2.0, 0.5, 0.1, 0.3), 2.0 * 0.25 / (2 * 0.4), 1e-15);
  EXPECT_EQ(hinge_weight(2.0, 0.5, 0, 0), 0);
  EXPECT_EQ(hinge_weight(2.0, 0.5, -1, 0.5), 0);
}

// A patch of equilateral triangles (edge a, flat in the xy plane, rotated in-plane by `angle`) wrapped onto a
// cylinder of radius R whose axis is along y. Returns total hinge energy over interior edges divided by the
// continuum plate energy (1/2) kb Area / R^2, Area being the share of the faces that belongs to those edges
// (a third of each adjacent face).
double cylinder_energy_ratio(int rows, int cols, double a, double angle, double R) {
  std::vector<Vec3> u, x;
  std::vector<int> vert_node;
  std::vector<std::array<int, 3>> tris;
  const double row_height = a * std::sqrt(3.0) / 2;
  const Eigen::Rotation2Dd rotation(angle);
  for (int j = 0; j <= rows; ++j) {
    for (int i = 0; i <= cols; ++i) {
      const Vec2 flat = rotation * Vec2(i * a + (j % 2) * a / 2 - cols * a / 2, j * row_height - rows * row_height / 2);
      u.emplace_back(flat.x(), flat.y(), 0);
      x.emplace_back(R * std::sin(flat.x() / R), flat.y(), R * (1 - std::cos(flat.x() / R)));
      vert_node.push_back(static_cast<int>(vert_node.size()));
    }
  }
  auto id = [cols](int j, int i) { return j * (cols + 1) + i; };
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      if (j % 2 == 0) {
        tris.push_back({id(j, i), id(j, i + 1), id(j + 1, i)});
        tris.push_back({id(j, i + 1), id(j + 1, i + 1), id(j + 1, i)});
      } else {
        tris.push_back({id(j, i), id(j + 1, i + 1), id(j + 1, i)});
        tris.push_back({id(j, i), id(j, i + 1), id(j + 1, i + 1)});
      }
    }
  }
  const Mesh mesh = Mesh::from_triangles(x, u, vert_node, tris);
  const double kb = 0.7;
  double energy = 0, area = 0;
  for (int e = 0; e < static_cast<int>(mesh.edges.size()); ++e) {
    const Edge& edge = mesh.edges[e];
    if (edge.is_boundary()) continue;
    const double A0 = mesh.faces[edge.f[0]].rest_area, A1 = mesh.faces[edge.f[1]].rest_area;
    const double l = (u[edge.n[0]] - u[edge.n[1]]).norm();  // vert k is node k here
    EXPECT_NEAR(l, a, 1e-12 * a);
    EXPECT_EQ(edge.rest_theta, 0);
    energy += hinge_energy(mesh.nodes[edge.n[0]].x, mesh.nodes[edge.n[1]].x,
                           mesh.nodes[mesh.opposite_node(e, edge.f[0])].x,
                           mesh.nodes[mesh.opposite_node(e, edge.f[1])].x, edge.rest_theta,
                           hinge_weight(kb, l, A0, A1));
    area += (A0 + A1) / 3;
  }
  return energy / (0.5 * kb * area / (R * R));
}

TEST(HingeBending, CylinderDihedralAngleOfEquilateralPair) {
  // The relation hinge_weight's comment relies on: theta = h (kappa_nn - kappa_tt / 3) for an equilateral pair
  // (height h) whose edge normal n makes angle psi with the curvature direction.
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

TEST(HingeBending, CylinderMatchesContinuumPlateEnergy) {
  const double R = 1;
  for (double angle : {0.0, M_PI / 2, 0.3}) {
    const double coarse = cylinder_energy_ratio(12, 12, 0.04, angle, R);
    const double fine = cylinder_energy_ratio(48, 48, 0.01, angle, R);
    EXPECT_NEAR(coarse, 1, 0.05) << "angle " << angle;
    EXPECT_NEAR(fine, 1, 0.01) << "angle " << angle;
    EXPECT_LT(std::fabs(fine - 1), std::fabs(coarse - 1) + 1e-4) << "angle " << angle;
  }
}

}  // namespace
}  // namespace arcsim
