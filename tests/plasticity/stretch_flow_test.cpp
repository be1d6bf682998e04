// The stretching flow rule (paper Eq. 9 with thinning) on a single face against hand-computed values.
#include <gtest/gtest.h>

#include <cmath>

#include "physics/membrane.hpp"
#include "plasticity/plastic_tensors.hpp"
#include "plasticity/stretch_flow.hpp"

namespace arcsim {
namespace {

constexpr double kThickness = 1e-3;  // m
constexpr double kEdge = 0.01;       // m

// Aluminium-like, Poisson ratio 0 so that a stretch along x with fixed width is uniaxial stress.
Material metal() {
  Material m;
  m.thickness = kThickness;
  m.density = 2700;
  m.youngs_modulus = 70e9;
  m.poisson_ratio = 0;
  m.yield_stress = 200e6;
  m.flow_rate = 5e-6;
  return m;
}

// One right triangle in the xy plane; its material frame is (x, y).
Mesh one_face() {
  const std::vector<Vec3> u{{0, 0, 0}, {kEdge, 0, 0}, {0, kEdge, 0}};
  Mesh mesh = Mesh::from_triangles(u, u, {0, 1, 2}, {{0, 1, 2}});
  mesh.faces[0].thickness = kThickness;
  return mesh;
}

// World positions = A * rest positions (a homogeneous deformation with 2D gradient A).
void deform(Mesh& mesh, const Mat2& A) {
  for (Node& n : mesh.nodes) {
    const Vec2 p = A * n.x0.head<2>();
    n.x = Vec3(p.x(), p.y(), 0);
  }
}

Mesh stretched_face(double stretch) {
  Mesh mesh = one_face();
  for (Node& n : mesh.nodes) n.x0 = n.x;
  deform(mesh, Vec2(stretch, 1).asDiagonal());
  return mesh;
}

TEST(StretchFlow, VonMisesOfUniaxialAndEquibiaxialStress) {
  EXPECT_NEAR(von_mises_plane_stress(Vec2(3e8, 0).asDiagonal()), 3e8, 1e-3);
  EXPECT_NEAR(von_mises_plane_stress(Vec2(2e8, 2e8).asDiagonal()), 2e8, 1e-3);  // plane stress: same as uniaxial
  Mat2 shear;
  shear << 0, 1e8, 1e8, 0;
  EXPECT_NEAR(von_mises_plane_stress(shear), std::sqrt(3.0) * 1e8, 1e-3);  // pure shear tau: sqrt(3) tau
}

TEST(StretchFlow, UniaxialStretchPastYieldGivesPredictedPlasticStrainAndThinning) {
  const double s = 1.01, dt = 1e-4;
  Mesh mesh = stretched_face(s);
  const Material m = metal();
  const StretchFlowResult r = apply_stretch_flow(mesh, 0, m, dt);
  // Hand computation: G11 = (s^2 - 1)/2, sigma = E G11 (nu = 0, uniaxial), gamma = dt mu (sigma - sigma_0).
  const double sigma = m.youngs_modulus * (s * s - 1) / 2;
  const double gamma = dt * m.flow_rate * (sigma - m.yield_stress);
  ASSERT_GT(gamma, 0.1);
  ASSERT_LT(gamma, 1.0);
  EXPECT_NEAR(r.von_mises, sigma, 1e-6 * sigma);
  EXPECT_NEAR(r.gamma, gamma, 1e-9);
  ASSERT_TRUE(r.changed);
  // Sigma = diag(s, 1), J = s: Fp = diag((s^(2/3))^-gamma, (s^(-1/3))^-gamma), h = h0 s^(-gamma/3).
  const Mat2 Fp = face_plastic_stretch_2d(mesh.faces[0]);
  EXPECT_NEAR(Fp(0, 0), std::pow(s, -2 * gamma / 3), 1e-12);
  EXPECT_NEAR(Fp(1, 1), std::pow(s, gamma / 3), 1e-12);
  EXPECT_NEAR(Fp(0, 1), 0, 1e-12);
  EXPECT_NEAR(Fp(1, 0), 0, 1e-12);
  EXPECT_NEAR(mesh.faces[0].thickness, kThickness * std::pow(s, -gamma / 3), 1e-15);
  // Out of plane Fp stays the identity.
  EXPECT_NEAR((mesh.faces[0].Fp * Vec3::UnitZ() - Vec3::UnitZ()).norm(), 0, 1e-15);
  // The update released membrane energy, and the work reported is that energy.
  const Mat2 Dm_inv = mesh.faces[0].Dm_inv;
  const auto energy = [&](const Mat2& Fp2, double h) {
    const Vec3& x0 = mesh.nodes[0].x;
    return membrane_energy(x0, mesh.nodes[1].x, mesh.nodes[2].x, Dm_inv * Fp2, mesh.faces[0].rest_area,
                           m.membrane_stiffness(h));
  };
  const double released = energy(Mat2::Identity(), kThickness) - energy(Fp, kThickness);
  EXPECT_GT(released, 0);
  EXPECT_NEAR(r.work, released, 1e-9 * released);
}

TEST(StretchFlow, FullFlowLeavesOnlyTheIsotropicElasticStretchAndUnloadsToThePlasticShape) {
  const double s = 1.02;
  Mesh mesh = stretched_face(s);
  const Material m = metal();
  const StretchFlowResult r = apply_stretch_flow(mesh, 0, m, 1.0);  // large step: gamma clamps to 1
  EXPECT_EQ(r.gamma, 1.0);
  // Permanent (plastic) stretch P = Fp^-1 = diag(s^(2/3), s^(-1/3)): length along x grows by s^(2/3) - 1.
  const Mat2 P = face_plastic_stretch_2d(mesh.faces[0]).inverse();
  EXPECT_NEAR(P(0, 0) - 1, std::pow(s, 2.0 / 3) - 1, 1e-12);
  EXPECT_NEAR(P(1, 1), std::pow(s, -1.0 / 3), 1e-12);
  // The elastic part left is the isotropic stretch s^(1/3).
  const Mat32 F_el = membrane_deformation_gradient(mesh.nodes[0].x, mesh.nodes[1].x, mesh.nodes[2].x,
                                                   mesh.faces[0].Dm_inv * face_plastic_stretch_2d(mesh.faces[0]));
  EXPECT_NEAR(F_el(0, 0), std::cbrt(s), 1e-12);
  EXPECT_NEAR(F_el(1, 1), std::cbrt(s), 1e-12);
  // Unloaded, the face rests (zero membrane energy) in the plastic shape x = P u.
  deform(mesh, P);
  const Face& f = mesh.faces[0];
  EXPECT_LT(membrane_energy(mesh.nodes[0].x, mesh.nodes[1].x, mesh.nodes[2].x, f.Dm_inv * face_plastic_stretch_2d(f),
                            f.rest_area, m.membrane_stiffness(f.thickness)),
            1e-20);
}

TEST(StretchFlow, ElasticBelowYieldChangesNothing) {
  // sigma = E (s^2 - 1)/2 = 70e9 * 0.0025 = 175 MPa < 200 MPa.
  Mesh mesh = stretched_face(std::sqrt(1.005));
  const Face before = mesh.faces[0];
  const StretchFlowResult r = apply_stretch_flow(mesh, 0, metal(), 1.0);
  EXPECT_FALSE(r.changed);
  EXPECT_EQ(r.gamma, 0);
  EXPECT_EQ(r.work, 0);
  EXPECT_TRUE(mesh.faces[0].Fp == before.Fp);
  EXPECT_EQ(mesh.faces[0].thickness, before.thickness);
}

TEST(StretchFlow, NoFlowWithoutFlowRateOrYieldStress) {
  Material m = metal();
  m.flow_rate = 0;
  Mesh mesh = stretched_face(1.05);
  EXPECT_FALSE(apply_stretch_flow(mesh, 0, m, 1.0).changed);
  m = metal();
  m.yield_stress = kInfinity;
  EXPECT_FALSE(apply_stretch_flow(mesh, 0, m, 1.0).changed);
  EXPECT_TRUE(mesh.faces[0].Fp.isIdentity(0));
}

// Volume: with P = Fp^-1 (2x2 in-plane plastic stretch), det(P) * h / h0 = 1 through many general
// deformations (shear, rotation, compression), also when plastic_limit clamps the stretch.
void check_volume_conserved(double plastic_limit) {
  Mesh mesh = one_face();
  for (Node& n : mesh.nodes) n.x0 = n.x;
  Material m = metal();
  m.plastic_limit = plastic_limit;
  int changed = 0;
  for (int k = 0; k < 60; ++k) {
    const double a = 0.3 * k;
    Mat2 R;
    R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    Mat2 A;
    A << 1.0 + 0.03 * std::sin(0.7 * k), 0.02 * std::cos(1.3 * k), -0.01 * std::sin(0.4 * k),
        1.0 - 0.025 * std::cos(0.9 * k);
    deform(mesh, R * A * face_plastic_stretch_2d(mesh.faces[0]).inverse());  // strain about the plastic shape
    changed += apply_stretch_flow(mesh, 0, m, 2e-4).changed ? 1 : 0;
    const Mat2 P = face_plastic_stretch_2d(mesh.faces[0]).inverse();
    ASSERT_NEAR(P.determinant() * mesh.faces[0].thickness / kThickness, 1.0, 1e-9) << "step " << k;
    if (std::isfinite(plastic_limit)) {
      const Vec2 sv = Eigen::JacobiSVD<Mat2>(P).singularValues();
      ASSERT_LE(sv.maxCoeff(), plastic_limit * (1 + 1e-12));
      ASSERT_GE(sv.minCoeff(), 1 / plastic_limit * (1 - 1e-12));
    }
  }
  EXPECT_GT(changed, 30);
  EXPECT_GT((face_plastic_stretch_2d(mesh.faces[0]) - Mat2::Identity()).norm(), 1e-3);
}

TEST(StretchFlow, VolumeConservedOverManySteps) { check_volume_conserved(kInfinity); }
TEST(StretchFlow, VolumeConservedWhenPlasticLimitClamps) { check_volume_conserved(1.01); }

}  // namespace
}  // namespace arcsim
