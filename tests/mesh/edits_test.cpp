// Unit tests of the topology edits on small hand-built meshes: exact resulting topology, positions, inherited
// state, seams, and refusals that leave the mesh untouched.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "mesh/edits.hpp"
#include "mesh/validate.hpp"
#include "mesh_fixtures.hpp"

namespace arcsim {
namespace {

using test::find_face;
using test::fingerprint;
using test::grid_node;
using test::live_count;
using test::make_flat_grid;

// Unit square from faces (0, 1, 2) and (0, 2, 3); world = rest + (0, 0, 1); faces and edges carry distinct state.
Mesh unit_square() {
  const std::vector<Vec3> u{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  std::vector<Vec3> x;
  for (const Vec3& p : u) x.push_back(p + Vec3(0, 0, 1));
  Mesh m = Mesh::from_triangles(x, u, {0, 1, 2, 3}, {{0, 1, 2}, {0, 2, 3}});
  for (int f = 0; f < 2; ++f) {
    m.faces[f].thickness = 0.001 * (f + 1);
    m.faces[f].damage = 0.1 * (f + 1);
    m.faces[f].Fp = Mat3::Identity() * (1 + 0.5 * f);
    m.faces[f].Sp = Mat3::Constant(f + 2.0);
  }
  for (int n = 0; n < 4; ++n) {
    m.nodes[n].v = Vec3(n, 0, 0);
    m.nodes[n].a = Vec3(0, n, 0);
    m.nodes[n].x0 = m.nodes[n].x + Vec3(0, 0, n);
  }
  return m;
}

// Rest-space normal of a live face, from its verts.
Vec3 rest_normal(const Mesh& m, int f) {
  const Vec3& u0 = m.verts[m.faces[f].v[0]].u;
  return (m.verts[m.faces[f].v[1]].u - u0).cross(m.verts[m.faces[f].v[2]].u - u0).normalized();
}

bool all_live(const std::vector<int>& indices, const std::vector<Face>& faces) {
  for (int i : indices)
    if (faces[i].dead) return false;
  return true;
}

// ------------------------------------------------------------------------------------------------------------
// split_edge

TEST(SplitEdge, InteriorEdgeOfSquare) {
  Mesh m = unit_square();
  const int diagonal = m.find_edge(0, 2);
  m.edges[diagonal].rest_theta = 0.3;
  m.edges[diagonal].damage = 0.4;
  m.edges[diagonal].preserve = true;
  const int a = m.edges[diagonal].n[0], b = m.edges[diagonal].n[1];
  const double t = 0.25;

  const EditResult r = split_edge(m, diagonal, t);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  ASSERT_EQ(r.added_nodes, std::vector<int>{4});
  EXPECT_EQ(r.added_verts, std::vector<int>{4});
  EXPECT_EQ(r.removed_faces, (std::vector<int>{0, 1}));
  EXPECT_EQ(r.removed_edges, std::vector<int>{diagonal});
  EXPECT_EQ(r.added_faces.size(), 4u);
  EXPECT_EQ(r.added_edges.size(), 4u);
  EXPECT_TRUE(all_live(r.added_faces, m.faces));
  EXPECT_TRUE(m.edges[diagonal].dead);

  const Node& n = m.nodes[4];
  const Node &na = m.nodes[a], &nb = m.nodes[b];
  EXPECT_TRUE(n.x.isApprox((1 - t) * na.x + t * nb.x));
  EXPECT_TRUE(n.x0.isApprox((1 - t) * na.x0 + t * nb.x0));
  EXPECT_TRUE(n.v.isApprox((1 - t) * na.v + t * nb.v));
  EXPECT_TRUE(n.a.isApprox((1 - t) * na.a + t * nb.a));
  EXPECT_TRUE(m.verts[4].u.isApprox((1 - t) * m.verts[a].u + t * m.verts[b].u));

  // Topology: the four triangles around the new node, each oriented like the parent (+z).
  const int f012[2] = {find_face(m, 0, 1, 4), find_face(m, 1, 2, 4)};
  const int f023[2] = {find_face(m, 0, 3, 4), find_face(m, 2, 3, 4)};
  for (int f : {f012[0], f012[1], f023[0], f023[1]}) {
    ASSERT_NE(f, kNone);
    EXPECT_TRUE(rest_normal(m, f).isApprox(Vec3::UnitZ()));
  }
  EXPECT_EQ(live_count(m.faces), 4);
  EXPECT_NEAR(test::total_rest_area(m), 1.0, 1e-14);
  // Children copy the parent's state.
  for (int f : f012) {
    EXPECT_EQ(m.faces[f].thickness, 0.001);
    EXPECT_EQ(m.faces[f].damage, 0.1);
    EXPECT_EQ(m.faces[f].Fp, Mat3::Identity());
    EXPECT_EQ(m.faces[f].Sp, Mat3::Constant(2.0));
  }
  for (int f : f023) {
    EXPECT_EQ(m.faces[f].thickness, 0.002);
    EXPECT_EQ(m.faces[f].Fp, Mat3::Identity() * 1.5);
  }
  // Halves copy the split edge; the new cross edges are flat and take the face damage.
  for (int end : {0, 2}) {
    const Edge& half = m.edges[m.find_edge(end, 4)];
    EXPECT_EQ(half.rest_theta, 0.3);
    EXPECT_EQ(half.damage, 0.4);
    EXPECT_TRUE(half.preserve);
    EXPECT_FALSE(half.is_boundary());
  }
  const Edge& cross1 = m.edges[m.find_edge(1, 4)];
  const Edge& cross3 = m.edges[m.find_edge(3, 4)];
  EXPECT_EQ(cross1.rest_theta, 0.0);
  EXPECT_EQ(cross1.damage, 0.1);
  EXPECT_FALSE(cross1.preserve);
  EXPECT_EQ(cross3.damage, 0.2);
}

TEST(SplitEdge, BoundaryEdge) {
  Mesh m = unit_square();
  const int bottom = m.find_edge(0, 1);
  const EditResult r = split_edge(m, bottom, 0.5);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_EQ(r.removed_faces, std::vector<int>{0});
  EXPECT_EQ(r.added_faces.size(), 2u);
  EXPECT_EQ(r.added_edges.size(), 3u);
  EXPECT_TRUE(m.nodes[4].x.isApprox(Vec3(0.5, 0, 1)));
  EXPECT_NE(find_face(m, 0, 4, 2), kNone);
  EXPECT_NE(find_face(m, 4, 1, 2), kNone);
  EXPECT_NE(find_face(m, 0, 2, 3), kNone);  // untouched
  EXPECT_TRUE(m.edges[m.find_edge(0, 4)].is_boundary());
  EXPECT_TRUE(m.edges[m.find_edge(4, 1)].is_boundary());
  EXPECT_TRUE(m.is_boundary_node(4));
  EXPECT_EQ(m.faces[find_face(m, 0, 4, 2)].rest_area, 0.25);
}

TEST(SplitEdge, LabelKeptOnlyWhenBothEndsShareIt) {
  Mesh m = unit_square();
  m.nodes[0].label = 3;
  m.nodes[1].label = 3;
  m.nodes[2].label = 5;
  ASSERT_TRUE(split_edge(m, m.find_edge(0, 1), 0.5).ok);
  EXPECT_EQ(m.nodes[4].label, 3);
  ASSERT_TRUE(split_edge(m, m.find_edge(1, 2), 0.5).ok);
  EXPECT_EQ(m.nodes[5].label, 0);
}

// Square whose two faces have their own rest verts: face 0 = verts (0, 1, 2), face 1 uses vert `v0` at node 0
// and `v2` at node 2 (both distinct from face 0's when `full_seam`, only at node 2 otherwise), raised in z.
Mesh seamed_square(bool full_seam) {
  std::vector<Vec3> x{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  std::vector<Vec3> u{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 0, 2), Vec3(1, 1, 2), Vec3(0, 1, 2)};
  std::vector<int> vert_node{0, 1, 2, 0, 2, 3};
  if (!full_seam) u[4] = Vec3(1, 1, 0.5), u[5] = Vec3(0, 1, 0.25);
  std::array<int, 3> second = full_seam ? std::array<int, 3>{3, 4, 5} : std::array<int, 3>{0, 4, 5};
  Mesh m = Mesh::from_triangles(x, u, vert_node, {{0, 1, 2}, second});
  if (!full_seam) m.remove_vert(3);  // unused
  return m;
}

TEST(SplitEdge, SeamGetsOneVertPerSide) {
  Mesh m = seamed_square(true);
  ASSERT_EQ(check_mesh(m), "");
  const int seam = m.find_edge(0, 2);
  EXPECT_EQ(m.rest_dihedral(seam), 0.0);
  const double t = m.edges[seam].n[0] == 0 ? 0.25 : 0.75;  // new node at a quarter from node 0
  const EditResult r = split_edge(m, seam, t);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  ASSERT_EQ(r.added_verts.size(), 2u);
  EXPECT_EQ(m.nodes[4].verts.size(), 2u);
  EXPECT_TRUE(m.nodes[4].x.isApprox(Vec3(0.25, 0.25, 0)));
  std::set<double> zs;
  for (int v : r.added_verts) {
    EXPECT_EQ(m.verts[v].faces.size(), 2u);  // each side's two children
    EXPECT_NEAR(m.verts[v].u.x(), 0.25, 1e-15);
    zs.insert(m.verts[v].u.z());
  }
  EXPECT_EQ(zs, (std::set<double>{0.0, 2.0}));
  // Both halves of the seam stay seams; every new face lies in its side's rest plane.
  EXPECT_EQ(m.rest_dihedral(m.find_edge(0, 4)), 0.0);
  for (int f : r.added_faces) {
    const double z = m.verts[m.faces[f].v[0]].u.z();
    for (int c = 0; c < 3; ++c) EXPECT_EQ(m.verts[m.faces[f].v[c]].u.z(), z);
  }
}

TEST(SplitEdge, PartlySharedSeamVertsStillGiveTwoVerts) {
  Mesh m = seamed_square(false);
  ASSERT_EQ(check_mesh(m), "");
  const int e = m.find_edge(0, 2);
  const EditResult r = split_edge(m, e, 0.5);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  ASSERT_EQ(r.added_verts.size(), 2u);
  std::set<double> zs;
  for (int v : r.added_verts) zs.insert(m.verts[v].u.z());
  EXPECT_EQ(zs, (std::set<double>{0.0, 0.25}));
}

TEST(SplitEdge, SharedVertsGiveOneVertAndSizingIsInterpolated) {
  Mesh m = unit_square();
  m.verts[0].sizing = Mat3::Identity() * 4;
  m.verts[2].sizing = Mat3::Identity() * 8;
  const int e = m.find_edge(0, 2);
  const double t = m.edges[e].n[0] == 0 ? 0.25 : 0.75;
  const EditResult r = split_edge(m, e, t);
  ASSERT_TRUE(r.ok);
  ASSERT_EQ(r.added_verts.size(), 1u);
  EXPECT_TRUE(m.verts[r.added_verts[0]].sizing.isApprox(Mat3::Identity() * 5));
}

TEST(SplitEdge, CurvedRestShapeKeepsAnglesOfOuterEdges) {
  Mesh m = test::make_cylinder_patch(4, 2, 1.0, 1.5, 1.0);
  std::mt19937 rng(7);
  test::fill_random_state(m, rng);
  std::vector<double> theta_before(m.edges.size());
  for (size_t e = 0; e < m.edges.size(); ++e) theta_before[e] = m.edges[e].rest_theta;
  // A vertical edge in the middle: an interior hinge with a real rest angle.
  const int e = m.find_edge(grid_node(4, 2, 0), grid_node(4, 2, 1));
  ASSERT_NE(e, kNone);
  const double whole = m.rest_dihedral(e);
  ASSERT_GT(std::abs(whole), 0.1);
  const EditResult r = split_edge(m, e, 0.5);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  for (size_t k = 0; k < theta_before.size(); ++k)
    if (!m.edges[k].dead) {
      EXPECT_EQ(m.edges[k].rest_theta, theta_before[k]);
    }
  for (int ne : r.added_edges) {
    const Edge& ed = m.edges[ne];
    const int other = ed.n[0] == r.added_nodes[0] ? ed.n[1] : ed.n[0];
    if (other == grid_node(4, 2, 0) || other == grid_node(4, 2, 1)) {
      EXPECT_EQ(ed.rest_theta, theta_before[e]);
      // The halves still hinge at the same rest angle as the whole edge did.
      EXPECT_NEAR(m.rest_dihedral(ne), whole, 1e-12);
    } else {
      EXPECT_NEAR(ed.rest_theta, 0.0, 1e-12);  // inside a former (planar) face
    }
  }
}

TEST(SplitEdge, RefusalsLeaveMeshUntouched) {
  Mesh m = unit_square();
  const uint64_t before = fingerprint(m);
  for (double t : {0.0, 1.0, -0.5, 1.5, std::nan(""), kInfinity, 1e-14}) {
    const EditResult r = split_edge(m, m.find_edge(0, 2), t);
    EXPECT_FALSE(r.ok) << t;
    EXPECT_TRUE(r.added_faces.empty());
  }
  EXPECT_FALSE(split_edge(m, 99, 0.5).ok);
  EXPECT_FALSE(split_edge(m, -1, 0.5).ok);
  EXPECT_EQ(fingerprint(m), before);
  m.remove_face(0);
  m.remove_edge(m.find_edge(0, 1));
  const int dead = m.find_edge(1, 2);
  m.remove_edge(dead);
  const uint64_t after_removal = fingerprint(m);
  EXPECT_FALSE(split_edge(m, dead, 0.5).ok);
  EXPECT_EQ(fingerprint(m), after_removal);
}

// ------------------------------------------------------------------------------------------------------------
// flip_edge

// Convex quad 0 (0,0), 1 (3,0), 2 (2,2), 3 (0,1) with diagonal 0-2: face (0,1,2) has area 3, (0,2,3) area 1.
Mesh kite() {
  const std::vector<Vec3> p{Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(2, 2, 0), Vec3(0, 1, 0)};
  Mesh m = Mesh::from_triangles(p, p, {0, 1, 2, 3}, {{0, 1, 2}, {0, 2, 3}});
  m.faces[0].thickness = 1.0;
  m.faces[1].thickness = 2.0;
  m.faces[0].damage = 0.0;
  m.faces[1].damage = 1.0;
  m.faces[0].Fp = Mat3::Identity();
  m.faces[1].Fp = Mat3::Identity() * 3;
  m.faces[0].Sp = Mat3::Zero();
  m.faces[1].Sp = Mat3::Constant(4);
  return m;
}

TEST(FlipEdge, ReplacesDiagonalAndAveragesStateByArea) {
  Mesh m = kite();
  const int diagonal = m.find_edge(0, 2);
  const EditResult r = flip_edge(m, diagonal);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_EQ(m.find_edge(0, 2), kNone);
  const int new_edge = m.find_edge(1, 3);
  ASSERT_NE(new_edge, kNone);
  EXPECT_EQ(r.added_edges, std::vector<int>{new_edge});
  EXPECT_EQ(r.removed_edges, std::vector<int>{diagonal});
  EXPECT_EQ(r.removed_faces, (std::vector<int>{0, 1}));
  const int a = find_face(m, 0, 1, 3), b = find_face(m, 1, 2, 3);
  ASSERT_NE(a, kNone);
  ASSERT_NE(b, kNone);
  EXPECT_EQ(live_count(m.faces), 2);
  EXPECT_DOUBLE_EQ(m.faces[a].rest_area, 1.5);
  EXPECT_DOUBLE_EQ(m.faces[b].rest_area, 2.5);
  for (int f : {a, b}) {
    EXPECT_TRUE(rest_normal(m, f).isApprox(Vec3::UnitZ()));
    EXPECT_DOUBLE_EQ(m.faces[f].thickness, 0.75 * 1 + 0.25 * 2);
    EXPECT_DOUBLE_EQ(m.faces[f].damage, 0.25);
    EXPECT_TRUE(m.faces[f].Fp.isApprox(Mat3::Identity() * 1.5));
    EXPECT_TRUE(m.faces[f].Sp.isApprox(Mat3::Constant(1)));
  }
  EXPECT_EQ(m.edges[new_edge].rest_theta, 0.0);
  EXPECT_DOUBLE_EQ(m.edges[new_edge].damage, 0.25);
  // Flipping back restores the original diagonal.
  ASSERT_TRUE(flip_edge(m, new_edge).ok);
  EXPECT_NE(m.find_edge(0, 2), kNone);
  EXPECT_EQ(check_mesh(m), "");
}

// A doubly curved (saddle) rest shape, so that no quad of the grid is planar.
Mesh saddle_grid(int nx, int ny) {
  Mesh m = make_flat_grid(nx, ny);
  for (Vert& v : m.verts) v.u.z() = 0.8 * (v.u.x() - 0.5) * (v.u.y() - 0.5);
  for (Node& n : m.nodes) n.x = m.verts[n.verts[0]].u;
  m.update_rest_data();
  return m;
}

TEST(FlipEdge, CurvedRestShapeKeepsPlasticOffsets) {
  Mesh m = saddle_grid(4, 3);
  std::mt19937 rng(11);
  test::fill_random_state(m, rng);
  std::vector<double> offset(m.edges.size()), theta(m.edges.size());
  for (size_t e = 0; e < m.edges.size(); ++e) {
    offset[e] = m.edges[e].rest_theta - m.rest_dihedral(static_cast<int>(e));
    theta[e] = m.edges[e].rest_theta;
  }
  // A diagonal in the middle of the patch.
  const int e = m.find_edge(grid_node(4, 1, 1), grid_node(4, 2, 2));
  ASSERT_NE(e, kNone);
  const EditResult r = flip_edge(m, e);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  const int ne = r.added_edges.at(0);
  EXPECT_NEAR(m.edges[ne].rest_theta, m.rest_dihedral(ne), 1e-15);
  EXPECT_GT(std::abs(m.rest_dihedral(ne)), 1e-3);  // the new diagonal hinges across the curvature
  int changed = 0;
  for (size_t k = 0; k < offset.size(); ++k) {
    if (m.edges[k].dead) continue;
    EXPECT_NEAR(m.edges[k].rest_theta - m.rest_dihedral(static_cast<int>(k)), offset[k], 1e-12) << k;
    if (std::abs(m.edges[k].rest_theta - theta[k]) > 1e-9) ++changed;
  }
  EXPECT_EQ(changed, 4);  // the quad's four outer edges (all interior here) have new wings
}

TEST(FlipEdge, Refusals) {
  {  // boundary edge
    Mesh m = kite();
    const uint64_t before = fingerprint(m);
    EXPECT_FALSE(flip_edge(m, m.find_edge(0, 1)).ok);
    EXPECT_EQ(fingerprint(m), before);
  }
  {  // preserved
    Mesh m = kite();
    m.edges[m.find_edge(0, 2)].preserve = true;
    const uint64_t before = fingerprint(m);
    EXPECT_FALSE(flip_edge(m, m.find_edge(0, 2)).ok);
    EXPECT_EQ(fingerprint(m), before);
  }
  {  // materials differ
    Mesh m = kite();
    m.faces[1].material = 1;
    const uint64_t before = fingerprint(m);
    EXPECT_FALSE(flip_edge(m, m.find_edge(0, 2)).ok);
    EXPECT_EQ(fingerprint(m), before);
  }
  {  // seam
    Mesh m = seamed_square(true);
    const uint64_t before = fingerprint(m);
    EXPECT_FALSE(flip_edge(m, m.find_edge(0, 2)).ok);
    EXPECT_EQ(fingerprint(m), before);
  }
  {  // non-convex quad: a flipped face would be inverted
    const std::vector<Vec3> p{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.3, 0.3, 0), Vec3(0, 1, 0)};
    Mesh m = Mesh::from_triangles(p, p, {0, 1, 2, 3}, {{0, 1, 2}, {0, 2, 3}});
    ASSERT_EQ(check_mesh(m), "");
    const uint64_t before = fingerprint(m);
    EXPECT_FALSE(flip_edge(m, m.find_edge(0, 2)).ok);
    EXPECT_EQ(fingerprint(m), before);
  }
  {  // the other diagonal already exists: three faces around node 3
    const std::vector<Vec3> p{Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 2, 0), Vec3(1, 0.7, 0)};
    Mesh m = Mesh::from_triangles(p, p, {0, 1, 2, 3}, {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}});
    ASSERT_EQ(check_mesh(m), "");
    const uint64_t before = fingerprint(m);
    for (int e = 0; e < static_cast<int>(m.edges.size()); ++e) EXPECT_FALSE(flip_edge(m, e).ok) << e;
    EXPECT_EQ(fingerprint(m), before);
  }
}

// ------------------------------------------------------------------------------------------------------------
// collapse_edge

TEST(CollapseEdge, InteriorEdgeOfGrid) {
  Mesh m = make_flat_grid(3, 3);
  std::mt19937 rng(5);
  test::fill_random_state(m, rng);
  const Mesh before = m;
  const int gone = grid_node(3, 1, 1), keep = grid_node(3, 2, 1);
  const int e = m.find_edge(gone, keep);
  const int side = m.edges[e].n[0] == gone ? 0 : 1;
  const EditResult r = collapse_edge(m, e, side);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_EQ(r.removed_nodes, std::vector<int>{gone});
  EXPECT_TRUE(m.nodes[gone].dead);
  EXPECT_EQ(live_count(m.faces), 18 - 2);
  EXPECT_EQ(live_count(m.edges), static_cast<int>(before.edges.size()) - 3);
  EXPECT_NEAR(test::total_rest_area(m), 1.0, 1e-14);
  EXPECT_TRUE(m.nodes[keep].x == before.nodes[keep].x);
  // Every surviving face of the removed node now uses the kept node, with its old state.
  for (size_t f = 0; f < before.faces.size(); ++f) {
    const int c = before.corner_of_node(static_cast<int>(f), gone);
    if (c == kNone || before.corner_of_node(static_cast<int>(f), keep) != kNone) continue;
    const int nf = find_face(m, keep, before.face_node(static_cast<int>(f), (c + 1) % 3),
                             before.face_node(static_cast<int>(f), (c + 2) % 3));
    ASSERT_NE(nf, kNone);
    EXPECT_EQ(m.faces[nf].thickness, before.faces[f].thickness);
    EXPECT_EQ(m.faces[nf].Fp, before.faces[f].Fp);
    EXPECT_EQ(m.faces[nf].Sp, before.faces[f].Sp);
    EXPECT_EQ(m.faces[nf].damage, before.faces[f].damage);
    EXPECT_TRUE(rest_normal(m, nf).isApprox(Vec3::UnitZ()));
  }
  // Edges gone -> x hand their state to keep -> x.
  for (int x : {grid_node(3, 0, 1), grid_node(3, 1, 2)}) {
    const int old_e = before.find_edge(gone, x), new_e = m.find_edge(keep, x);
    ASSERT_NE(new_e, kNone);
    EXPECT_EQ(m.edges[new_e].damage, before.edges[old_e].damage);
    EXPECT_NEAR(m.edges[new_e].rest_theta, before.edges[old_e].rest_theta, 1e-15);  // flat: offsets only
  }
}

TEST(CollapseEdge, BoundaryEdgeAndBoundaryRules) {
  Mesh m = make_flat_grid(3, 3);
  const int corner = grid_node(3, 0, 0), next = grid_node(3, 1, 0), above = grid_node(3, 1, 1);
  // A boundary node may not move along an interior edge.
  uint64_t before = fingerprint(m);
  const int inward = m.find_edge(next, above);
  EXPECT_FALSE(collapse_edge(m, inward, m.edges[inward].n[0] == next ? 0 : 1).ok);
  EXPECT_EQ(fingerprint(m), before);
  // Along the boundary it may.
  const int along = m.find_edge(next, corner);
  const EditResult r = collapse_edge(m, along, m.edges[along].n[0] == next ? 0 : 1);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_EQ(live_count(m.faces), 17);
  EXPECT_NEAR(test::total_rest_area(m), 1.0, 1e-14);  // collinear boundary
  EXPECT_TRUE(m.is_boundary_node(corner));
  const int merged = m.find_edge(corner, grid_node(3, 2, 0));
  ASSERT_NE(merged, kNone);
  EXPECT_TRUE(m.edges[merged].is_boundary());
}

TEST(CollapseEdge, PreservedElementsAreNotRemoved) {
  Mesh m = make_flat_grid(3, 3);
  const int gone = grid_node(3, 1, 1), keep = grid_node(3, 2, 1);
  const int e = m.find_edge(gone, keep);
  const int side = m.edges[e].n[0] == gone ? 0 : 1;
  m.nodes[gone].preserve = true;
  uint64_t before = fingerprint(m);
  EXPECT_FALSE(collapse_edge(m, e, side).ok);
  EXPECT_EQ(fingerprint(m), before);
  m.nodes[gone].preserve = false;
  m.edges[e].preserve = true;
  before = fingerprint(m);
  EXPECT_FALSE(collapse_edge(m, e, side).ok);
  EXPECT_EQ(fingerprint(m), before);
  m.edges[e].preserve = false;
  m.edges[m.find_edge(gone, grid_node(3, 1, 2))].preserve = true;  // another edge at the removed node
  before = fingerprint(m);
  EXPECT_FALSE(collapse_edge(m, e, side).ok);
  EXPECT_EQ(fingerprint(m), before);
  // The other way round (removing `keep`) touches no preserved edge.
  EXPECT_TRUE(collapse_edge(m, e, 1 - side).ok);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_TRUE(m.edges[m.find_edge(gone, grid_node(3, 1, 2))].preserve);
}

// Triangle u, w, x with a valence-3 node p inside, surrounded by a ring so that u and p are interior.
// Nodes: 0 u, 1 w, 2 x, 3 p, 4.. ring.
Mesh inner_triangle() {
  const std::vector<Vec3> p{Vec3(0, 0, 0),  Vec3(2, 0, 0),    Vec3(1, 2, 0),  Vec3(1, 0.7, 0),
                            Vec3(1, -2, 0), Vec3(-1.5, 2, 0), Vec3(-2, -0.5, 0)};
  const std::vector<std::array<int, 3>> tris{{0, 1, 3}, {1, 2, 3}, {2, 0, 3},  // inner
                                             {1, 0, 4}, {0, 2, 5}, {0, 5, 6}, {0, 6, 4}};
  return Mesh::from_triangles(p, p, {0, 1, 2, 3, 4, 5, 6}, tris);
}

TEST(CollapseEdge, LinkConditionRefusesPinching) {
  Mesh m = inner_triangle();
  ASSERT_EQ(check_mesh(m), "");
  ASSERT_FALSE(m.is_boundary_node(0));
  const uint64_t before = fingerprint(m);
  // u and w share neighbour x, which is not opposite to u-w: collapsing would pinch p away.
  const int uw = m.find_edge(0, 1);
  EXPECT_FALSE(collapse_edge(m, uw, m.edges[uw].n[0] == 0 ? 0 : 1).ok);
  EXPECT_EQ(fingerprint(m), before);
  // Removing p into u is fine: p's three faces become the single face u, w, x.
  const int up = m.find_edge(0, 3);
  const EditResult r = collapse_edge(m, up, m.edges[up].n[0] == 3 ? 0 : 1);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_NE(find_face(m, 0, 1, 2), kNone);
  EXPECT_EQ(live_count(m.faces), 5);
}

TEST(CollapseEdge, RefusesDuplicateFacesAndEmptyNodes) {
  // Closed tetrahedron: any collapse would leave two faces over the same nodes.
  const std::vector<Vec3> p{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  Mesh tet = Mesh::from_triangles(p, p, {0, 1, 2, 3}, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}});
  ASSERT_EQ(check_mesh(tet), "");
  const uint64_t before = fingerprint(tet);
  for (int e = 0; e < 6; ++e)
    for (int s = 0; s < 2; ++s) EXPECT_FALSE(collapse_edge(tet, e, s).ok);
  EXPECT_EQ(fingerprint(tet), before);
  // A lone triangle cannot lose a node.
  Mesh tri = Mesh::from_triangles({p[0], p[1], p[2]}, {p[0], p[1], p[2]}, {0, 1, 2}, {{0, 1, 2}});
  for (int e = 0; e < 3; ++e)
    for (int s = 0; s < 2; ++s) EXPECT_FALSE(collapse_edge(tri, e, s).ok);
  // An ear (a face with two boundary edges) can lose its tip only along a boundary edge, which would empty the
  // tip... the square's corner face: collapsing 1 into 0 leaves the single face 0-2-3.
  Mesh sq = unit_square();
  const int e01 = sq.find_edge(0, 1);
  const EditResult r = collapse_edge(sq, e01, sq.edges[e01].n[0] == 1 ? 0 : 1);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(sq), "");
  EXPECT_EQ(live_count(sq.faces), 1);
}

TEST(CollapseEdge, RefusesRestInversion) {
  // Interior node p = 0 with ring A..E; the ring is star-shaped from p but not from A.
  const std::vector<Vec3> p{Vec3(0, 0, 0),   Vec3(1, 0, 0),   Vec3(1, 1, 0),
                            Vec3(-1, 1, 0),  Vec3(-1, -1, 0), Vec3(0.2, -0.1, 0)};
  Mesh m = Mesh::from_triangles(p, p, {0, 1, 2, 3, 4, 5}, {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 1}});
  ASSERT_EQ(check_mesh(m), "");
  const uint64_t before = fingerprint(m);
  const int pa = m.find_edge(0, 1);
  EXPECT_FALSE(collapse_edge(m, pa, m.edges[pa].n[0] == 0 ? 0 : 1).ok);
  EXPECT_EQ(fingerprint(m), before);
  const int pc = m.find_edge(0, 3);
  ASSERT_TRUE(collapse_edge(m, pc, m.edges[pc].n[0] == 0 ? 0 : 1).ok);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_EQ(live_count(m.faces), 3);
}

TEST(CollapseEdge, SeamNodesMapTheirVertsSideBySide) {
  const int nx = 6, ny = 3;
  Mesh m = test::make_seamed_tube(nx, ny, 1.0, 1.0);
  ASSERT_EQ(check_mesh(m), "");
  auto node = [&](int i, int j) { return j * nx + (i % nx); };
  // Along the seam: both ends are seam nodes, the two sides map vert to vert.
  const int gone = node(0, 1), keep = node(0, 2);
  const int e = m.find_edge(gone, keep);
  ASSERT_EQ(m.nodes[keep].verts.size(), 2u);
  const EditResult r = collapse_edge(m, e, m.edges[e].n[0] == gone ? 0 : 1);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_EQ(r.removed_verts.size(), 2u);
  EXPECT_EQ(m.nodes[keep].verts.size(), 2u);
  // Faces on each side use the kept node's vert of that side: rest x coordinate 0 or the circumference, and no
  // face spans the seam in rest space.
  for (int f : r.added_faces) {
    double lo = 1e9, hi = -1e9;
    for (int c = 0; c < 3; ++c) {
      lo = std::min(lo, m.verts[m.faces[f].v[c]].u.x());
      hi = std::max(hi, m.verts[m.faces[f].v[c]].u.x());
    }
    EXPECT_LT(hi - lo, 2 * test::kPi / nx + 1e-12);
  }
  // Off the seam, a seam node cannot be removed (its other rest vert has nowhere to go)...
  const int side_node = node(1, 2);
  const int off = m.find_edge(keep, side_node);
  const uint64_t before = fingerprint(m);
  EXPECT_FALSE(collapse_edge(m, off, m.edges[off].n[0] == keep ? 0 : 1).ok);
  EXPECT_EQ(fingerprint(m), before);
  // ...but a plain node can be merged into a seam node.
  ASSERT_TRUE(collapse_edge(m, off, m.edges[off].n[0] == side_node ? 0 : 1).ok);
  EXPECT_EQ(check_mesh(m), "");
}

// ------------------------------------------------------------------------------------------------------------
// split_node

// Faces of node n whose centroid (world) is above / below height y.
int faces_with_centroid(const Mesh& m, int n, bool above, double y) {
  int count = 0;
  for (int v : m.nodes[n].verts)
    for (int f : m.verts[v].faces) {
      double cy = 0;
      for (int c = 0; c < 3; ++c) cy += m.nodes[m.face_node(f, c)].x.y() / 3;
      count += (cy > y) == above;
    }
  return count;
}

TEST(SplitNode, InteriorNodeWithTwoCuts) {
  Mesh m = make_flat_grid(4, 4);
  std::mt19937 rng(2);
  test::fill_random_state(m, rng);
  const int n = grid_node(4, 2, 2), right = grid_node(4, 3, 2), left = grid_node(4, 1, 2);
  const int c0 = m.find_edge(n, right), c1 = m.find_edge(n, left);
  const Edge cut0 = m.edges[c0];
  const Mesh before = m;
  const EditResult r = split_node(m, n, {c0, c1});
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  ASSERT_EQ(r.added_nodes.size(), 1u);
  const int copy = r.added_nodes[0];
  // CCW from +x to -x is the upper half: it moves to the copy.
  EXPECT_EQ(faces_with_centroid(m, copy, true, 0.5), faces_with_centroid(before, n, true, 0.5));
  EXPECT_EQ(faces_with_centroid(m, copy, false, 0.5), 0);
  EXPECT_EQ(faces_with_centroid(m, n, true, 0.5), 0);
  EXPECT_EQ(faces_with_centroid(m, n, false, 0.5), faces_with_centroid(before, n, false, 0.5));
  // The copy is a twin.
  EXPECT_EQ(m.nodes[copy].x, before.nodes[n].x);
  EXPECT_EQ(m.nodes[copy].x0, before.nodes[n].x0);
  EXPECT_EQ(m.nodes[copy].v, before.nodes[n].v);
  EXPECT_EQ(m.nodes[copy].a, before.nodes[n].a);
  EXPECT_TRUE(m.nodes[copy].preserve);
  EXPECT_TRUE(m.nodes[n].preserve);
  EXPECT_EQ(m.nodes[copy].verts.size(), 1u);
  EXPECT_EQ(m.verts[m.nodes[copy].verts[0]].u, before.verts[before.nodes[n].verts[0]].u);
  // Each cut edge became two boundary edges with the same state; far ends (interior) stay single.
  for (int far : {right, left}) {
    const int e0 = m.find_edge(n, far), e1 = m.find_edge(copy, far);
    ASSERT_NE(e0, kNone);
    ASSERT_NE(e1, kNone);
    EXPECT_TRUE(m.edges[e0].is_boundary());
    EXPECT_TRUE(m.edges[e1].is_boundary());
    EXPECT_EQ(m.edges[e1].rest_theta, m.edges[e0].rest_theta);
    EXPECT_EQ(m.edges[e1].damage, m.edges[e0].damage);
  }
  EXPECT_EQ(m.edges[m.find_edge(copy, right)].damage, cut0.damage);
  EXPECT_EQ(live_count(m.nodes), 26);
  EXPECT_EQ(count_components(m), 1);
  EXPECT_NEAR(test::total_rest_area(m), 1.0, 1e-14);
  // Face state is carried over unchanged.
  for (int f : r.added_faces) {
    int c = m.corner_of_node(f, copy);
    ASSERT_NE(c, kNone);
    const int old = find_face(before, n, m.face_node(f, (c + 1) % 3), m.face_node(f, (c + 2) % 3));
    EXPECT_EQ(m.faces[f].Fp, before.faces[old].Fp);
    EXPECT_EQ(m.faces[f].thickness, before.faces[old].thickness);
  }
}

TEST(SplitNode, CutOrderChoosesTheSector) {
  Mesh m = make_flat_grid(4, 4);
  const int n = grid_node(4, 2, 2);
  const int c0 = m.find_edge(n, grid_node(4, 1, 2)), c1 = m.find_edge(n, grid_node(4, 3, 2));
  const EditResult r = split_node(m, n, {c0, c1});  // from -x CCW to +x: the lower half moves
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(faces_with_centroid(m, r.added_nodes[0], true, 0.5), 0);
  EXPECT_GT(faces_with_centroid(m, r.added_nodes[0], false, 0.5), 0);
}

TEST(SplitNode, BoundaryNodeWithOneCut) {
  Mesh m = make_flat_grid(4, 4);
  const int n = grid_node(4, 2, 0), up = grid_node(4, 2, 1);
  const Mesh before = m;
  const EditResult r = split_node(m, n, {m.find_edge(n, up)});
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  ASSERT_EQ(r.added_nodes.size(), 1u);
  const int copy = r.added_nodes[0];
  // CCW from the cut (+y) to the boundary (-x): the faces left of x = 0.5 move.
  auto faces_left = [](const Mesh& mesh, int node, bool left) {
    int count = 0;
    for (int v : mesh.nodes[node].verts)
      for (int f : mesh.verts[v].faces) {
        double cx = 0;
        for (int c = 0; c < 3; ++c) cx += mesh.nodes[mesh.face_node(f, c)].x.x() / 3;
        count += (cx < 0.5) == left;
      }
    return count;
  };
  EXPECT_EQ(faces_left(m, copy, true), faces_left(before, n, true));
  EXPECT_EQ(faces_left(m, copy, false), 0);
  EXPECT_EQ(faces_left(m, n, true), 0);
  EXPECT_TRUE(m.edges[m.find_edge(n, up)].is_boundary());
  EXPECT_TRUE(m.edges[m.find_edge(copy, up)].is_boundary());
  EXPECT_EQ(count_components(m), 1);
}

TEST(SplitNode, BoundaryNodeWithTwoCutsMakesTwoCopies) {
  Mesh m = make_flat_grid(4, 4);
  const int n = grid_node(4, 2, 0);
  const int c0 = m.find_edge(n, grid_node(4, 3, 1)), c1 = m.find_edge(n, grid_node(4, 2, 1));
  ASSERT_NE(c0, kNone);
  ASSERT_NE(c1, kNone);
  const EditResult r = split_node(m, n, {c0, c1});
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  ASSERT_EQ(r.added_nodes.size(), 2u);
  // Three single fans: the face between the two cuts is alone on one copy.
  const std::vector<int> fans{n, r.added_nodes[0], r.added_nodes[1]};
  std::vector<size_t> sizes;
  for (int node : fans) sizes.push_back(m.verts[m.nodes[node].verts[0]].faces.size());
  EXPECT_EQ(sizes, (std::vector<size_t>{1, 1, 2}));
  for (int node : fans) EXPECT_TRUE(m.nodes[node].preserve);
}

// Components of the live faces, each with its total rest area.
std::vector<double> component_areas(const Mesh& m) {
  const std::vector<int> label = test::face_components(m);
  std::vector<double> area;
  for (size_t f = 0; f < m.faces.size(); ++f) {
    if (label[f] == kNone) continue;
    if (static_cast<int>(area.size()) <= label[f]) area.resize(label[f] + 1, 0);
    area[label[f]] += m.faces[f].rest_area;
  }
  return area;
}

TEST(SplitNode, CrackAcrossTheSheetCutsItInTwo) {
  Mesh m = make_flat_grid(4, 4);
  // Boundary (0, 2) to boundary (4, 2), one node at a time, always along +x.
  int tip = grid_node(4, 0, 2);
  for (int i = 0; i < 4; ++i) {
    const int next = grid_node(4, i + 1, 2);
    const EditResult r = split_node(m, tip, {m.find_edge(tip, next)});
    ASSERT_TRUE(r.ok) << i;
    EXPECT_EQ(check_mesh(m), "") << i;
    EXPECT_EQ(r.added_nodes.size(), i < 3 ? 1u : 2u);  // the last step also splits the far boundary node
    tip = next;
  }
  EXPECT_EQ(live_count(m.nodes), 25 + 5);
  EXPECT_EQ(count_components(m), 2);
  const std::vector<double> areas = component_areas(m);
  ASSERT_EQ(areas.size(), 2u);
  EXPECT_NEAR(areas[0], 0.5, 1e-14);
  EXPECT_NEAR(areas[1], 0.5, 1e-14);
  // Every node now lies on one side of the crack: none has faces both above and below it.
  for (size_t n = 0; n < m.nodes.size(); ++n) {
    if (m.nodes[n].dead || std::abs(m.nodes[n].x.y() - 0.5) > 1e-12) continue;
    const bool up = faces_with_centroid(m, static_cast<int>(n), true, 0.5) > 0;
    const bool down = faces_with_centroid(m, static_cast<int>(n), false, 0.5) > 0;
    EXPECT_NE(up, down) << n;
  }
}

TEST(SplitNode, TwoCutsReachingBothBoundariesSeparateAtOnce) {
  Mesh m = make_flat_grid(2, 2);
  const int n = grid_node(2, 1, 1);
  const EditResult r =
      split_node(m, n, {m.find_edge(n, grid_node(2, 2, 1)), m.find_edge(n, grid_node(2, 0, 1))});
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(check_mesh(m), "");
  EXPECT_EQ(r.added_nodes.size(), 3u);  // the centre, then both far ends
  EXPECT_EQ(count_components(m), 2);
  for (int added : r.added_nodes) EXPECT_TRUE(m.nodes[added].preserve);
}

TEST(SplitNode, UnzippingASeamedTubeLeavesOneVertPerNode) {
  const int nx = 5, ny = 3;
  Mesh m = test::make_seamed_tube(nx, ny, 1.0, 1.0);
  int tip = 0;  // node (0, 0), on the bottom rim and on the seam
  for (int j = 0; j < ny; ++j) {
    const int next = (j + 1) * nx;
    const EditResult r = split_node(m, tip, {m.find_edge(tip, next)});
    ASSERT_TRUE(r.ok) << j;
    ASSERT_EQ(check_mesh(m), "") << j;
    tip = next;
  }
  EXPECT_EQ(count_components(m), 1);
  for (const Node& node : m.nodes)
    if (!node.dead) {
      EXPECT_EQ(node.verts.size(), 1u);
    }
  EXPECT_EQ(live_count(m.verts), (nx + 1) * (ny + 1));  // the flat rectangle's verts, nothing orphaned
}

TEST(SplitNode, Refusals) {
  Mesh m = make_flat_grid(3, 3);
  const int inner = grid_node(3, 1, 1), rim = grid_node(3, 1, 0);
  const int e_in = m.find_edge(inner, grid_node(3, 2, 1));
  const int e_in2 = m.find_edge(inner, grid_node(3, 0, 1));
  const int e_far = m.find_edge(grid_node(3, 2, 2), grid_node(3, 2, 1));
  const int e_boundary = m.find_edge(rim, grid_node(3, 0, 0));
  const uint64_t before = fingerprint(m);
  EXPECT_FALSE(split_node(m, inner, {e_in}).ok);                 // interior node, one cut
  EXPECT_FALSE(split_node(m, inner, {e_in, e_far}).ok);          // edge not incident
  EXPECT_FALSE(split_node(m, inner, {e_in, e_in}).ok);           // repeated
  EXPECT_FALSE(split_node(m, inner, {}).ok);                     // nothing to cut
  EXPECT_FALSE(split_node(m, rim, {e_boundary}).ok);             // already on the boundary
  EXPECT_FALSE(split_node(m, inner, {e_in, e_in2, e_far}).ok);   // too many
  EXPECT_FALSE(split_node(m, 99, {e_in}).ok);
  EXPECT_FALSE(split_node(m, inner, {e_in, 999}).ok);
  EXPECT_EQ(fingerprint(m), before);
}

TEST(NodeFan, OrdersFacesCounterClockwise) {
  Mesh m = make_flat_grid(2, 2);
  NodeFan fan;
  ASSERT_TRUE(node_fan(m, grid_node(2, 1, 1), fan));
  EXPECT_TRUE(fan.closed);
  ASSERT_EQ(fan.corners.size(), 8u);
  for (size_t k = 0; k < fan.corners.size(); ++k) {
    EXPECT_EQ(fan.corners[k].edge_in, fan.corners[(k + 1) % fan.corners.size()].edge_out);
  }
  ASSERT_TRUE(node_fan(m, grid_node(2, 1, 0), fan));
  EXPECT_FALSE(fan.closed);
  EXPECT_TRUE(m.edges[fan.corners.front().edge_out].is_boundary());
  EXPECT_TRUE(m.edges[fan.corners.back().edge_in].is_boundary());
  // The first face of a bottom-rim fan starts along +x.
  const Edge& first = m.edges[fan.corners.front().edge_out];
  EXPECT_TRUE(first.n[0] == grid_node(2, 2, 0) || first.n[1] == grid_node(2, 2, 0));
}

}  // namespace
}  // namespace arcsim
