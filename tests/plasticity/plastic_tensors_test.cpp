// Face bending-strain tensors <-> per-edge plastic offsets (paper Eq. 3 / 11) and the edge rest angles built
// from them.
#include <gtest/gtest.h>

#include <cmath>

#include "plasticity/plastic_tensors.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using testing::Diagonal;
using testing::make_grid;

TEST(PlasticTensors, OffsetsRoundTripThroughTheTensorOnTiltedFaces) {
  // A face not in the xy plane, so that rest_frame and normals are general 3D vectors.
  const std::vector<Vec3> u{{0, 0, 0}, {0.03, 0.01, 0.02}, {-0.005, 0.025, 0.01}};
  Mesh mesh = Mesh::from_triangles(u, u, {0, 1, 2}, {{0, 1, 2}});
  const Vec3 offsets(0.1, -0.05, 0.02);
  const Mat3 S = face_bending_strain_from_offsets(mesh, 0, offsets);
  EXPECT_NEAR((S - S.transpose()).norm(), 0, 1e-12);
  EXPECT_NEAR((S * mesh.faces[0].rest_normal).norm(), 0, 1e-12 * S.norm());  // in the tangent plane
  EXPECT_NEAR((face_offsets_from_bending_strain(mesh, 0, S) - offsets).norm(), 0, 1e-12);
}

TEST(PlasticTensors, TensorOfOneEdgeOffsetIsHandComputed) {
  // Right triangle (0,0), (a,0), (0,a): edge 0 runs along x, its normal is -y (d x n = (1,0,0) x (0,0,1)).
  const double a = 0.02;
  const std::vector<Vec3> u{{0, 0, 0}, {a, 0, 0}, {0, a, 0}};
  Mesh mesh = Mesh::from_triangles(u, u, {0, 1, 2}, {{0, 1, 2}});
  const Mat3 S = face_bending_strain_from_offsets(mesh, 0, Vec3(0.3, 0, 0));
  // S = d l / (2 A) n n^T = 0.3 a / a^2 e_y e_y^T.
  Mat3 expected = Mat3::Zero();
  expected(1, 1) = 0.3 / a;
  EXPECT_NEAR((S - expected).norm(), 0, 1e-10);
}

TEST(PlasticTensors, UniformCurvatureGivesConsistentEdgeRestAngles) {
  // Sp = kappa e_x e_x^T on every face of a flat grid: each interior edge gets the same offset from both of its
  // faces, and the offsets read back from the edges reproduce every face's Sp.
  for (Diagonal diagonal : {Diagonal::kForward, Diagonal::kAlternating}) {
    Mesh mesh = make_grid(6, 4, 0.12, 0.08, diagonal);
    Mat3 Sp = Mat3::Zero();
    Sp(0, 0) = 7.5;  // 1/m
    for (Face& f : mesh.faces) f.Sp = Sp;
    update_edge_rest_angles_from_Sp(mesh, {});
    for (size_t fi = 0; fi < mesh.faces.size(); ++fi) {
      const Face& f = mesh.faces[fi];
      Vec3 from_edges;
      for (int i = 0; i < 3; ++i) from_edges[i] = mesh.edges[f.e[i]].rest_theta - mesh.rest_dihedral(f.e[i]);
      const Mat3 S = face_bending_strain_from_offsets(mesh, static_cast<int>(fi), from_edges);
      EXPECT_NEAR((S - Sp).norm(), 0, 1e-9) << "face " << fi;
    }
    // An edge across the bending direction (along y, spacing 2 cm) bends by about kappa * spacing.
    const int e = mesh.find_edge(1 + 7 * 1, 1 + 7 * 2);  // nodes (1,1)-(1,2), interior vertical edge
    ASSERT_NE(e, kNone);
    EXPECT_NEAR(std::abs(mesh.edges[e].rest_theta), 7.5 * 0.02, 0.3 * 7.5 * 0.02);
  }
}

TEST(PlasticTensors, ZeroSpGivesGeometricRestAnglesAndDamageAverages) {
  Mesh mesh = make_grid(3, 3, 0.03, 0.03);
  for (Edge& e : mesh.edges) e.rest_theta = 1.0;
  mesh.faces[0].damage = 2.0;
  update_edge_rest_angles_from_Sp(mesh, {});
  update_edge_damage_from_faces(mesh, {mesh.faces[0].e[0], mesh.faces[0].e[1]});
  for (size_t e = 0; e < mesh.edges.size(); ++e) EXPECT_EQ(mesh.edges[e].rest_theta, 0.0);
  // e[0] of face 0 is on the border (one face), e[1] is shared with face 1.
  EXPECT_EQ(mesh.edges[mesh.faces[0].e[0]].damage, 2.0);
  EXPECT_EQ(mesh.edges[mesh.faces[0].e[1]].damage, 1.0);
}

TEST(PlasticTensors, DegenerateFaceGivesZeroOffsets) {
  const std::vector<Vec3> u{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  Mesh mesh = Mesh::from_triangles(u, u, {0, 1, 2}, {{0, 1, 2}});
  Mat3 S = Mat3::Identity();
  const Vec3 d = face_offsets_from_bending_strain(mesh, 0, S);
  EXPECT_TRUE(d.isZero(0));
  EXPECT_TRUE(face_bending_strain_from_offsets(mesh, 0, Vec3(1, 2, 3)).isZero(0));
}

TEST(PlasticTensors, PlasticStretchEmbeddingRoundTrips) {
  const std::vector<Vec3> u{{0, 0, 0}, {0.03, 0.01, 0.02}, {-0.005, 0.025, 0.01}};
  Mesh mesh = Mesh::from_triangles(u, u, {0, 1, 2}, {{0, 1, 2}});
  Face& f = mesh.faces[0];
  Mat2 Fp2;
  Fp2 << 0.9, 0.05, -0.02, 1.1;
  f.Fp = face_plastic_stretch_3d(f, Fp2);
  EXPECT_NEAR((face_plastic_stretch_2d(f) - Fp2).norm(), 0, 1e-14);
  EXPECT_NEAR((f.Fp * f.rest_normal - f.rest_normal).norm(), 0, 1e-14);
  EXPECT_TRUE(face_plastic_stretch_3d(f, Mat2::Identity()).isIdentity(0));
}

}  // namespace
}  // namespace arcsim
