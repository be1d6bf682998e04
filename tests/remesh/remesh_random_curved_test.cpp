// Randomised remeshing of a curved, plastically deformed, two-material sheet (issue 4 acceptance 4): after every
// pass the mesh is manifold and consistently oriented (check_mesh), no face is inverted in rest space, rest
// verts stay on the reference surface, and all per-element state is defined: material indices in range,
// thickness positive and finite, rest angles, plastic tensors Fp (invertible) and Sp finite.
#include <gtest/gtest.h>

#include <random>

#include "mesh/validate.hpp"
#include "remesh/remesh.hpp"
#include "remesh/remesh_fixtures.hpp"
#include "restshape/reference_surface.hpp"

namespace arcsim {
namespace {

using namespace remesh_test;

// "" if every live face's state is defined, else the first face at fault.
std::string undefined_face_state(const Mesh& m, int materials) {
  for (size_t f = 0; f < m.faces.size(); ++f) {
    const Face& face = m.faces[f];
    if (face.dead) continue;
    const std::string at = "face " + std::to_string(f) + ": ";
    if (face.material < 0 || face.material >= materials) return at + "material " + std::to_string(face.material);
    if (!(face.thickness > 0) || !std::isfinite(face.thickness)) return at + "thickness";
    if (!face.Fp.allFinite() || !(face.Fp.determinant() > 0)) return at + "Fp";
    if (!face.Sp.allFinite()) return at + "Sp";
  }
  for (size_t e = 0; e < m.edges.size(); ++e)
    if (!m.edges[e].dead && !std::isfinite(m.edges[e].rest_theta)) return "edge " + std::to_string(e);
  return "";
}

// Random in-plane plastic stretch (a few %) and plastic curvature (up to 2 1/m) in each face's rest frame, and a
// random thickness around the material's.
void randomise_face_state(Mesh& m, std::mt19937& rng) {
  std::uniform_real_distribution<double> sym(-1, 1);
  m.update_rest_data();
  for (Face& f : m.faces) {
    Mat2 s, k;
    s << sym(rng), sym(rng), 0, sym(rng);
    k << sym(rng), sym(rng), 0, sym(rng);
    s(1, 0) = s(0, 1);
    k(1, 0) = k(0, 1);
    f.Fp = Mat3::Identity() + f.rest_frame * (0.04 * s) * f.rest_frame.transpose();
    f.Sp = f.rest_frame * (2.0 * k) * f.rest_frame.transpose();
    f.thickness *= 1 + 0.2 * sym(rng);
  }
}

TEST(RemeshRandomCurved, PassesKeepAPlasticTwoMaterialDomeValid) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> unit(0, 1), sym(-1, 1);
  const std::vector<Material> materials{cotton(), glass()};
  for (int trial = 0; trial < 3; ++trial) {
    const double R = 0.2;
    Mesh m = make_spherical_cap(R, 1.0, 4 + trial);
    const auto ref = make_mesh_reference(m);
    for (Face& f : m.faces) {
      const Vec3 c = (m.verts[f.v[0]].u + m.verts[f.v[1]].u + m.verts[f.v[2]].u) / 3;
      f.material = c.x() > 0 ? 1 : 0;  // two halves
      f.thickness = materials[f.material].thickness;
    }
    randomise_face_state(m, rng);
    for (Node& n : m.nodes) {
      n.x += 0.01 * Vec3(sym(rng), sym(rng), sym(rng));
      n.x0 = n.x;
      n.v = Vec3(sym(rng), sym(rng), sym(rng));
      n.a = Vec3(sym(rng), sym(rng), sym(rng));
    }
    int changes = 0;
    for (int pass = 0; pass < 6; ++pass) {
      RemeshOptions o;
      o.reference = ref.get();
      o.sizing.remeshing.size_min = 0.02;
      o.sizing.remeshing.size_max = 0.03 + 0.2 * unit(rng);
      o.sizing.remeshing.aspect_min = 0.2;
      o.sizing.remeshing.refine_angle = 0.2 + 0.3 * unit(rng);
      o.sizing.remeshing.refine_velocity = 2 + 10 * unit(rng);
      o.sizing.remeshing.refine_compression = 0.01;
      const RemeshStats st = remesh_mesh(m, materials, o);
      const std::string where = "trial " + std::to_string(trial) + " pass " + std::to_string(pass);
      changes += st.splits + st.collapses;
      ASSERT_EQ(check_mesh(m), "") << where;
      ASSERT_EQ(inverted_face(m, [](const Vec3& c) { return c; }), "") << where;
      ASSERT_EQ(undefined_face_state(m, 2), "") << where;
      for (const Vert& v : m.verts) {
        if (v.dead) continue;
        ASSERT_LT((ref->closest_point(v.u) - v.u).norm(), 1e-9) << where;
      }
      m.compact();
      ASSERT_EQ(check_mesh(m), "") << where << " after compact";
    }
    EXPECT_GT(changes, 50) << "trial " << trial;
  }
}

}  // namespace
}  // namespace arcsim
