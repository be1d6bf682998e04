// Plate bending element (paper Eq. 3 strain, plate energy): derivatives against finite differences, PSD of the
// solver Hessian, invariance, and the continuum limit on a cylinder for several mesh types and directions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "physics/bending.hpp"
#include "physics/cloth_physics.hpp"
#include "physics/plate_bending.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

struct Element {
  std::array<Vec3, 6> x;
  std::array<bool, 3> has_wing{true, true, true};
  Vec3 rest_theta;
  Mat3 Q;
};

// A random face with three wings, randomly perturbed and with random rest angles (curved rest shape).
Element random_element(std::mt19937& rng, bool boundary_edge) {
  std::uniform_real_distribution<double> u(-1, 1);
  Element e;
  e.x[0] = Vec3(0, 0, 0);
  e.x[1] = Vec3(1, 0, 0);
  e.x[2] = Vec3(0.4, 0.9, 0);
  // wing i across edge (i, i+1), on the far side from the opposite corner
  for (int i = 0; i < 3; ++i) {
    const Vec3 mid = 0.5 * (e.x[i] + e.x[(i + 1) % 3]);
    e.x[3 + i] = mid + (mid - e.x[(i + 2) % 3]) * 0.8;
  }
  for (auto& p : e.x) p += 0.15 * Vec3(u(rng), u(rng), u(rng));
  if (boundary_edge) e.has_wing[1] = false;
  e.rest_theta = Vec3(0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng));
  std::array<double, 3> lengths{1.0, 1.1, 0.95};
  std::array<Vec3, 3> normals{Vec3(0, -1, 0), Vec3(0.7, 0.7, 0).normalized(), Vec3(-1, 0.2, 0).normalized()};
  e.Q = plate_bending_matrix(lengths, normals, 0.45, 2.0, 0.3, e.has_wing);
  return e;
}

// The energy-only evaluation: the finite differences below check plate_bending_terms' gradient against it.
double energy(const Element& e) { return plate_bending_energy(e.x, e.has_wing, e.rest_theta, e.Q); }

TEST(PlateBending, EnergyAloneEqualsTheTermsEnergyBitForBit) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    const Element e = random_element(rng, trial % 4 == 3);
    const double terms = plate_bending_terms(e.x, e.has_wing, e.rest_theta, e.Q, HessianKind::kNone).energy;
    EXPECT_GT(terms, 0) << "trial " << trial;
    EXPECT_EQ(energy(e), terms) << "trial " << trial;  // the step's energy check must see the same numbers
  }
}

// The Gauss-Newton Hessian as its comment defines it, every block a general 3x3 product: the element takes the
// blocks of wing slots (G_p with one nonzero column) as outer products, which must give the same bits, signed
// zeros included (flat, axis-aligned elements have exact zeros in their gradients).
Mat18 general_product_hessian(const Element& e) {
  std::array<Vec12, 3> grad;
  for (int i = 0; i < 3; ++i) {
    grad[i].setZero();
    if (!e.has_wing[i]) continue;
    const auto s = plate_hinge_slots(i);
    grad[i] = dihedral_angle_gradient(e.x[s[0]], e.x[s[1]], e.x[s[2]], e.x[s[3]]);
  }
  std::array<Mat3, 6> G;
  for (Mat3& g : G) g.setZero();
  for (int i = 0; i < 3; ++i) {
    if (!e.has_wing[i]) continue;
    const auto s = plate_hinge_slots(i);
    for (int a = 0; a < 4; ++a) G[s[a]].col(i) = grad[i].segment<3>(3 * a);
  }
  Mat18 H = Mat18::Zero();
  std::array<Mat3, 6> GQ;
  for (int p = 0; p < 6; ++p) GQ[p] = 2 * G[p] * e.Q;
  for (int p = 0; p < 6; ++p) {
    if (p >= 3 && !e.has_wing[p - 3]) continue;
    for (int q = p; q < 6; ++q) {
      if (q >= 3 && !e.has_wing[q - 3]) continue;
      const Mat3 block = GQ[p] * G[q].transpose();
      H.block<3, 3>(3 * p, 3 * q) = block;
      if (q != p) H.block<3, 3>(3 * q, 3 * p) = block.transpose();
    }
  }
  return H;
}

TEST(PlateBending, WingBlocksAreTheGeneralProductsBitForBit) {
  std::mt19937 rng(21);
  std::vector<Element> elements;
  for (int trial = 0; trial < 40; ++trial) elements.push_back(random_element(rng, trial % 4 == 3));
  // Flat in the xy plane, corners on the axes: gradients along z only, exact zeros elsewhere.
  Element flat = random_element(rng, false);
  for (auto& p : flat.x) p.z() = 0;
  flat.x[0] = Vec3(0, 0, 0), flat.x[1] = Vec3(1, 0, 0), flat.x[2] = Vec3(0, 1, 0);
  elements.push_back(flat);
  flat.has_wing[2] = false;
  elements.push_back(flat);
  for (size_t k = 0; k < elements.size(); ++k) {
    const Element& e = elements[k];
    const Mat18 got = plate_bending_terms(e.x, e.has_wing, e.rest_theta, e.Q, HessianKind::kProjected).hessian;
    const Mat18 expected = general_product_hessian(e);
    EXPECT_EQ(std::memcmp(got.data(), expected.data(), sizeof(Mat18)), 0) << "element " << k;
  }
}

TEST(PlateBending, GradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    Element e = random_element(rng, trial % 4 == 3);
    const PlateBendingTerms t = plate_bending_terms(e.x, e.has_wing, e.rest_theta, e.Q, HessianKind::kExact);
    const double h = 1e-6;
    Vec18 fd_grad;
    Mat18 fd_hess;
    for (int k = 0; k < 18; ++k) {
      Element p = e, m = e;
      p.x[k / 3][k % 3] += h;
      m.x[k / 3][k % 3] -= h;
      fd_grad[k] = (energy(p) - energy(m)) / (2 * h);
      const Vec18 gp = plate_bending_terms(p.x, p.has_wing, p.rest_theta, p.Q, HessianKind::kNone).gradient;
      const Vec18 gm = plate_bending_terms(m.x, m.has_wing, m.rest_theta, m.Q, HessianKind::kNone).gradient;
      fd_hess.col(k) = (gp - gm) / (2 * h);
    }
    EXPECT_LT((fd_grad - t.gradient).norm(), 1e-6 * t.gradient.norm() + 1e-10) << "trial " << trial;
    EXPECT_LT((fd_hess - t.hessian).norm(), 1e-6 * t.hessian.norm() + 1e-9) << "trial " << trial;
  }
}

TEST(PlateBending, SolverHessianIsPositiveSemiDefinite) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    Element e = random_element(rng, trial % 3 == 0);
    const Mat18 H = plate_bending_terms(e.x, e.has_wing, e.rest_theta, e.Q, HessianKind::kProjected).hessian;
    EXPECT_LT((H - H.transpose()).norm(), 1e-12 * H.norm());
    const double min_eig = Eigen::SelfAdjointEigenSolver<Mat18>(H).eigenvalues().minCoeff();
    EXPECT_GE(min_eig, -1e-10 * H.norm()) << "trial " << trial;
  }
}

TEST(PlateBending, RigidMotionLeavesEnergyAndForcesInvariant) {
  std::mt19937 rng(3);
  Element e = random_element(rng, false);
  const PlateBendingTerms before = plate_bending_terms(e.x, e.has_wing, e.rest_theta, e.Q, HessianKind::kNone);
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 t(0.3, -2, 5);
  Element moved = e;
  for (auto& p : moved.x) p = R * p + t;
  const PlateBendingTerms after =
      plate_bending_terms(moved.x, moved.has_wing, moved.rest_theta, moved.Q, HessianKind::kNone);
  EXPECT_NEAR(after.energy, before.energy, 1e-12 * before.energy);
  for (int i = 0; i < 6; ++i)
    EXPECT_LT((after.gradient.segment<3>(3 * i) - R * before.gradient.segment<3>(3 * i)).norm(),
              1e-9 * before.gradient.norm());
  // Translation invariance: the forces sum to zero.
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < 6; ++i) sum += before.gradient.segment<3>(3 * i);
  EXPECT_LT(sum.norm(), 1e-10 * before.gradient.norm());
}

TEST(PlateBending, FlatRestStateHasNoEnergy) {
  Mesh m = testing::make_grid(4, 4, 1, 1);
  Material mat;
  mat.thickness = 1e-3;
  mat.youngs_modulus = 1e9;
  mat.poisson_ratio = 0.3;
  mat.density = 1000;
  std::vector<Material> mats{mat};
  for (Face& f : m.faces) f.thickness = 1e-3;
  ElementCache c;
  build_element_cache(m, mats, c);
  EXPECT_EQ(internal_energy(m, c), 0.0);
  EXPECT_EQ(internal_forces(m, c).norm(), 0.0);
}

// Bending a patch onto a cylinder of radius R: the total bending energy approaches the continuum plate energy
// (kb/2) Area / R^2 for every mesh family and bending direction (the shortfall is the boundary layer, O(h)).
TEST(PlateBending, CylinderEnergyConvergesToContinuumForAllMeshesAndDirections) {
  const double R = 1.0, kb = 1.0;
  for (int family = 0; family < 3; ++family) {
    for (int dir = 0; dir < 4; ++dir) {
      double previous_error = 1;
      for (double edge : {0.02, 0.01}) {
        Mesh m = family == 0   ? testing::make_equilateral_strip(0.2, 0.2, edge, true)
                 : family == 1 ? testing::make_equilateral_strip(0.2, 0.2, edge, false)
                               : testing::make_grid(static_cast<int>(0.2 / edge), static_cast<int>(0.2 / edge),
                                                    0.2, 0.2, testing::Diagonal::kForward);
        const double angle = dir * M_PI / 8;
        const Vec3 d(std::cos(angle), std::sin(angle), 0), p(-std::sin(angle), std::cos(angle), 0);
        double area = 0, energy_sum = 0;
        for (size_t f = 0; f < m.faces.size(); ++f) area += m.faces[f].rest_area;
        for (Node& n : m.nodes) {
          const double s = n.x.dot(d), q = n.x.dot(p);
          n.x = R * std::sin(s / R) * d + q * p + Vec3(0, 0, R * (1 - std::cos(s / R)));
        }
        Material mat;
        mat.youngs_modulus = 12;  // kb = E h^3 / 12 = 1 with h = 1, nu = 0
        mat.thickness = 1;
        std::vector<Material> mats{mat};
        for (Face& f : m.faces) f.thickness = 1;
        ElementCache c;
        build_element_cache(m, mats, c);
        for (const auto& b : c.bending) {
          std::array<Vec3, 6> x;
          for (int i = 0; i < 6; ++i) x[i] = m.nodes[b.nodes[i]].x;
          energy_sum += plate_bending_terms(x, b.has_wing, b.rest_theta, b.Q, HessianKind::kNone).energy;
        }
        const double error = std::abs(energy_sum / (0.5 * kb * area / (R * R)) - 1);
        EXPECT_LT(error, edge > 0.015 ? 0.12 : 0.06) << "family " << family << " direction " << dir << " edge " << edge;
        EXPECT_LT(error, previous_error + 1e-3) << "does not converge: family " << family << " dir " << dir;
        previous_error = error;
      }
    }
  }
}

}  // namespace
}  // namespace arcsim
