// The face-element builder: stiffness weakening, masses and plastic rest measure against closed forms, the
// wings of bending elements, and the callers agreeing with each other (the full step's cache, the world
// reprojection of remeshing) because they build their elements here.
#include <gtest/gtest.h>

#include <cmath>

#include "physics/cloth_physics.hpp"
#include "physics/face_element.hpp"
#include "physics/membrane.hpp"
#include "physics/zone_fixtures.hpp"
#include "remesh/reprojection.hpp"

namespace arcsim {
namespace {

using testing::ZoneTestSheet;

TEST(FaceElement, MembraneStiffnessIsWeakenedByDamage) {
  ZoneTestSheet sheet(4);
  Face& face = sheet.mesh.faces[3];
  const Material& m = sheet.materials[0];
  face.damage = 0.8;
  const MembraneStiffness plain = m.membrane_stiffness(face.thickness);
  const MembraneStiffness weak = face_membrane_stiffness(face, m);
  const double factor = 1 / (1 + m.weakening * face.damage);  // 1 / 1.4
  EXPECT_NEAR(weak.k11, plain.k11 * factor, 1e-15 * plain.k11);
  EXPECT_NEAR(weak.k12, plain.k12 * factor, 1e-15 * plain.k11);
  EXPECT_NEAR(weak.k22, plain.k22 * factor, 1e-15 * plain.k11);
  EXPECT_NEAR(weak.k33, plain.k33 * factor, 1e-15 * plain.k11);
  const MembraneStiffness ignored = face_membrane_stiffness(face, m, MembraneWeakening::kIgnored);
  EXPECT_EQ(ignored.k11, plain.k11);
  EXPECT_EQ(ignored.k33, plain.k33);
  EXPECT_EQ(make_face_element(sheet.mesh, sheet.materials, 3).k.k22, weak.k22);
}

TEST(FaceElement, CornerMassesAddUpToTheSheetsMass) {
  const ZoneTestSheet sheet(6);
  const Material& m = sheet.materials[0];
  double lumped = 0, area = 0;
  for (const Face& f : sheet.mesh.faces) {
    lumped += 3 * face_corner_mass(f, m);
    area += f.rest_area;
  }
  EXPECT_NEAR(lumped, m.density * m.thickness * area, 1e-14 * lumped);
  double nodes = 0;
  for (const Node& n : sheet.mesh.nodes) nodes += n.mass;
  EXPECT_NEAR(nodes, lumped, 1e-14 * lumped);
}

// At the rest positions the elastic deformation gradient is the plastic stretch in the face's frame:
// [u1-u0, u2-u0] Dm_inv = rest_frame, so F_el = rest_frame Fp2.
TEST(FaceElement, RestMeasureCarriesThePlasticStretch) {
  ZoneTestSheet sheet(4);
  const int f = 5;
  Face& face = sheet.mesh.faces[f];
  Mat2 Fp2;
  Fp2 << 0.9, 0.05, -0.02, 1.1;
  face.Fp = face_plastic_stretch_3d(face, Fp2);
  EXPECT_LT((face_plastic_stretch_2d(face) - Fp2).norm(), 1e-14);
  const FaceElement el = make_face_element(sheet.mesh, sheet.materials, f);
  const Vec3& u0 = sheet.mesh.verts[face.v[0]].u;
  const Vec3& u1 = sheet.mesh.verts[face.v[1]].u;
  const Vec3& u2 = sheet.mesh.verts[face.v[2]].u;
  const Mat32 F_el = membrane_deformation_gradient(u0, u1, u2, el.Dm_inv);
  EXPECT_LT((F_el - face.rest_frame * Fp2).norm(), 1e-12);
  // Without plasticity the rest measure is exactly Dm_inv.
  face.Fp = Mat3::Identity();
  EXPECT_EQ(face_elastic_dm_inv(face), face.Dm_inv);
}

TEST(FaceElement, BendingMatrixIsWeakenedByEdgeDamage) {
  ZoneTestSheet sheet(4);
  Mesh& mesh = sheet.mesh;
  const int f = 12;
  const Material& m = sheet.materials[0];
  const std::array<bool, 3> wings{true, true, true};
  for (int e : mesh.faces[f].e) mesh.edges[e].damage = 0;
  const Mat3 Q = face_bending_matrix(mesh, m, f, wings);
  for (int e : mesh.faces[f].e) mesh.edges[e].damage = 2;
  const Mat3 weak = face_bending_matrix(mesh, m, f, wings);
  EXPECT_LT((weak - Q / (1 + m.weakening * 2)).norm(), 1e-14 * Q.norm());
  EXPECT_GT(Q.norm(), 0);
}

TEST(FaceElement, BendingElementWings) {
  const ZoneTestSheet sheet(4);
  const Mesh& mesh = sheet.mesh;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const BendingElement b = make_bending_element(mesh, sheet.materials, static_cast<int>(f));
    for (int i = 0; i < 3; ++i) {
      const int e = mesh.faces[f].e[i];
      EXPECT_EQ(b.has_wing[i], !mesh.edges[e].is_boundary());
      if (b.has_wing[i])
        EXPECT_EQ(b.nodes[3 + i], mesh.opposite_node(e, mesh.other_face(e, static_cast<int>(f))));
      else
        EXPECT_EQ(b.nodes[3 + i], b.nodes[0]);
      EXPECT_EQ(b.rest_theta[i], mesh.edges[e].rest_theta);
    }
    EXPECT_EQ(b.dofs, b.nodes);
  }
}

// The world reprojection of remeshing and the full step build the same elements: the node energy gradient of
// the reprojection (no load) equals minus the full step's internal force at every node.
TEST(FaceElement, ReprojectionAndFullStepSeeTheSameForces) {
  ZoneTestSheet sheet(6);
  for (Node& n : sheet.mesh.nodes) n.a.setZero();
  ElementCache cache;
  build_element_cache(sheet.mesh, sheet.materials, cache);
  const VecX f = internal_forces(sheet.mesh, cache);
  ASSERT_GT(f.norm(), 0);
  ReprojectionParams params;
  params.gravity.setZero();
  for (size_t n = 0; n < sheet.mesh.nodes.size(); ++n) {
    const LocalEnergy local = node_local_energy(sheet.mesh, sheet.materials, static_cast<int>(n),
                                                sheet.mesh.nodes[n].x, params);
    EXPECT_LT((local.gradient + f.segment<3>(3 * n)).norm(), 1e-9 * f.norm()) << "node " << n;
  }
}

}  // namespace
}  // namespace arcsim
