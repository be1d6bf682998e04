// The low-level element functions of Mesh (add/remove, adjacency, compact) and its queries.
#include <gtest/gtest.h>

#include <cmath>

#include "mesh/validate.hpp"
#include "mesh_fixtures.hpp"

namespace arcsim {
namespace {

using test::grid_node;
using test::make_flat_grid;

// Unit square from two triangles (0, 1, 2) and (0, 2, 3), nodes counter-clockwise from the origin.
Mesh unit_square() {
  const std::vector<Vec3> p{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  return Mesh::from_triangles(p, p, {0, 1, 2, 3}, {{0, 1, 2}, {0, 2, 3}});
}

TEST(MeshCore, FromTrianglesBuildsAdjacencyAndOrientation) {
  Mesh m = unit_square();
  ASSERT_EQ(m.edges.size(), 5u);
  const int diagonal = m.find_edge(0, 2);
  ASSERT_NE(diagonal, kNone);
  EXPECT_EQ(m.find_edge(2, 0), diagonal);
  EXPECT_EQ(m.find_edge(1, 3), kNone);
  // Face 0 runs 2 -> 0, face 1 runs 0 -> 2.
  const Edge& d = m.edges[diagonal];
  const int f_forward = d.n[0] == 0 ? 1 : 0;  // the face running n[0] -> n[1]
  EXPECT_EQ(d.f[0], f_forward);
  EXPECT_EQ(d.f[1], 1 - f_forward);
  EXPECT_FALSE(d.is_boundary());
  EXPECT_TRUE(m.edges[m.find_edge(0, 1)].is_boundary());
  // e[i] joins corners i and i+1.
  for (int f = 0; f < 2; ++f)
    for (int i = 0; i < 3; ++i) EXPECT_EQ(m.faces[f].e[i], m.find_edge(m.face_node(f, i), m.face_node(f, (i + 1) % 3)));
  EXPECT_EQ(m.opposite_node(diagonal, 0), 1);
  EXPECT_EQ(m.opposite_node(diagonal, 1), 3);
  EXPECT_EQ(m.other_face(diagonal, 0), 1);
  EXPECT_EQ(m.corner_of_node(1, 3), 2);
  EXPECT_EQ(m.corner_of_node(1, 1), kNone);
  EXPECT_DOUBLE_EQ(m.faces[0].rest_area, 0.5);
  EXPECT_TRUE(m.faces[0].rest_normal.isApprox(Vec3::UnitZ()));
  EXPECT_TRUE(m.is_compact());
  EXPECT_EQ(check_mesh(m), "");
}

TEST(MeshCore, RestDataFrameAndInverseEdgeMatrix) {
  Mesh m = unit_square();
  const Face& f = m.faces[0];
  // The frame is orthonormal, in the face plane, and Dm_inv maps the rest edges to the unit basis.
  const Mat32& T = f.rest_frame;
  EXPECT_NEAR((T.transpose() * T - Mat2::Identity()).norm(), 0, 1e-12);
  const Vec3 d1 = m.verts[f.v[1]].u - m.verts[f.v[0]].u, d2 = m.verts[f.v[2]].u - m.verts[f.v[0]].u;
  Mat2 Dm;
  Dm << T.col(0).dot(d1), T.col(0).dot(d2), T.col(1).dot(d1), T.col(1).dot(d2);
  EXPECT_NEAR((f.Dm_inv * Dm - Mat2::Identity()).norm(), 0, 1e-12);
}

TEST(MeshCore, DihedralSignsAgreeInRestAndWorld) {
  // Fold the square along the diagonal: node 3 lifted in rest and world space.
  std::vector<Vec3> p{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0.5)};
  Mesh m = Mesh::from_triangles(p, p, {0, 1, 2, 3}, {{0, 1, 2}, {0, 2, 3}});
  const int d = m.find_edge(0, 2);
  EXPECT_GT(std::abs(m.rest_dihedral(d)), 0.1);
  EXPECT_NEAR(m.rest_dihedral(d), m.world_dihedral(d), 1e-12);
  EXPECT_NEAR(m.edges[d].rest_theta, m.rest_dihedral(d), 1e-12);  // from_triangles stores it
  EXPECT_EQ(m.rest_dihedral(m.find_edge(0, 1)), 0.0);             // boundary
}

TEST(MeshCore, AddElementsFromRemovedPrototypesAreAlive) {
  Mesh m = unit_square();
  const Face old_face = m.faces[1];
  m.remove_face(1);
  m.remove_edge(m.find_edge(2, 3));
  m.remove_edge(m.find_edge(3, 0));
  m.remove_vert(3);
  m.remove_node(3);
  EXPECT_FALSE(m.is_compact());
  EXPECT_EQ(check_mesh(m), "");
  // Re-adding from the tombstones must give live elements.
  const int n = m.add_node(m.nodes[3]);
  EXPECT_FALSE(m.nodes[n].dead);
  EXPECT_TRUE(m.nodes[n].verts.empty());
  EXPECT_TRUE(m.nodes[n].edges.empty());
  const int v = m.add_vert(m.verts[3], n);
  EXPECT_FALSE(m.verts[v].dead);
  EXPECT_EQ(m.verts[v].node, n);
  EXPECT_EQ(m.nodes[n].verts, std::vector<int>{v});
  Face proto = m.faces[1];
  ASSERT_TRUE(proto.dead);
  const int f = m.add_face({0, 2, v}, proto);
  m.update_rest_data(f);
  EXPECT_FALSE(m.faces[f].dead);
  EXPECT_EQ(m.faces[f].material, old_face.material);
  EXPECT_EQ(check_mesh(m), "");
}

TEST(MeshCore, AddFaceLinksEdgesAndRefusesConflictsWithoutChanges) {
  Mesh m = unit_square();
  const size_t edges = m.edges.size(), faces = m.faces.size();
  const std::vector<int> vert0_faces = m.verts[0].faces;
  // Same orientation as face 0 on edge 0-1: refused, nothing changed.
  EXPECT_THROW(m.add_face({0, 1, 3}, Face()), std::logic_error);
  EXPECT_EQ(m.edges.size(), edges);
  EXPECT_EQ(m.faces.size(), faces);
  EXPECT_EQ(m.verts[0].faces, vert0_faces);
  // Degenerate (node repeated through a second vert).
  const int v = m.add_vert(Vert(), 0);
  EXPECT_THROW(m.add_face({0, 1, v}, Face()), std::logic_error);
  EXPECT_EQ(m.edges.size(), edges);
  // A valid face on the other side of 0-1 creates two edges and takes side f[1] of 0-1.
  const int n4 = m.add_node(Node());
  Vert vert;
  vert.u = Vec3(0.5, -1, 0);
  const int v4 = m.add_vert(vert, n4);
  const int f = m.add_face({1, 0, v4}, Face());
  EXPECT_EQ(m.edges.size(), edges + 2);
  const Edge& bottom = m.edges[m.find_edge(0, 1)];
  EXPECT_FALSE(bottom.is_boundary());
  EXPECT_EQ(bottom.f[bottom.n[0] == 1 ? 0 : 1], f);
  // get_or_add_edge finds existing edges either way round.
  EXPECT_EQ(m.get_or_add_edge(n4, 0), m.find_edge(0, n4));
  EXPECT_EQ(m.edges.size(), edges + 2);
  m.remove_vert(v);
  m.update_rest_data();
  EXPECT_EQ(check_mesh(m), "");
}

TEST(MeshCore, RemoveUnlinksBothWays) {
  Mesh m = unit_square();
  const int diagonal = m.find_edge(0, 2);
  m.remove_face(0);
  EXPECT_TRUE(m.faces[0].dead);
  EXPECT_TRUE(m.edges[diagonal].is_boundary());
  EXPECT_TRUE(m.verts[1].faces.empty());
  EXPECT_EQ(m.verts[0].faces, std::vector<int>{1});
  const int e01 = m.find_edge(0, 1), e12 = m.find_edge(1, 2);
  EXPECT_EQ(m.edges[e01].f[0], kNone);
  EXPECT_EQ(m.edges[e01].f[1], kNone);
  m.remove_edge(e01);
  m.remove_edge(e12);
  EXPECT_EQ(m.find_edge(0, 1), kNone);
  EXPECT_TRUE(m.nodes[1].edges.empty());
  m.remove_vert(1);
  EXPECT_TRUE(m.nodes[1].verts.empty());
  m.remove_node(1);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_FALSE(m.is_boundary_node(1));
  EXPECT_TRUE(m.is_boundary_node(0));
}

TEST(MeshCore, CompactRenumbersEverythingAndKeepsOrder) {
  Mesh m = make_flat_grid(3, 3);
  std::mt19937 rng(3);
  test::fill_random_state(m, rng);
  // Remove the corner face at node (3, 0) and everything only it used.
  const int corner = grid_node(3, 3, 0);
  const int f = m.verts[m.nodes[corner].verts[0]].faces.at(0);
  m.remove_face(f);
  for (int e : std::vector<int>(m.nodes[corner].edges)) m.remove_edge(e);
  m.remove_vert(m.nodes[corner].verts[0]);
  m.remove_node(corner);
  ASSERT_EQ(check_mesh(m), "");
  const Mesh before = m;

  const Mesh::Compaction c = m.compact();
  EXPECT_TRUE(m.is_compact());
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_EQ(m.nodes.size(), before.nodes.size() - 1);
  EXPECT_EQ(m.verts.size(), before.verts.size() - 1);
  EXPECT_EQ(m.faces.size(), before.faces.size() - 1);
  // The two boundary edges at the corner went; the diagonal, shared with the next face, stays.
  EXPECT_EQ(m.edges.size(), before.edges.size() - 2);
  EXPECT_EQ(c.node[corner], kNone);
  EXPECT_EQ(c.face[f], kNone);
  // Order kept, state moved with the elements, references renumbered.
  int expected = 0;
  for (size_t i = 0; i < before.nodes.size(); ++i) {
    if (before.nodes[i].dead) continue;
    EXPECT_EQ(c.node[i], expected++);
    EXPECT_EQ(m.nodes[c.node[i]].x, before.nodes[i].x);
    EXPECT_EQ(m.nodes[c.node[i]].v, before.nodes[i].v);
  }
  for (size_t i = 0; i < before.faces.size(); ++i) {
    if (before.faces[i].dead) continue;
    const Face& nf = m.faces[c.face[i]];
    EXPECT_EQ(nf.thickness, before.faces[i].thickness);
    EXPECT_EQ(nf.Fp, before.faces[i].Fp);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(nf.v[k], c.vert[before.faces[i].v[k]]);
      EXPECT_EQ(nf.e[k], c.edge[before.faces[i].e[k]]);
      EXPECT_EQ(m.verts[nf.v[k]].u, before.verts[before.faces[i].v[k]].u);
    }
  }
  for (size_t i = 0; i < before.edges.size(); ++i) {
    if (before.edges[i].dead) continue;
    const Edge& ne = m.edges[c.edge[i]];
    EXPECT_EQ(ne.damage, before.edges[i].damage);
    EXPECT_EQ(ne.rest_theta, before.edges[i].rest_theta);
    for (int s = 0; s < 2; ++s) {
      EXPECT_EQ(ne.n[s], c.node[before.edges[i].n[s]]);
      EXPECT_EQ(ne.f[s], before.edges[i].f[s] == kNone ? kNone : c.face[before.edges[i].f[s]]);
    }
  }
  // Compacting a compact mesh is the identity.
  const Mesh::Compaction again = m.compact();
  for (size_t i = 0; i < again.face.size(); ++i) EXPECT_EQ(again.face[i], static_cast<int>(i));
}

TEST(MeshCore, WorldQueries) {
  Mesh m = unit_square();
  m.nodes[2].x = Vec3(2, 2, 0);
  EXPECT_DOUBLE_EQ(m.world_area(0), 1.0);
  EXPECT_TRUE(m.world_normal(0).isApprox(Vec3::UnitZ()));
  // A collapsed world triangle has a defined (not NaN) normal.
  m.nodes[1].x = m.nodes[0].x;
  EXPECT_TRUE(m.world_normal(0).allFinite());
  EXPECT_EQ(m.world_area(0), 0.0);
}

}  // namespace
}  // namespace arcsim
