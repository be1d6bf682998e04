// The bending flow rule (paper Eq. 10): hand-computed increments, and a strip bent past its yield curvature
// that keeps the excess curvature once released (static equilibrium with the real plate-bending physics).
#include <gtest/gtest.h>

#include <cmath>

#include "physics/cloth_physics.hpp"
#include "physics/statics.hpp"
#include "plasticity/bend_flow.hpp"
#include "plasticity/plastic_step.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

constexpr double kLength = 0.1, kWidth = 0.01, kThickness = 1e-3;  // m
constexpr double kYieldCurv = 5, kBentCurv = 20;                   // 1/m

Material strip_material(double yield_curv) {
  Material m;
  m.thickness = kThickness;
  m.density = 1000;
  m.youngs_modulus = 1e9;
  m.poisson_ratio = 0.3;
  m.yield_curv = yield_curv;
  // Stretching plasticity too (a polymer-like 20 MPa yield), which the small membrane strains of a bent strip
  // (~4e-4, i.e. 0.4 MPa) must not trigger.
  m.yield_stress = 20e6;
  m.flow_rate = 5e-5;
  return m;
}

TEST(BendFlow, IncrementOfEq10IsHandComputed) {
  Mat3 S = Mat3::Zero();
  S(0, 0) = 8;
  Mat3 expected = Mat3::Zero();
  expected(0, 0) = 3;  // (8 - 5) along the strain
  EXPECT_NEAR((bend_flow_increment(S, 5) - expected).norm(), 0, 1e-14);
  S << 3, 4, 0, 4, 0, 0, 0, 0, 0;  // |S| = sqrt(41)
  EXPECT_NEAR((bend_flow_increment(S, 5) - S / std::sqrt(41.0) * (std::sqrt(41.0) - 5)).norm(), 0, 1e-14);
  EXPECT_NEAR(bend_flow_increment(S, 5).norm(), std::sqrt(41.0) - 5, 1e-14);
  EXPECT_TRUE(bend_flow_increment(S, 7).isZero(0));  // below yield: nothing
}

// A strip along x (rest: flat, z = 0), nx cells by 2, bent onto a cylinder of curvature kappa about the y axis.
Mesh bent_strip(double kappa) {
  Mesh mesh = testing::make_grid(20, 2, kLength, kWidth, testing::Diagonal::kAlternating);
  for (Face& f : mesh.faces) f.thickness = kThickness;
  for (Node& n : mesh.nodes) {
    const double s = n.x.x();
    n.x0 = n.x;
    n.x = Vec3(std::sin(kappa * s) / kappa, n.x.y(), (1 - std::cos(kappa * s)) / kappa);
  }
  return mesh;
}

bool is_interior_face(const Mesh& mesh, int f) {
  for (int i = 0; i < 3; ++i) {
    const double x = mesh.verts[mesh.faces[f].v[i]].u.x();
    if (x < 1e-9 || x > kLength - 1e-9) return false;
  }
  return true;
}

// Curvature (1/m) of the circle through three points.
double circle_curvature(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double area2 = (b - a).cross(c - a).norm();
  return 2 * area2 / ((b - a).norm() * (c - b).norm() * (a - c).norm());
}

// Clamps the first two columns where they are, lets the rest of the strip relax without loads, returns the
// curvature of its centre line.
double released_curvature(Mesh mesh, const std::vector<Material>& materials) {
  update_node_masses(mesh, materials);
  ElementCache cache;
  build_element_cache(mesh, materials, cache);
  CholeskySolver solver;
  ExternalLoads loads;
  loads.pinned.assign(mesh.nodes.size(), 0);
  for (size_t i = 0; i < mesh.nodes.size(); ++i) loads.pinned[i] = mesh.nodes[i].x0.x() <= kLength / 20 + 1e-9;
  const StaticResult r = solve_static(mesh, cache, solver, loads);
  // Without loads the solver's tolerance (relative to the weight) is zero: check the force residual instead.
  EXPECT_LT(r.residual, 1e-8) << "N";
  // Centre row (j = 1) of the 21 x 3 grid: nodes 21 .. 41.
  return circle_curvature(mesh.nodes[21].x, mesh.nodes[31].x, mesh.nodes[41].x);
}

TEST(BendFlow, StripBentPastYieldKeepsTheExcessCurvature) {
  const std::vector<Material> materials{strip_material(kYieldCurv)};
  Mesh mesh = bent_strip(kBentCurv);
  // The sign of the strain says which way the strip bends (negative here: it curls towards +z).
  const double sign = face_elastic_bending_strain(mesh, 40)(0, 0) > 0 ? 1 : -1;
  const PlasticStepResult r = plastic_step(mesh, materials, 1e-3);
  EXPECT_GT(r.bent_faces, 0);
  EXPECT_EQ(r.stretched_faces, 0);
  EXPECT_GT(r.bend_work, 0);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!is_interior_face(mesh, static_cast<int>(f))) continue;
    const Face& face = mesh.faces[f];
    // Plastic curvature (kappa - kappa_0) about y, i.e. along x x^T.
    EXPECT_NEAR(sign * face.Sp(0, 0), kBentCurv - kYieldCurv, 0.03 * (kBentCurv - kYieldCurv)) << "face " << f;
    EXPECT_NEAR(face.Sp(1, 1), 0, 0.03 * kBentCurv) << "face " << f;
    // ARCSim's damage: |S_el| / kappa_0 - 1 = 3.
    EXPECT_NEAR(face.damage, kBentCurv / kYieldCurv - 1, 0.1) << "face " << f;
    // What is left elastic is at the yield curvature.
    EXPECT_NEAR(face_elastic_bending_strain(mesh, static_cast<int>(f)).norm(), kYieldCurv, 0.05 * kYieldCurv);
  }
  // Released: it springs back by kappa_0 and keeps kappa - kappa_0.
  EXPECT_NEAR(released_curvature(mesh, materials), kBentCurv - kYieldCurv, 0.03 * (kBentCurv - kYieldCurv));
  // A second plasticity pass at the same shape changes (almost) nothing more: the elastic part is at yield.
  Mesh again = mesh;
  const PlasticStepResult r2 = plastic_step(again, materials, 1e-3);
  EXPECT_LT(r2.bend_work, 0.01 * r.bend_work);
}

TEST(BendFlow, ElasticStripBelowYieldSpringsBackFlat) {
  // The same bend with kappa_0 above it: nothing changes and the released strip is straight.
  const std::vector<Material> materials{strip_material(2 * kBentCurv)};
  Mesh mesh = bent_strip(kBentCurv);
  const Mesh before = mesh;
  const PlasticStepResult r = plastic_step(mesh, materials, 1e-3);
  EXPECT_FALSE(r.changed());
  EXPECT_EQ(r.work(), 0);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    EXPECT_TRUE(mesh.faces[f].Sp.isZero(0));
    EXPECT_TRUE(mesh.faces[f].Fp.isIdentity(0));
    EXPECT_EQ(mesh.faces[f].thickness, kThickness);
    EXPECT_EQ(mesh.faces[f].damage, 0);
  }
  for (size_t e = 0; e < mesh.edges.size(); ++e) EXPECT_EQ(mesh.edges[e].rest_theta, before.edges[e].rest_theta);
  EXPECT_LT(released_curvature(mesh, materials), 0.01 * kBentCurv);
}

TEST(BendFlow, NonPlasticMaterialNextToAPlasticOneKeepsZeroTensors) {
  // Left half plastic, right half elastic (material 1 without yield); bending past yield everywhere.
  std::vector<Material> materials{strip_material(kYieldCurv), strip_material(kInfinity)};
  materials[1].yield_stress = kInfinity;
  Mesh mesh = bent_strip(kBentCurv);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Face& face = mesh.faces[f];
    const double cx = (mesh.verts[face.v[0]].u.x() + mesh.verts[face.v[1]].u.x() + mesh.verts[face.v[2]].u.x()) / 3;
    mesh.faces[f].material = cx > kLength / 2 ? 1 : 0;
  }
  const PlasticStepResult r = plastic_step(mesh, materials, 1e-3);
  EXPECT_GT(r.bent_faces, 0);
  for (const Face& face : mesh.faces) {
    if (face.material == 1) {
      EXPECT_TRUE(face.Sp.isZero(0));
      EXPECT_TRUE(face.Fp.isIdentity(0));
      EXPECT_EQ(face.damage, 0);
    } else if (is_interior_face(mesh, static_cast<int>(&face - mesh.faces.data()))) {
      EXPECT_GT(face.Sp.norm(), 1) << "face " << (&face - mesh.faces.data());
    }
  }
}

}  // namespace
}  // namespace arcsim
