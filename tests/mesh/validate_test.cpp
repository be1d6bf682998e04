// validate_triangles (input check) and check_mesh (consistency of a built mesh): every kind of problem is
// built on purpose and must be reported, naming the element.
#include <gtest/gtest.h>

#include <functional>

#include "math/errors.hpp"
#include "mesh/validate.hpp"
#include "mesh_fixtures.hpp"

namespace arcsim {
namespace {

using test::grid_node;
using test::make_flat_grid;

// Two triangles making the unit square, nodes 0..3 counter-clockwise from the origin, with one rest vert per
// node at the node's position. Lines 10 and 11 of a pretend file.
TriangleInput unit_square() {
  TriangleInput in;
  in.node_count = 4;
  in.vert_u = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  in.vert_node = {0, 1, 2, 3};
  in.tris = {{0, 1, 2}, {0, 2, 3}};
  in.tri_source_line = {10, 11};
  return in;
}

std::string error_of(const TriangleInput& in) {
  try {
    validate_triangles(in, "sheet.obj");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ValidateTriangles, AcceptsValidInput) {
  EXPECT_EQ(error_of(unit_square()), "");
  // A seam: node 2 with two rest verts, one per face.
  TriangleInput seam = unit_square();
  seam.vert_u.push_back(Vec3(1, 1, 0.5));
  seam.vert_node.push_back(2);
  seam.tris[1] = {0, 4, 3};
  EXPECT_EQ(error_of(seam), "");
}

TEST(ValidateTriangles, IndexOutOfRangeNamesFileAndLine) {
  TriangleInput in = unit_square();
  in.tris[1][2] = 7;
  EXPECT_EQ(error_of(in), "sheet.obj:11: face 2: vertex index 8 out of range (4 rest vertices)");
  in.tris[1][2] = -1;
  EXPECT_NE(error_of(in).find("sheet.obj:11: face 2: vertex index 0 out of range"), std::string::npos);
}

TEST(ValidateTriangles, VertexNodeOutOfRangeAndNonFiniteRest) {
  TriangleInput in = unit_square();
  in.vert_node[3] = 4;
  EXPECT_EQ(error_of(in), "sheet.obj: rest vertex 4 refers to node 5, out of range (4 nodes)");
  in = unit_square();
  in.vert_u[1].y() = std::nan("");
  EXPECT_EQ(error_of(in), "sheet.obj: rest vertex 2 has a non-finite coordinate");
  in = unit_square();
  in.vert_node.pop_back();
  EXPECT_NE(error_of(in).find("4 rest vertices but 3"), std::string::npos);
}

TEST(ValidateTriangles, DegenerateFace) {
  TriangleInput in = unit_square();
  // Different rest verts of the same node still make a degenerate face.
  in.vert_u.push_back(Vec3(2, 2, 0));
  in.vert_node.push_back(0);
  in.tris.push_back({0, 1, 4});
  in.tri_source_line.push_back(12);
  EXPECT_EQ(error_of(in), "sheet.obj:12: face 3: degenerate, node 1 repeated");
}

TEST(ValidateTriangles, ZeroRestArea) {
  TriangleInput in = unit_square();
  in.vert_u[1] = Vec3(1, 1, 0);
  in.vert_u[2] = Vec3(0.5, 0.5, 0);  // face 1 = (0, 1, 2) is collinear, face 2 is fine
  EXPECT_EQ(error_of(in), "sheet.obj:10: face 1: zero area in rest space");
  // Without source lines the message still names the face.
  in.tri_source_line.clear();
  EXPECT_EQ(error_of(in), "sheet.obj: face 1: zero area in rest space");
}

TEST(ValidateTriangles, DuplicateFaceInEitherOrientation) {
  TriangleInput in = unit_square();
  in.tris.push_back({2, 3, 0});
  in.tri_source_line.push_back(12);
  EXPECT_EQ(error_of(in), "sheet.obj:12: face 3: duplicates face 2");
  in.tris.back() = {3, 2, 0};
  EXPECT_EQ(error_of(in), "sheet.obj:12: face 3: duplicates face 2");
}

TEST(ValidateTriangles, NonManifoldEdge) {
  TriangleInput in = unit_square();
  in.node_count = 5;
  in.vert_u.push_back(Vec3(0.5, 0.5, 1));
  in.vert_node.push_back(4);
  in.tris.push_back({2, 0, 4});  // a third face on edge 0-2
  in.tri_source_line.push_back(12);
  EXPECT_EQ(error_of(in), "sheet.obj:12: face 3: non-manifold edge (node 1, node 3) has more than two faces");
}

TEST(ValidateTriangles, InconsistentOrientation) {
  TriangleInput in = unit_square();
  in.tris[1] = {3, 0, 2};  // consistent (same cycle as 0, 2, 3)
  EXPECT_EQ(error_of(in), "");
  in.tris[1] = {0, 3, 2};  // clockwise: runs 2 -> 0, as face 1 does
  EXPECT_EQ(error_of(in), "sheet.obj:11: face 2: inconsistent orientation: runs edge (node 1, node 3) the same way "
                          "as face 1");
}

TEST(ValidateTriangles, NonManifoldVertexBowTie) {
  // Two triangles touching only at node 0.
  TriangleInput in;
  in.node_count = 5;
  in.vert_u = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)};
  in.vert_node = {0, 1, 2, 3, 4};
  in.tris = {{0, 1, 2}, {0, 3, 4}};
  EXPECT_EQ(error_of(in), "sheet.obj: non-manifold vertex: its faces form more than one fan (node 1)");
  // Closing the gap with faces 0-2-3 makes a single fan again.
  in.tris.push_back({0, 2, 3});
  EXPECT_EQ(error_of(in), "");
}

TEST(ValidateTriangles, UnreferencedNode) {
  TriangleInput in = unit_square();
  in.node_count = 6;
  EXPECT_EQ(error_of(in), "sheet.obj: node referenced by no face (node 5)");
}

TEST(ValidateTriangles, ReportsProblemsInDocumentedOrder) {
  // A duplicate face and an out-of-range index: the range problem comes first whatever the face order.
  TriangleInput in = unit_square();
  in.tris.push_back({0, 1, 2});
  in.tris.push_back({0, 1, 9});
  in.tri_source_line = {10, 11, 12, 13};
  EXPECT_NE(error_of(in).find("sheet.obj:13: face 4: vertex index 10 out of range"), std::string::npos);
}

TEST(ValidateTriangles, LargeMeshIsCheckedThroughout) {
  // 80k triangles: a problem near the end of a large input is found. (Speed, linear in the size, is measured
  // by BM_ValidateTriangles in tools/bench/mesh_bench.cpp, not asserted here.)
  const int n = 200;
  TriangleInput in;
  in.node_count = (n + 1) * (n + 1);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      in.vert_u.emplace_back(i, j, 0);
      in.vert_node.push_back(grid_node(n, i, j));
    }
  in.tris = test::grid_triangles(n, n, [&](int i, int j) { return grid_node(n, i, j); });
  EXPECT_EQ(error_of(in), "");
  in.tris.push_back(in.tris[1000]);
  EXPECT_NE(error_of(in).find("duplicates face 1001"), std::string::npos);
}

// ------------------------------------------------------------------------------------------------------------
// check_mesh

// Applies `corrupt` to a fresh 3x3 grid and returns check_mesh's verdict.
std::string corrupted(const std::function<void(Mesh&)>& corrupt, const MeshCheckOptions& options = {}) {
  Mesh m = make_flat_grid(3, 3);
  EXPECT_EQ(check_mesh(m), "");
  corrupt(m);
  return check_mesh(m, options);
}

// The expectation: a non-empty message that mentions `needle`.
#define EXPECT_CAUGHT(message, needle)                                                       \
  do {                                                                                       \
    const std::string caught_message = (message);                                            \
    EXPECT_NE(caught_message, "");                                                           \
    EXPECT_NE(caught_message.find(needle), std::string::npos) << "message: " << caught_message; \
  } while (0)

TEST(CheckMesh, AcceptsBuiltMeshes) {
  EXPECT_EQ(check_mesh(make_flat_grid(4, 3)), "");
  EXPECT_EQ(check_mesh(test::make_cylinder_patch(6, 3, 1.0, 2.0, 1.0)), "");
  EXPECT_EQ(check_mesh(test::make_seamed_tube(6, 3, 1.0, 1.0)), "");
}

TEST(CheckMesh, CatchesReferencesToDeadElements) {
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.verts[m.faces[4].v[1]].dead = true; }), "dead or invalid vert");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.faces[2].dead = true; }), "dead or invalid face 2");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.edges[m.faces[0].e[0]].dead = true; }), "dead or invalid edge");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.nodes[5].dead = true; }), "dead or invalid node 5");
}

TEST(CheckMesh, CatchesIndicesOutOfRange) {
  // The old vert / edge no longer agrees with face 3.
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.faces[3].v[2] = 1000; }), "face 3");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.faces[3].e[2] = -7; }), "face 3");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.edges[3].f[0] = 99; }), "face 99");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.verts[3].node = 99; }), "node 99");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.nodes[2].edges.push_back(500); }), "edge 500");
}

TEST(CheckMesh, CatchesOneSidedAdjacency) {
  // Each list loses or gains an entry that the other side does not agree with.
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.verts[5].faces.pop_back(); }), "missing from the face list of its vert 5");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.verts[0].faces.push_back(17); }), "lists face 17 which does not use it");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.verts[0].faces.push_back(m.verts[0].faces[0]); }), "lists a face twice");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.nodes[5].verts.clear(); }), "node 5: has no rest vertices");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.nodes[5].edges.pop_back(); }), "missing from the edge list of its node 5");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.nodes[0].edges.push_back(m.nodes[10].edges[0]); }), "does not touch it");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.verts[6].node = 7; }), "belongs to node 7");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.nodes[6].verts.push_back(m.nodes[6].verts[0]); }), "lists a vert twice");
}

TEST(CheckMesh, CatchesWrongFaceEdgeLinks) {
  // Face corner edges swapped: e[i] must join corners i and i+1.
  EXPECT_CAUGHT(corrupted([](Mesh& m) { std::swap(m.faces[4].e[0], m.faces[4].e[1]); }), "does not");
  // An edge's face on the wrong side (orientation convention).
  EXPECT_CAUGHT(corrupted([](Mesh& m) {
                  const int e = m.faces[4].e[2];  // the diagonal of a cell: an interior edge
                  std::swap(m.edges[e].f[0], m.edges[e].f[1]);
                }),
                "required direction");
  // Edge forgets a face.
  EXPECT_CAUGHT(corrupted([](Mesh& m) {
                  const int e = m.faces[4].e[2];
                  for (int& f : m.edges[e].f)
                    if (f == 4) f = kNone;
                }),
                "not on the expected side");
  // Edge stores the same face on both sides.
  EXPECT_CAUGHT(corrupted([](Mesh& m) {
                  const int e = m.faces[4].e[2];
                  m.edges[e].f = {4, 4};
                }),
                "same face on both sides");
}

TEST(CheckMesh, CatchesEdgeProblems) {
  // An edge without faces (left over by an edit).
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.get_or_add_edge(0, 10); }), "has no faces");
  // A self-loop.
  EXPECT_CAUGHT(corrupted([](Mesh& m) {
                  Edge& e = m.edges[0];
                  const int other = e.n[1];
                  auto& list = m.nodes[other].edges;
                  list.erase(std::find(list.begin(), list.end(), 0));
                  e.n[1] = e.n[0];
                }),
                "to itself");
  // Two edges between the same nodes: a third face hangs on the copy, so the edge is non-manifold.
  EXPECT_CAUGHT(corrupted([](Mesh& m) {
                  const int e = m.faces[0].e[1];  // interior edge
                  Edge copy = m.edges[e];
                  const int n0 = copy.n[0], n1 = copy.n[1];
                  m.edges.push_back(copy);
                  const int c = static_cast<int>(m.edges.size()) - 1;
                  m.nodes[n0].edges.push_back(c);
                  m.nodes[n1].edges.push_back(c);
                  // Move face 0 over to the copy.
                  m.edges[e].f[0] = m.edges[e].f[0] == 0 ? kNone : m.edges[e].f[0];
                  m.edges[e].f[1] = m.edges[e].f[1] == 0 ? kNone : m.edges[e].f[1];
                  m.edges[c].f = {copy.f[0] == 0 ? 0 : kNone, copy.f[1] == 0 ? 0 : kNone};
                  m.faces[0].e[1] = c;
                }),
                "duplicates edge");
}

TEST(CheckMesh, CatchesDegenerateAndDuplicateFaces) {
  // A face whose two corners are the same node (through two verts).
  EXPECT_CAUGHT(corrupted([](Mesh& m) {
                  Vert extra;
                  const int v = m.add_vert(extra, m.face_node(6, 0));
                  const int old = m.faces[6].v[1];
                  auto& list = m.verts[old].faces;
                  list.erase(std::find(list.begin(), list.end(), 6));
                  m.faces[6].v[1] = v;
                  m.verts[v].faces.push_back(6);
                }),
                "degenerate");
  // Two faces over the same nodes (a closed two-face pillow hung on the grid would be caught the same way).
  Mesh pillow = Mesh::from_triangles({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)},
                                     {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 0), Vec3(1, 0, 0),
                                      Vec3(0, 1, 1)},
                                     {0, 1, 2, 0, 1, 2}, {{0, 1, 2}, {4, 3, 5}});
  EXPECT_CAUGHT(check_mesh(pillow), "duplicates face 0");
}

TEST(CheckMesh, CatchesBowTie) {
  // Two triangles sharing only node 0 (built without validation).
  Mesh m = Mesh::from_triangles({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)},
                                {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)},
                                {0, 1, 2, 3, 4}, {{0, 1, 2}, {0, 3, 4}});
  EXPECT_CAUGHT(check_mesh(m), "node 0: non-manifold");
}

TEST(CheckMesh, CatchesOrphans) {
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.add_node(Node()); }), "node 16: has no rest vertices");
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.add_vert(Vert(), 3); }), "has no faces");
}

TEST(CheckMesh, CatchesRestGeometryProblems) {
  // Zero rest area.
  EXPECT_CAUGHT(corrupted([](Mesh& m) {
                  const Face& f = m.faces[0];
                  m.verts[f.v[2]].u = 0.5 * (m.verts[f.v[0]].u + m.verts[f.v[1]].u);
                  m.update_rest_data();
                }),
                "zero or near-zero rest area");
  // Positive area is optional.
  MeshCheckOptions lenient;
  lenient.require_positive_rest_area = false;
  EXPECT_EQ(corrupted(
                [](Mesh& m) {
                  const Face& f = m.faces[0];
                  m.verts[f.v[2]].u = 0.5 * (m.verts[f.v[0]].u + m.verts[f.v[1]].u);
                  m.update_rest_data();
                },
                lenient),
            "");
  // Rest data not updated after moving a rest vert.
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.verts[5].u.x() += 0.01; }), "stale rest data");
  MeshCheckOptions no_rest_data;
  no_rest_data.require_current_rest_data = false;
  EXPECT_EQ(corrupted([](Mesh& m) { m.verts[5].u.x() += 0.01; }, no_rest_data), "");
  // Inverted face: rest area and normal disagree with the stored data.
  EXPECT_CAUGHT(corrupted([](Mesh& m) { m.verts[5].u.x() += 10; }), "face");
}

TEST(CheckMesh, CatchesNonFiniteState) {
  const double nan = std::nan("");
  const double inf = kInfinity;
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.nodes[3].x.y() = nan; }), "node 3: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.nodes[3].v.z() = inf; }), "node 3: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.nodes[3].a.x() = nan; }), "node 3: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.nodes[3].x0.x() = nan; }), "node 3: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.nodes[3].mass = nan; }), "node 3: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.verts[3].sizing(1, 1) = nan; }), "vert 3: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.edges[4].rest_theta = nan; }), "edge 4: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.edges[4].damage = inf; }), "edge 4: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.faces[7].thickness = nan; }), "face 7: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.faces[7].Fp(2, 1) = nan; }), "face 7: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.faces[7].Sp(0, 1) = inf; }), "face 7: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.faces[7].damage = nan; }), "face 7: has non-finite");
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.faces[7].Dm_inv(0, 0) = nan; }), "face 7: has non-finite derived");
  // A non-finite rest position shows as a degenerate face first.
  EXPECT_CAUGHT(corrupted([&](Mesh& m) { m.verts[5].u.x() = nan; }), "rest area");
  MeshCheckOptions lenient;
  lenient.require_finite_state = false;
  EXPECT_EQ(corrupted([&](Mesh& m) { m.faces[7].Sp(0, 1) = inf; }, lenient), "");
}

TEST(CheckMesh, IgnoresTombstonesButNotLinksToThem) {
  Mesh m = make_flat_grid(3, 3);
  // Properly removing a corner face and its orphans keeps the mesh valid.
  const int corner_node = grid_node(3, 3, 0);
  const int f = m.verts[m.nodes[corner_node].verts[0]].faces[0];
  m.remove_face(f);
  for (int e : std::vector<int>(m.nodes[corner_node].edges))
    if (m.edges[e].f[0] == kNone && m.edges[e].f[1] == kNone) m.remove_edge(e);
  // The corner node had only face f (alternating diagonals put one triangle at that corner).
  ASSERT_TRUE(m.nodes[corner_node].edges.empty());
  m.remove_vert(m.nodes[corner_node].verts[0]);
  m.remove_node(corner_node);
  EXPECT_EQ(check_mesh(m), "");
  // Garbage in a tombstone does not matter.
  m.faces[f].v = {-5, -5, -5};
  m.nodes[corner_node].x.x() = std::nan("");
  EXPECT_EQ(check_mesh(m), "");
}

TEST(CheckMesh, LargeMeshIsCheckedThroughout) {
  // 45k faces: a bad face near the end of a large mesh is found. (The check runs after each topology phase, so
  // it must stay cheap: BM_CheckMesh in tools/bench/mesh_bench.cpp measures it.)
  Mesh m = make_flat_grid(150, 150);
  EXPECT_EQ(check_mesh(m), "");
  m.faces[44000].Fp(0, 0) = std::nan("");
  EXPECT_CAUGHT(check_mesh(m), "face 44000");
}

TEST(CountComponents, CountsPiecesJoinedByEdges) {
  EXPECT_EQ(count_components(make_flat_grid(3, 2)), 1);
  // Two separate triangles.
  Mesh two = Mesh::from_triangles({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(5, 0, 0), Vec3(6, 0, 0),
                                   Vec3(5, 1, 0)},
                                  {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(5, 0, 0), Vec3(6, 0, 0),
                                   Vec3(5, 1, 0)},
                                  {0, 1, 2, 3, 4, 5}, {{0, 1, 2}, {3, 4, 5}});
  EXPECT_EQ(count_components(two), 2);
}

}  // namespace
}  // namespace arcsim
