// Normals of the flattened collision geometry (collision/contact_geometry.hpp) against closed forms: a regular
// octahedron, whose face normals are (+-1, +-1, +-1)/sqrt(3), node normals the axes and edge normals the
// directions of the edge midpoints; a hinge folded by 90 degrees, whose edge normal bisects the faces;
// boundary edges and degenerate faces; and the global numbering when several meshes are flattened together.
#include "collision/contact_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace arcsim {
namespace {

// Regular octahedron of circumradius `radius` centred at `center`, faces oriented outwards.
Mesh octahedron(double radius, const Vec3& center) {
  std::vector<Vec3> x;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {1.0, -1.0}) x.push_back(center + sign * radius * Vec3::Unit(axis));
  std::vector<std::array<int, 3>> tris;
  for (int sx : {0, 1})
    for (int sy : {2, 3})
      for (int sz : {4, 5}) {
        std::array<int, 3> t{sx, sy, sz};
        const Vec3 n = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
        if (n.dot(x[t[0]] + x[t[1]] + x[t[2]] - 3 * center) < 0) std::swap(t[1], t[2]);
        tris.push_back(t);
      }
  return Mesh::from_triangles(x, x, {0, 1, 2, 3, 4, 5}, tris);
}

ContactGeometry geometry_of(const std::vector<ContactBody>& bodies) {
  ContactGeometry g;
  build_contact_geometry(bodies, ContactStage::kAfterStep, 1e-3, g);
  return g;
}

TEST(ContactGeometryNormals, RegularOctahedron) {
  const Vec3 center(0.3, -1, 2);
  const Mesh m = octahedron(0.5, center);
  const ContactGeometry g = geometry_of({{&m, true}});
  ASSERT_EQ(g.faces.size(), 8u);
  ASSERT_EQ(g.edges.size(), 12u);
  const std::vector<Vec3> fn = face_normals(g, g.x1);
  for (size_t f = 0; f < g.faces.size(); ++f) {
    const Vec3 centroid = (g.x1[g.faces[f][0]] + g.x1[g.faces[f][1]] + g.x1[g.faces[f][2]]) / 3 - center;
    // Outward, unit, and along (+-1, +-1, +-1).
    EXPECT_LT((fn[f] - centroid.normalized()).norm(), 1e-14) << "face " << f;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(std::abs(fn[f](c)), 1 / std::sqrt(3.0), 1e-15) << "face " << f;
  }
  const std::vector<Vec3> nn = node_normals(g, fn);
  for (int v = 0; v < g.node_count(); ++v)
    EXPECT_LT((nn[v] - (g.x1[v] - center).normalized()).norm(), 1e-14) << "node " << v;
  const std::vector<Vec3> en = edge_normals(g, fn);
  for (size_t e = 0; e < g.edges.size(); ++e) {
    const Vec3 mid = 0.5 * (g.x1[g.edges[e][0]] + g.x1[g.edges[e][1]]) - center;
    EXPECT_LT((en[e] - mid.normalized()).norm(), 1e-14) << "edge " << e;
    EXPECT_FALSE(g.is_boundary_edge(static_cast<int>(e)));
  }
}

TEST(ContactGeometryNormals, FoldedHingeAndBoundaryEdges) {
  // Face A in the xy plane (normal +z), face B folded up by 90 degrees about the x axis (normal +y): the
  // shared edge's normal bisects them, each boundary edge has its own face's normal, and the nodes of the
  // shared edge average the two faces' normals.
  const std::vector<Vec3> x{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, 0, 1)};
  const std::vector<Vec3> u{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, -1, 0)};
  const Mesh m = Mesh::from_triangles(x, u, {0, 1, 2, 3}, {{0, 1, 2}, {1, 0, 3}});
  const ContactGeometry g = geometry_of({{&m, true}});
  const std::vector<Vec3> fn = face_normals(g, g.x1);
  EXPECT_LT((fn[0] - Vec3(0, 0, 1)).norm(), 1e-15);
  EXPECT_LT((fn[1] - Vec3(0, 1, 0)).norm(), 1e-15);
  const std::vector<Vec3> en = edge_normals(g, fn);
  const std::vector<Vec3> nn = node_normals(g, fn);
  const Vec3 bisector = Vec3(0, 1, 1).normalized();
  int interior = 0;
  for (size_t e = 0; e < g.edges.size(); ++e) {
    if (g.is_boundary_edge(static_cast<int>(e))) {
      const int f = g.edge_faces[e][0] != kNone ? g.edge_faces[e][0] : g.edge_faces[e][1];
      EXPECT_LT((en[e] - fn[f]).norm(), 1e-15) << "edge " << e;
    } else {
      ++interior;
      EXPECT_LT((en[e] - bisector).norm(), 1e-15);
    }
  }
  EXPECT_EQ(interior, 1);
  EXPECT_LT((nn[0] - bisector).norm(), 1e-15);
  EXPECT_LT((nn[1] - bisector).norm(), 1e-15);
  EXPECT_LT((nn[2] - fn[0]).norm(), 1e-15);
  EXPECT_LT((nn[3] - fn[1]).norm(), 1e-15);
  // Normals follow the positions they are given: flattened (face B unfolded into the plane), every normal is +z.
  std::vector<Vec3> flat = g.x1;
  flat[3] = Vec3(0.5, -1, 0);
  const std::vector<Vec3> fn_flat = face_normals(g, flat);
  for (const Vec3& n : edge_normals(g, fn_flat)) EXPECT_LT((n - Vec3::UnitZ()).norm(), 1e-15);
  for (const Vec3& n : node_normals(g, fn_flat)) EXPECT_LT((n - Vec3::UnitZ()).norm(), 1e-15);
}

TEST(ContactGeometryNormals, DegenerateFaceHasNoNormal) {
  // Face A collapsed onto its edge (zero area): no normal, and it adds nothing to its edges and nodes.
  const std::vector<Vec3> u{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, -1, 0)};
  const Mesh m = Mesh::from_triangles(u, u, {0, 1, 2, 3}, {{0, 1, 2}, {1, 0, 3}});
  const ContactGeometry g = geometry_of({{&m, true}});
  std::vector<Vec3> x = g.x1;
  x[2] = Vec3(0.5, 0, 0);
  const std::vector<Vec3> fn = face_normals(g, x);
  EXPECT_EQ(fn[0], Vec3::Zero());
  EXPECT_LT((fn[1] - Vec3::UnitZ()).norm(), 1e-15);
  const std::vector<Vec3> nn = node_normals(g, fn);
  EXPECT_EQ(nn[2], Vec3::Zero());  // its only face is degenerate
  EXPECT_LT((nn[0] - Vec3::UnitZ()).norm(), 1e-15);
  for (const Vec3& n : edge_normals(g, fn)) EXPECT_TRUE(n == Vec3::Zero() || (n - Vec3::UnitZ()).norm() < 1e-15);
}

TEST(ContactGeometryNormals, SeveralMeshesAreNumberedGlobally) {
  // Two octahedra (a cloth and an obstacle): the second one's faces, edges and nodes follow the first one's in
  // the flattened numbering, and its normals are those of an octahedron about its own centre.
  const Vec3 ca(0, 0, 0), cb(3, 1, -2);
  const Mesh a = octahedron(1, ca), b = octahedron(0.25, cb);
  const ContactGeometry g = geometry_of({{&a, true}, {&b, false}});
  ASSERT_EQ(g.meshes.size(), 2u);
  const ContactGeometry::Range& rb = g.meshes[1];
  EXPECT_EQ(rb.node_begin, 6);
  EXPECT_EQ(rb.face_begin, 8);
  EXPECT_EQ(rb.edge_begin, 12);
  EXPECT_FALSE(g.movable(rb.node_begin));
  const std::vector<Vec3> fn = face_normals(g, g.x1);
  const std::vector<Vec3> nn = node_normals(g, fn);
  const std::vector<Vec3> en = edge_normals(g, fn);
  for (int v = rb.node_begin; v < rb.node_end; ++v)
    EXPECT_LT((nn[v] - (g.x1[v] - cb).normalized()).norm(), 1e-14) << "node " << v;
  for (int e = rb.edge_begin; e < rb.edge_end; ++e) {
    const Vec3 mid = 0.5 * (g.x1[g.edges[e][0]] + g.x1[g.edges[e][1]]) - cb;
    EXPECT_LT((en[e] - mid.normalized()).norm(), 1e-14) << "edge " << e;
  }
  for (int f = rb.face_begin; f < rb.face_end; ++f)
    for (int v : g.faces[f]) EXPECT_GE(v, rb.node_begin);
}

}  // namespace
}  // namespace arcsim
