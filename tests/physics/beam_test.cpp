// A clamped strip sagging under its own weight against Euler-Bernoulli beam theory: tip deflection
// delta = q L^4 / (8 E I), q = rho h w g (N/m), I = w h^3 / 12. With Poisson ratio 0 the plate and beam bending
// stiffnesses coincide. Deflection is kept ~3% of the length so geometric nonlinearity is negligible.
#include <gtest/gtest.h>

#include <cmath>

#include "physics/cloth_physics.hpp"
#include "physics/statics.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

constexpr double kLength = 0.2, kWidth = 0.02, kThickness = 2e-3, kDensity = 1000, kYoungs = 1e9, kGravity = 9.8;

Material beam_material() {
  Material m;
  m.thickness = kThickness;
  m.density = kDensity;
  m.youngs_modulus = kYoungs;
  m.poisson_ratio = 0;
  return m;
}

double analytic_tip_deflection() {
  const double q = kDensity * kThickness * kWidth * kGravity;
  const double I = kWidth * std::pow(kThickness, 3) / 12;
  return q * std::pow(kLength, 4) / (8 * kYoungs * I);
}

// Clamps every node at x <= 0, solves for static equilibrium, returns the mean tip deflection (m).
double simulated_tip_deflection(Mesh mesh) {
  std::vector<Material> materials{beam_material()};
  for (Face& f : mesh.faces) f.thickness = kThickness;
  update_node_masses(mesh, materials);
  ElementCache cache;
  build_element_cache(mesh, materials, cache);
  CholeskySolver solver;
  ExternalLoads loads;
  loads.gravity = Vec3(0, 0, -kGravity);
  loads.pinned.assign(mesh.nodes.size(), 0);
  for (size_t i = 0; i < mesh.nodes.size(); ++i) loads.pinned[i] = mesh.nodes[i].x.x() <= 1e-9;
  const StaticResult r = solve_static(mesh, cache, solver, loads);
  EXPECT_TRUE(r.converged) << "residual " << r.residual;
  double sum = 0;
  int count = 0;
  for (const Node& n : mesh.nodes) {
    if (n.x0.x() >= kLength - 1e-9) {  // x0 still holds the initial (flat) position
      sum += -n.x.z();
      ++count;
    }
  }
  EXPECT_GT(count, 0);
  return sum / count;
}

enum class MeshKind { kEquilateralAlong, kEquilateralAcross, kRightForward, kRightBackward };

struct BeamCase {
  const char* name;
  MeshKind kind;
  double edge;       // element size (m)
  double tolerance;  // relative
};

Mesh make_strip(MeshKind kind, double edge) {
  const double clamp = 2 * edge;  // two element rows of clamped material behind x = 0
  switch (kind) {
    case MeshKind::kEquilateralAlong:
      return testing::make_equilateral_strip(kLength + clamp, kWidth, edge, true, -clamp, 0.0);
    case MeshKind::kEquilateralAcross:
      return testing::make_equilateral_strip(kLength + clamp, kWidth, edge, false, -clamp, 0.0);
    case MeshKind::kRightForward:
    case MeshKind::kRightBackward:
      return testing::make_grid(static_cast<int>(std::lround((kLength + clamp) / edge)),
                                static_cast<int>(std::lround(kWidth / edge)), kLength + clamp, kWidth,
                                kind == MeshKind::kRightForward ? testing::Diagonal::kForward
                                                                : testing::Diagonal::kBackward,
                                -clamp, 0);
  }
  return {};
}

class ClampedStrip : public ::testing::TestWithParam<BeamCase> {};

TEST_P(ClampedStrip, TipDeflectionMatchesEulerBernoulli) {
  const BeamCase c = GetParam();
  const double expected = analytic_tip_deflection();
  const double got = simulated_tip_deflection(make_strip(c.kind, c.edge));
  RecordProperty("relative_error", std::to_string(got / expected - 1));
  EXPECT_NEAR(got / expected, 1.0, c.tolerance) << c.name << ": simulated " << got << " m, beam theory "
                                                 << expected << " m";
}

// Fine: 16-20 elements across the 2 cm strip, within 2%. Coarse: 8 elements across, within 5%. Both
// triangulation directions of each family.
INSTANTIATE_TEST_SUITE_P(
    Beam, ClampedStrip,
    ::testing::Values(BeamCase{"SlowFineEquilateralAlong", MeshKind::kEquilateralAlong, 0.001, 0.02},
                      BeamCase{"SlowFineEquilateralAcross", MeshKind::kEquilateralAcross, 0.001, 0.02},
                      BeamCase{"SlowFineRightForward", MeshKind::kRightForward, 0.00125, 0.02},
                      BeamCase{"SlowFineRightBackward", MeshKind::kRightBackward, 0.00125, 0.02},
                      BeamCase{"CoarseEquilateralAlong", MeshKind::kEquilateralAlong, 0.0025, 0.05},
                      BeamCase{"CoarseEquilateralAcross", MeshKind::kEquilateralAcross, 0.0025, 0.05},
                      BeamCase{"CoarseRightForward", MeshKind::kRightForward, 0.0025, 0.05},
                      BeamCase{"CoarseRightBackward", MeshKind::kRightBackward, 0.0025, 0.05}),
    [](const ::testing::TestParamInfo<BeamCase>& param) { return std::string(param.param.name); });

}  // namespace
}  // namespace arcsim
