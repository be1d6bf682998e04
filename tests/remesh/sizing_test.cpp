// Sizing metric terms against closed-form values on deformed flat sheets and cylinders.
#include <gtest/gtest.h>

#include <cmath>

#include "mesh/mesh_fixtures.hpp"
#include "remesh/metric.hpp"
#include "remesh/sizing.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using testing::make_grid;

SizingParams wide_params() {
  SizingParams p;
  p.remeshing.size_min = 1e-6;
  p.remeshing.size_max = 1e6;
  return p;
}

// A face well inside a grid (the grids here are at least 4 x 4).
int interior_face(const Mesh& m) {
  for (size_t f = 0; f < m.faces.size(); ++f) {
    bool interior = true;
    for (int i = 0; i < 3; ++i) interior = interior && !m.is_boundary_node(m.face_node(static_cast<int>(f), i));
    if (interior) return static_cast<int>(f);
  }
  return 0;
}

TEST(Sizing, CompressionOfAFlatSheet) {
  // World = rest squeezed by s along x: F^T F - I = diag(s^2 - 1, 0), so the term is diag((1 - s^2)/c^2, 0).
  Mesh m = make_grid(4, 4, 1.0, 1.0);
  const double s = 0.9, c = 0.05;
  for (Node& n : m.nodes) n.x.x() *= s;
  SizingParams p = wide_params();
  p.remeshing.refine_compression = c;
  for (size_t f = 0; f < m.faces.size(); ++f) {
    const Mat2 M = face_sizing_terms(m, static_cast<int>(f), p, {}).compression;
    EXPECT_NEAR(M(0, 0), (1 - s * s) / (c * c), 1e-9 * (1 - s * s) / (c * c));
    EXPECT_NEAR(M(1, 1), 0, 1e-6);
    EXPECT_NEAR(M(0, 1), 0, 1e-6);
  }
  // Stretching asks for nothing.
  for (Node& n : m.nodes) n.x.x() *= 1.2 / s;
  EXPECT_LT(face_sizing_terms(m, 0, p, {}).compression.norm(), 1e-9);
}

TEST(Sizing, CompressionIsReducedByCurvatureAcrossIt) {
  // Squeezed along x; rolling the sheet about x (curvature along y) stiffens it against buckling along x.
  Mesh flat = make_grid(8, 8, 0.1, 0.1);
  Mesh rolled = flat;
  const double s = 0.95, radius = 0.05;
  for (size_t n = 0; n < flat.nodes.size(); ++n) {
    const Vec3 u = flat.nodes[n].x;
    flat.nodes[n].x = Vec3(s * u.x(), u.y(), 0);
    rolled.nodes[n].x = Vec3(s * u.x(), radius * std::sin(u.y() / radius), radius * (1 - std::cos(u.y() / radius)));
  }
  SizingParams p = wide_params();
  p.remeshing.refine_compression = 0.01;
  const int f = interior_face(flat);
  const double plain = metric_eigenvalues(face_sizing_terms(flat, f, p, {}).compression)(1);
  const double ribbed = metric_eigenvalues(face_sizing_terms(rolled, f, p, {}).compression)(1);
  EXPECT_GT(plain, 0);
  EXPECT_LT(ribbed, 0.9 * plain);
  p.rib_stiffening = 0;  // no rib effect: the curvature does not matter
  EXPECT_NEAR(metric_eigenvalues(face_sizing_terms(rolled, f, p, {}).compression)(1), plain, 1e-6 * plain);
}

TEST(Sizing, CurvatureAcrossACompressionCanCancelIt) {
  // Squeezed by s along x, rolled about x with radius R: G^2 - 4 c^2 perp(S^T S) has the eigenvalue
  // (1 - s^2)^2 - 4 c^2 / R^2 along x. Gentle rolling (positive) reduces the term; tight rolling (negative) asks
  // for no refinement at all, since the signed root then outweighs -G.
  Mesh flat = make_grid(8, 8, 0.1, 0.1);
  const double s = 0.95, c = 0.01;
  SizingParams p = wide_params();
  p.remeshing.refine_compression = c;
  auto compression_along_x = [&](double radius) {
    Mesh m = flat;
    for (Node& n : m.nodes) {
      const Vec3 u = n.x;
      n.x = radius > 0 ? Vec3(s * u.x(), radius * std::sin(u.y() / radius), radius * (1 - std::cos(u.y() / radius)))
                       : Vec3(s * u.x(), u.y(), 0);
    }
    // The term along rest x (rolling also shortens the chords along y a little: a small term there).
    const int f = interior_face(m);
    const Vec2 x = m.faces[f].rest_frame.transpose() * Vec3(1, 0, 0);
    return x.dot(face_sizing_terms(m, f, p, {}).compression * x) / x.squaredNorm();
  };
  const double plain = compression_along_x(0);
  EXPECT_NEAR(plain, (1 - s * s) / (c * c), 1e-6 * plain);
  // Gentle: 4 c^2 / R^2 = 4e-4 with R = 1 against (1 - s^2)^2 = 9.5e-3: reduced a little, not cancelled.
  const double gentle = compression_along_x(1.0);
  EXPECT_LT(gentle, plain);
  EXPECT_GT(gentle, 0.9 * plain);
  // Tight: R = 0.05 gives 0.16, far above 9.5e-3: nothing left.
  EXPECT_LT(compression_along_x(0.05), 1e-9 * plain);
}

TEST(Sizing, VelocityGradient) {
  // v = (alpha u_x, 0, 0): V = alpha e_x e_1^T, term diag(alpha^2 / refine_velocity^2, 0).
  Mesh m = make_grid(4, 4, 1.0, 1.0);
  const double alpha = 3, rv = 0.5;
  for (Node& n : m.nodes) n.v = Vec3(alpha * n.x.x(), 0, 0);
  SizingParams p = wide_params();
  p.remeshing.refine_velocity = rv;
  const Mat2 M = face_sizing_terms(m, 3, p, {}).velocity;
  EXPECT_NEAR(M(0, 0), alpha * alpha / (rv * rv), 1e-9);
  EXPECT_NEAR(M(1, 1), 0, 1e-9);
  // The combined metric equals it (every other term is off), and Fp = diag(2, 1, 1) turns it into
  // Fp^-T M Fp^-1 = diag(alpha^2 / (4 rv^2), 0) before the clamp.
  EXPECT_NEAR(face_sizing(m, 3, p, {})(0, 0), alpha * alpha / (rv * rv), 1e-6);
  m.faces[3].Fp = Vec3(2, 1, 1).asDiagonal();
  EXPECT_NEAR(face_sizing(m, 3, p, {})(0, 0), alpha * alpha / (4 * rv * rv), 1e-6);
  SizingExtras no_plastic;
  no_plastic.plastic_transform = false;
  EXPECT_NEAR(face_sizing(m, 3, p, no_plastic)(0, 0), alpha * alpha / (rv * rv), 1e-6);
}

TEST(Sizing, CurvatureOfARolledSheet) {
  // Flat rest, world rolled onto a cylinder of radius R about the y axis: the bending tensor of interior faces
  // is about diag(1/R, 0), so the size along x is R * refine_angle and along y unlimited. The discrete
  // per-face tensor varies between the two triangles of a cell; their mean matches within a few percent.
  const double R = 0.2, angle = 0.1;
  Mesh m = make_grid(10, 10, 0.2, 0.2);
  for (Node& n : m.nodes) {
    const Vec3 u = n.x;
    n.x = Vec3(R * std::sin(u.x() / R), u.y(), R * (1 - std::cos(u.x() / R)));
  }
  SizingParams p = wide_params();
  p.remeshing.refine_angle = angle;
  Mat2 mean = Mat2::Zero();
  int count = 0;
  for (size_t f = 0; f < m.faces.size(); ++f) {
    bool interior = true;
    for (int i = 0; i < 3; ++i) interior = interior && !m.is_boundary_node(m.face_node(static_cast<int>(f), i));
    if (!interior) continue;
    const Mat2 S = face_bending_tensor(m, static_cast<int>(f),
                                       Vec3(m.world_dihedral(m.faces[f].e[0]), m.world_dihedral(m.faces[f].e[1]),
                                            m.world_dihedral(m.faces[f].e[2])));
    mean += S.cwiseAbs();
    ++count;
  }
  mean /= count;
  EXPECT_NEAR(mean(0, 0), 1 / R, 0.05 / R);
  EXPECT_LT(mean(1, 1), 0.05 / R);
  const Mat2 M = face_sizing_terms(m, interior_face(m), p, {}).curvature;
  const Vec2 l = metric_eigenvalues(M);
  EXPECT_NEAR(1 / std::sqrt(l(1)), R * angle, 0.35 * R * angle);  // one face, not the mean
  EXPECT_LT(l(0), 0.1 * l(1));
}

TEST(Sizing, RestCurvatureKeepsACurvedRestShapeResolvedWhenFlattened) {
  // Rest: a cylinder patch (rest angles = its dihedral angles); world: the same sheet unrolled flat. The world
  // curvature term vanishes, the rest-curvature term M_rc = S_rp^T S_rp / refine_angle^2 does not.
  const double R = 0.3, angle = 0.05;
  Mesh m = test::make_cylinder_patch(12, 6, R, 1.2, 0.3);
  for (Node& n : m.nodes) {
    const Vec3 u = m.verts[n.verts[0]].u;
    n.x = Vec3(R * std::atan2(u.x(), u.z()), u.y(), 0);
  }
  SizingParams p = wide_params();
  p.remeshing.refine_angle = angle;
  const int f = interior_face(m);
  const SizingTerms t = face_sizing_terms(m, f, p, {});
  EXPECT_LT(t.curvature.norm(), 1e-9);
  const double size = 1 / std::sqrt(metric_eigenvalues(t.rest_curvature)(1));
  EXPECT_NEAR(size, R * angle, 0.35 * R * angle);
}

TEST(Sizing, ObstacleProximity) {
  // Sheet tilted as z = b u_x above the plane z = -d: h = b u_x + d, grad h = (b, 0), term diag(b^2/h^2, 0)
  // with h the mean height of the face's corners.
  Mesh m = make_grid(4, 4, 1.0, 1.0);
  const double b = 0.2, d = 0.05;
  for (Node& n : m.nodes) n.x.z() = b * n.x.x();
  std::vector<ObstaclePlane> planes(m.nodes.size());
  for (ObstaclePlane& pl : planes) {
    pl.valid = true;
    pl.point = Vec3(0, 0, -d);
    pl.normal = Vec3::UnitZ();
  }
  SizingExtras extras;
  extras.node_planes = &planes;
  const int f = 5;
  double h = 0;
  for (int i = 0; i < 3; ++i) h += (m.nodes[m.face_node(f, i)].x.z() + d) / 3;
  const Mat2 M = face_sizing_terms(m, f, wide_params(), extras).obstacle;
  EXPECT_NEAR(M(0, 0), b * b / (h * h), 1e-9 * b * b / (h * h));
  EXPECT_NEAR(M(1, 1), 0, 1e-12);
  EXPECT_EQ(face_sizing_terms(m, f, wide_params(), {}).obstacle, Mat2::Zero());
}

TEST(Sizing, ExtraTermFractureAndClamp) {
  Mesh m = make_grid(4, 4, 1.0, 1.0);
  SizingParams p;
  p.remeshing.size_min = 0.01;
  p.remeshing.size_max = 0.5;
  p.remeshing.aspect_min = 0.2;
  // Nothing asks for refinement: the coarsest size everywhere.
  Vec2 l = metric_eigenvalues(face_sizing(m, 0, p, {}));
  EXPECT_NEAR(l(0), 4, 1e-9);
  EXPECT_NEAR(l(1), 4, 1e-9);
  // Fracture term at 2 lambda = tau: exactly size_min; at lambda = tau / 4: 2 size_min.
  EXPECT_NEAR(fracture_sizing_term(50, 100, 0.01)(0, 0), 1e4, 1e-6);
  EXPECT_NEAR(fracture_sizing_term(25, 100, 0.01)(1, 1), 2500, 1e-6);
  EXPECT_EQ(fracture_sizing_term(25, 0, 0.01), Mat2::Zero());
  std::vector<Mat3> extra(m.faces.size(), Mat3::Zero());
  extra[0] = Vec3(1e6, 0, 0).asDiagonal();  // would ask for 1 mm along x: clamped to 1 cm, y raised by aspect
  SizingExtras extras;
  extras.face_terms = &extra;
  l = metric_eigenvalues(face_sizing(m, 0, p, extras));
  EXPECT_NEAR(l(1), 1e4, 1e-6);
  EXPECT_NEAR(l(0), 0.04 * 1e4, 1e-6);
}

TEST(Sizing, VertexSizingAndEdgeLengths) {
  Mesh m = make_grid(4, 2, 1.0, 0.5);  // cells 0.25 x 0.25
  SizingExtras uniform;
  uniform.uniform_size = 0.1;
  compute_vertex_sizing(m, wide_params(), uniform);
  for (size_t e = 0; e < m.edges.size(); ++e) {
    const Edge& ed = m.edges[e];
    const double length = (m.nodes[ed.n[1]].x - m.nodes[ed.n[0]].x).norm();
    EXPECT_NEAR(edge_metric_length(m, static_cast<int>(e)), length / 0.1, 1e-9);
  }
  // Area weighting: a vert between a face asking for I/a^2 and one asking for I/b^2 (equal areas) gets the mean.
  Mesh two = make_grid(1, 1, 1.0, 1.0);
  std::vector<Mat3> extra{Mat3::Identity() * 100, Mat3::Identity() * 300};
  SizingExtras extras;
  extras.face_terms = &extra;
  SizingParams p = wide_params();
  compute_vertex_sizing(two, p, extras);
  const int shared = two.faces[0].v[0];  // both faces share the diagonal's ends
  EXPECT_NEAR(two.verts[shared].sizing(0, 0), 200, 1e-6);
}

}  // namespace
}  // namespace arcsim
