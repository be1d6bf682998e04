// The separation strength of a node (paper Eq. 5-7) on fans built by hand and from grids.
//
// Geometric factor. For a uniform uniaxial stress sigma n n^T the traction across a sector's unit arc is
// q_k = sigma n (n . a_k), a_k = integral of the outward normal m(phi) over the sector's arc. Eq. 7 then gives
// s = sigma min(n . a_1, -n . a_2) when the sectors pull apart. With n the split's normal:
//   - interior node (flat: total angle 2 pi), the half discs on either side of the line: a_1 = 2 n = -a_2, so
//     s = 2 sigma, c = 2; a plane turned by delta from the ideal one gives s = 2 sigma cos(delta);
//   - straight border, ray at angle phi from the border, load along the border (n = e_x at phi = 90 deg):
//     a_1 = (sin phi, 1 - cos phi), a_2 = (-sin phi, 1 + cos phi), so s = sigma sin phi, the largest
//     at the perpendicular cut: s = sigma, and c = 1 (the factor of the ray's own normal is 1 - |cos phi|);
//   - crack tip (a wedge of 2 pi, lips behind the node), ray at angle psi from straight ahead, mode I load
//     across the crack: a_1 = -a_2 = (sin psi, -1 - cos psi) (lips along -x), s = sigma (1 + cos psi), the
//     largest straight ahead: s = 2 sigma, c = 2.
// The node's factor c is the largest over its candidate planes (2, 1 and 2 above), and the reported strength
// s / c equals sigma for these loads, on any partition of the fan into faces.
//
// Sampling resolution: interior planes are sampled every 360/200 = 1.8 deg (a plane and its turn by 180 deg are
// the same), so the best sampled plane is within 0.9 deg of the ideal one; rays at a border node are sampled
// every (total angle)/200: 0.9 deg on a straight border (within 0.45 deg), 1.8 deg at a crack tip (0.9 deg).
#include "fracture/separation_strength.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <random>

#include "mesh/edits.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kThickness = 1e-3;      // m
constexpr double kToughness = 1e6;       // Pa: area toughness 1000 N/m
constexpr double kSigma = 1500;          // N/m
constexpr double kDegree = kPi / 180;

std::vector<Material> materials(double toughness = kToughness) {
  Material m;
  m.thickness = kThickness;
  m.density = 1000;
  m.youngs_modulus = 1e9;
  m.toughness = toughness;
  return {m};
}

// A fan around node 0 at the origin: ring points CCW, faces (0, ring i, ring i+1), closed or open. Ring points
// of an open fan may coincide (a slit's two lips). Flat in z = 0, rest = world.
Mesh fan_mesh(const std::vector<Vec2>& ring, bool closed) {
  std::vector<Vec3> x{Vec3::Zero()};
  for (const Vec2& p : ring) x.emplace_back(p.x(), p.y(), 0);
  std::vector<int> vert_node(x.size());
  for (size_t i = 0; i < x.size(); ++i) vert_node[i] = static_cast<int>(i);
  std::vector<std::array<int, 3>> tris;
  const int n = static_cast<int>(ring.size());
  for (int i = 1; i < n; ++i) tris.push_back({0, i, i + 1});
  if (closed) tris.push_back({0, n, 1});
  Mesh mesh = Mesh::from_triangles(x, x, vert_node, tris);
  for (Face& f : mesh.faces) f.thickness = kThickness;
  return mesh;
}

Vec2 polar(double r, double angle) { return Vec2(r * std::cos(angle), r * std::sin(angle)); }

// The same planar stress (N/m, in the xy plane) on every face, expressed in each face's frame.
std::vector<FaceFractureStress> uniform_stress(const Mesh& mesh, const Mat2& sigma_xy) {
  Mat3 S = Mat3::Zero();
  S.topLeftCorner<2, 2>() = sigma_xy;
  std::vector<FaceFractureStress> out(mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Mat32& R = mesh.faces[f].rest_frame;
    out[f].sigma = R.transpose() * S * R;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(out[f].sigma));
    out[f].lambda_max = std::max(eig.eigenvalues().maxCoeff(), 0.0);
  }
  return out;
}

Mat2 uniaxial(double sigma, const Vec2& n) { return sigma * n * n.transpose(); }

// Whether the ray leaves the node into its face, between (or on) the face's two edges at the node.
bool ray_in_face(const Mesh& mesh, int node, const CutRay& ray) {
  if (ray.face == kNone) return false;
  const int corner = mesh.corner_of_node(ray.face, node);
  if (corner == kNone) return false;
  const Face& face = mesh.faces[ray.face];
  const Vec3 u = mesh.verts[face.v[corner]].u;
  const Vec3 out = mesh.verts[face.v[(corner + 1) % 3]].u - u;
  const Vec3 in = mesh.verts[face.v[(corner + 2) % 3]].u - u;
  const Vec3& n = face.rest_normal;
  const double tol = 1e-12;
  return out.cross(ray.direction).dot(n) >= -tol && ray.direction.cross(in).dot(n) >= -tol &&
         std::abs(ray.direction.dot(n)) < 1e-12 && std::abs(ray.direction.norm() - 1) < 1e-12;
}

class Fans {
 public:
  explicit Fans(unsigned seed) : gen_(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(gen_); }
  std::vector<Vec2> regular(int n) {
    std::vector<Vec2> ring;
    for (int k = 0; k < n; ++k) ring.push_back(polar(1, 2 * kPi * k / n));
    return ring;
  }
  // Angles jittered by up to 20% of the regular spacing, radii in [0.3, 1.7].
  std::vector<Vec2> irregular(int n) {
    std::vector<Vec2> ring;
    const double spacing = 2 * kPi / n, offset = uniform(0, 2 * kPi);
    for (int k = 0; k < n; ++k) ring.push_back(polar(uniform(0.3, 1.7), offset + spacing * (k + uniform(-0.2, 0.2))));
    return ring;
  }
  // A regular ring squashed 20:1 and turned: long thin triangles with sharp and flat corners at the node.
  std::vector<Vec2> anisotropic(int n) {
    const double turn = uniform(0, kPi);
    const Eigen::Rotation2Dd R(turn);
    std::vector<Vec2> ring;
    for (const Vec2& p : regular(n)) ring.push_back(R * Vec2(p.x(), 0.05 * p.y()));
    return ring;
  }

 private:
  std::mt19937 gen_;
};

void expect_interior_uniaxial(const Mesh& mesh, const Vec2& n) {
  const NodeSeparation s = node_separation(mesh, materials(), 0, uniform_stress(mesh, uniaxial(kSigma, n)));
  EXPECT_FALSE(s.on_boundary);
  EXPECT_NEAR(s.strength, kSigma, 0.01 * kSigma);
  EXPECT_GE(s.strength, kSigma * std::cos(0.9 * kDegree) * (1 - 1e-12));
  EXPECT_NEAR(s.factor, 2, 1e-9);
  EXPECT_NEAR(s.raw, s.strength * s.factor, 1e-9 * kSigma);
  EXPECT_NEAR(s.toughness, kToughness * kThickness, 1e-9);
  ASSERT_EQ(s.rays.size(), 2u);
  const Vec3 load(n.x(), n.y(), 0);
  for (const CutRay& ray : s.rays) {
    EXPECT_TRUE(ray_in_face(mesh, 0, ray));
    EXPECT_LE(std::abs(ray.direction.dot(load)), std::sin(0.9 * kDegree) + 1e-9);
  }
  EXPECT_NEAR(s.rays[0].direction.dot(s.rays[1].direction), -1, 1e-9);
}

TEST(SeparationStrength, UniaxialStressAtInteriorNodesOfAnyFan) {
  Fans fans(7);
  for (int n = 3; n <= 12; ++n) {
    for (int trial = 0; trial < 3; ++trial) {
      const double angle = fans.uniform(0, kPi);
      const Vec2 load(std::cos(angle), std::sin(angle));
      SCOPED_TRACE("faces " + std::to_string(n) + " trial " + std::to_string(trial));
      {
        SCOPED_TRACE("regular");
        expect_interior_uniaxial(fan_mesh(fans.regular(n), true), load);
      }
      {
        SCOPED_TRACE("irregular");
        expect_interior_uniaxial(fan_mesh(fans.irregular(n), true), load);
      }
      {
        SCOPED_TRACE("anisotropic");
        expect_interior_uniaxial(fan_mesh(fans.anisotropic(n), true), load);
      }
    }
  }
}

// breaking_only (fracture's candidate scan), at interior nodes under uniaxial stress: a breaking node gets the
// full result bit for bit; a stressed node that does not break (past the cheap skip's half toughness, below its
// toughness) is skipped without refining its factor: strength 0 and no rays, where the full evaluation reports
// its strength.
TEST(SeparationStrength, BreakingOnlySkipsNodesThatDoNotBreak) {
  Fans fans(13);
  SeparationOptions only_breaking;
  only_breaking.breaking_only = true;
  for (int n = 3; n <= 9; ++n) {
    const Mesh mesh = fan_mesh(fans.irregular(n), true);
    const double angle = fans.uniform(0, kPi);
    const std::vector<FaceFractureStress> stress =
        uniform_stress(mesh, uniaxial(kSigma, Vec2(std::cos(angle), std::sin(angle))));
    SCOPED_TRACE("faces " + std::to_string(n));
    // Toughness 1000 N/m: breaks (strength ~1500 N/m).
    const NodeSeparation full = node_separation(mesh, materials(), 0, stress);
    const NodeSeparation fast = node_separation(mesh, materials(), 0, stress, only_breaking);
    ASSERT_TRUE(full.breaks());
    EXPECT_TRUE(fast.breaks());
    EXPECT_EQ(fast.strength, full.strength);
    EXPECT_EQ(fast.raw, full.raw);
    EXPECT_EQ(fast.factor, full.factor);
    EXPECT_EQ(fast.toughness, full.toughness);
    ASSERT_EQ(fast.rays.size(), full.rays.size());
    for (size_t k = 0; k < full.rays.size(); ++k) {
      EXPECT_EQ(fast.rays[k].face, full.rays[k].face);
      EXPECT_EQ(fast.rays[k].direction, full.rays[k].direction);
    }
    // Toughness 2000 N/m: stressed past half of it (not skipped cheaply), does not break.
    const NodeSeparation full_tough = node_separation(mesh, materials(2 * kToughness), 0, stress);
    const NodeSeparation fast_tough = node_separation(mesh, materials(2 * kToughness), 0, stress, only_breaking);
    EXPECT_FALSE(full_tough.breaks());
    EXPECT_GT(full_tough.strength, 0);
    EXPECT_FALSE(fast_tough.breaks());
    EXPECT_EQ(fast_tough.strength, 0);
    EXPECT_TRUE(fast_tough.rays.empty());
  }
}

TEST(SeparationStrength, StretchedGridEndToEnd) {
  Mesh mesh = testing::make_grid(6, 6, 0.6, 0.6, testing::Diagonal::kAlternating);
  for (Face& f : mesh.faces) f.thickness = kThickness;
  for (Node& node : mesh.nodes) node.x.y() *= 1.003;
  const std::vector<Material> m = materials();
  const auto stress = fracture_stresses(mesh, m);
  const double expected = 1e9 * kThickness * 0.5 * (1.003 * 1.003 - 1);  // k_s G22, nu = 0
  const int centre = 3 * 7 + 3;
  const NodeSeparation s = node_separation(mesh, m, centre, stress);
  EXPECT_NEAR(s.strength, expected, 1e-3 * expected);
  ASSERT_EQ(s.rays.size(), 2u);
  EXPECT_LE(std::abs(s.rays[0].direction.y()), std::sin(0.9 * kDegree) + 1e-9);
  // Pure compression: nothing to separate.
  for (Node& node : mesh.nodes) node.x = Vec3(0.99 * node.x.x(), 0.995 * node.x.y(), 0);
  const NodeSeparation c = node_separation(mesh, m, centre, fracture_stresses(mesh, m));
  EXPECT_EQ(c.strength, 0);
  EXPECT_TRUE(c.rays.empty());
  EXPECT_FALSE(c.breaks());
}

TEST(SeparationStrength, PureCompressionDoesNotBreak) {
  Fans fans(3);
  for (int n : {3, 6, 11}) {
    Mesh mesh = fan_mesh(fans.irregular(n), true);
    for (Node& node : mesh.nodes) node.x *= 0.98;
    const std::vector<Material> m = materials();
    const NodeSeparation s = node_separation(mesh, m, 0, fracture_stresses(mesh, m));
    EXPECT_EQ(s.strength, 0);
    EXPECT_EQ(s.raw, 0);
  }
}

// A straight border, through the node, at a random angle; the load runs along it.
TEST(SeparationStrength, StraightBorderLoadedAlongItGetsThePerpendicularCut) {
  Fans fans(11);
  for (int n = 3; n <= 12; ++n) {
    const double turn = fans.uniform(0, 2 * kPi);
    std::vector<Vec2> ring{polar(fans.uniform(0.5, 1.5), turn)};
    for (int k = 1; k < n; ++k)
      ring.push_back(polar(fans.uniform(0.3, 1.7), turn + kPi * (k + fans.uniform(-0.2, 0.2)) / n));
    ring.push_back(polar(fans.uniform(0.5, 1.5), turn + kPi));
    const Mesh mesh = fan_mesh(ring, false);
    const Vec2 along(std::cos(turn), std::sin(turn));
    const NodeSeparation s = node_separation(mesh, materials(), 0, uniform_stress(mesh, uniaxial(kSigma, along)));
    SCOPED_TRACE("faces " + std::to_string(n));
    EXPECT_TRUE(s.on_boundary);
    EXPECT_NEAR(s.strength, kSigma, 0.01 * kSigma);
    EXPECT_LE(s.strength, kSigma * (1 + 1e-9));
    EXPECT_NEAR(s.factor, 1, 1e-6);
    ASSERT_EQ(s.rays.size(), 1u);
    EXPECT_TRUE(ray_in_face(mesh, 0, s.rays[0]));
    const Vec3 inward(-along.y(), along.x(), 0);
    EXPECT_GE(s.rays[0].direction.dot(inward), std::cos(0.45 * kDegree) - 1e-9);
  }
}

// A crack tip: the node at the end of a slit, lips behind it along `back`; the fan wraps all around (2 pi).
Mesh crack_tip(Fans& fans, int n, double turn) {
  std::vector<Vec2> ring{polar(1, turn + kPi)};
  for (int k = 1; k < n; ++k)
    ring.push_back(polar(fans.uniform(0.4, 1.6), turn + kPi + 2 * kPi * (k + fans.uniform(-0.2, 0.2)) / n));
  ring.push_back(polar(1, turn + kPi));  // the other lip: same place, another node
  return fan_mesh(ring, false);
}

TEST(SeparationStrength, CrackTipUnderModeOneCutsStraightAhead) {
  Fans fans(5);
  for (int n = 4; n <= 12; ++n) {
    const double turn = fans.uniform(0, 2 * kPi);
    const Mesh mesh = crack_tip(fans, n, turn);
    const Vec2 ahead(std::cos(turn), std::sin(turn)), across(-ahead.y(), ahead.x());
    const NodeSeparation s = node_separation(mesh, materials(), 0, uniform_stress(mesh, uniaxial(kSigma, across)));
    SCOPED_TRACE("faces " + std::to_string(n));
    EXPECT_TRUE(s.on_boundary);
    EXPECT_NEAR(s.factor, 2, 1e-6);
    EXPECT_NEAR(s.strength, kSigma, 0.01 * kSigma);
    ASSERT_EQ(s.rays.size(), 1u);
    EXPECT_TRUE(ray_in_face(mesh, 0, s.rays[0]));
    EXPECT_GE(s.rays[0].direction.dot(Vec3(ahead.x(), ahead.y(), 0)), std::cos(0.9 * kDegree) - 1e-9);
  }
}

// A slit cut into a grid from its left border along the middle row, node by node, as the crack opening does.
// Returns the tip node (on the border, with a 2 pi wedge).
int cut_slit(Mesh& mesh, int nx, int row, int length) {
  auto node = [&](int i) { return row * (nx + 1) + i; };
  for (int i = 0; i < length; ++i) {
    const int edge = mesh.find_edge(node(i), node(i + 1));
    const EditResult r = split_node(mesh, node(i), {edge});
    if (!r.ok) ADD_FAILURE() << "split_node refused at " << i;
  }
  return node(length);
}

TEST(SeparationStrength, SlitInAGridGrowsStraightAheadUnderModeOne) {
  for (auto diagonal : {testing::Diagonal::kForward, testing::Diagonal::kAlternating}) {
    Mesh mesh = testing::make_grid(8, 8, 0.8, 0.8, diagonal);
    for (Face& f : mesh.faces) f.thickness = kThickness;
    const int tip = cut_slit(mesh, 8, 4, 4);
    ASSERT_TRUE(mesh.is_boundary_node(tip));
    const NodeSeparation s = node_separation(mesh, materials(), tip, uniform_stress(mesh, uniaxial(kSigma, Vec2(0, 1))));
    EXPECT_TRUE(s.on_boundary);
    EXPECT_NEAR(s.factor, 2, 1e-6);
    EXPECT_NEAR(s.strength, kSigma, 0.01 * kSigma);
    ASSERT_EQ(s.rays.size(), 1u);
    EXPECT_TRUE(ray_in_face(mesh, tip, s.rays[0]));
    EXPECT_GE(s.rays[0].direction.x(), std::cos(0.9 * kDegree) - 1e-9);
    // A node on the slit's lip, loaded the same way, is pulled off the border, not along it: no break.
    const int lip = 4 * 9 + 2;
    EXPECT_LT(node_separation(mesh, materials(), lip, uniform_stress(mesh, uniaxial(kSigma, Vec2(0, 1)))).strength,
              1e-9 * kSigma);
  }
}

// Loaded along the crack, the tip is not opened (the lips are free): a weaker, different answer.
TEST(SeparationStrength, CrackTipLoadedAlongTheCrackIsWeaker) {
  Fans fans(9);
  const Mesh mesh = crack_tip(fans, 8, 0.3);
  const Vec2 ahead(std::cos(0.3), std::sin(0.3));
  const NodeSeparation s = node_separation(mesh, materials(), 0, uniform_stress(mesh, uniaxial(kSigma, ahead)));
  EXPECT_LT(s.strength, 0.9 * kSigma);
}

TEST(SeparationStrength, SkipsNodesFarBelowTheToughness) {
  const Mesh mesh = fan_mesh(Fans(1).regular(6), true);
  const double tau = kToughness * kThickness;
  const std::vector<Material> m = materials();
  const Vec2 x(1, 0);
  EXPECT_EQ(node_separation(mesh, m, 0, uniform_stress(mesh, uniaxial(0.49 * tau, x))).strength, 0);
  const NodeSeparation weak = node_separation(mesh, m, 0, uniform_stress(mesh, uniaxial(0.6 * tau, x)));
  EXPECT_NEAR(weak.strength, 0.6 * tau, 1e-3 * tau);
  EXPECT_FALSE(weak.breaks());
  EXPECT_NEAR(weak.ratio(), 0.6, 1e-3);
  const NodeSeparation strong = node_separation(mesh, m, 0, uniform_stress(mesh, uniaxial(1.1 * tau, x)));
  EXPECT_TRUE(strong.breaks());
}

TEST(SeparationStrength, ToughnessIsTheMeanOfTheCutFaces) {
  // Faces span 45..135, 135..225, 225..315, 315..45 deg: a load along x cuts faces 0 and 2 along +-y.
  std::vector<Vec2> ring;
  for (int k = 0; k < 4; ++k) ring.push_back(polar(1, kPi / 4 + k * kPi / 2));
  Mesh mesh = fan_mesh(ring, true);
  mesh.faces[0].thickness = 1e-3;
  mesh.faces[2].thickness = 3e-3;
  const NodeSeparation s = node_separation(mesh, materials(), 0, uniform_stress(mesh, uniaxial(kSigma, Vec2(1, 0))));
  ASSERT_EQ(s.rays.size(), 2u);
  EXPECT_NEAR(s.toughness, kToughness * 2e-3, 1e-9);
  EXPECT_TRUE((s.rays[0].face == 0 && s.rays[1].face == 2) || (s.rays[0].face == 2 && s.rays[1].face == 0));
}

TEST(SeparationStrength, UnbreakableFacesAreNotCut) {
  std::vector<Vec2> ring;
  for (int k = 0; k < 4; ++k) ring.push_back(polar(1, kPi / 4 + k * kPi / 2));
  Mesh mesh = fan_mesh(ring, true);
  std::vector<Material> m = materials();
  const auto stress = uniform_stress(mesh, uniaxial(kSigma, Vec2(1, 0)));
  m[0].toughness = 0;
  EXPECT_EQ(node_separation(mesh, m, 0, stress).strength, 0);
  m = materials();
  m.push_back(m[0]);
  m[1].toughness = 0;
  mesh.faces[0].material = 1;  // the best plane's face: the split must go elsewhere, through faces 1 and 3
  const NodeSeparation s = node_separation(mesh, m, 0, stress);
  ASSERT_EQ(s.rays.size(), 2u);
  for (const CutRay& ray : s.rays) {
    EXPECT_NE(ray.face, 0) << ray.direction.transpose();
    EXPECT_TRUE(ray_in_face(mesh, 0, ray));
    // Not through face 0's inside (45..135 deg): a ray along its edges is fine.
    EXPECT_FALSE(ray.direction.y() > std::sin(45 * kDegree) + 1e-9) << ray.direction.transpose();
  }
  EXPECT_LT(s.strength, kSigma * std::cos(44 * kDegree));
}

TEST(SeparationStrength, BadNodesGetZero) {
  const Mesh mesh = fan_mesh(Fans(1).regular(5), true);
  const auto stress = uniform_stress(mesh, uniaxial(kSigma, Vec2(0, 1)));
  EXPECT_EQ(node_separation(mesh, materials(), -1, stress).strength, 0);
  EXPECT_EQ(node_separation(mesh, materials(), 99, stress).strength, 0);
}

// Rough cost per node on a grid under tension (printed, not checked).
TEST(SeparationStrength, CostPerNode) {
  Mesh mesh = testing::make_grid(40, 40, 1.0, 1.0, testing::Diagonal::kAlternating);
  for (Face& f : mesh.faces) f.thickness = kThickness;
  for (Node& node : mesh.nodes) node.x.x() *= 1.01;
  const std::vector<Material> m = materials();
  const auto stress = fracture_stresses(mesh, m);
  const auto start = std::chrono::steady_clock::now();
  double sum = 0;
  for (size_t n = 0; n < mesh.nodes.size(); ++n) sum += node_separation(mesh, m, static_cast<int>(n), stress).strength;
  const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  std::cout << "node_separation: " << us / mesh.nodes.size() << " us per node\n";
  EXPECT_GT(sum, 0);
}

}  // namespace
}  // namespace arcsim
