#include "render/render_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "math/errors.hpp"
#include "mesh/mesh.hpp"

namespace arcsim {
namespace {

using Edge2 = std::array<int, 2>;

// Unit square 0-1-2-3 split along 0-2.
const std::vector<std::array<int, 3>> kSquare = {{0, 1, 2}, {0, 2, 3}};

TEST(RenderMesh, BoundaryEdgesOfASquareRunAlongItsBorder) {
  const std::vector<Edge2> edges = boundary_edges(kSquare);
  // Shared diagonal 0-2 excluded; the others in the direction they run in their triangle, input order.
  EXPECT_EQ(edges, (std::vector<Edge2>{{0, 1}, {1, 2}, {2, 3}, {3, 0}}));
}

TEST(RenderMesh, BoundaryEdgesIncludeCrackLips) {
  // Two triangles that touch along 1-2 in space but use separate nodes (2, 3 duplicated as 4, 5): a crack.
  const std::vector<std::array<int, 3>> cracked = {{0, 1, 2}, {5, 4, 3}};
  const std::vector<Edge2> edges = boundary_edges(cracked);
  EXPECT_EQ(edges.size(), 6u);
  EXPECT_NE(std::find(edges.begin(), edges.end(), Edge2{1, 2}), edges.end());
  EXPECT_NE(std::find(edges.begin(), edges.end(), Edge2{4, 3}), edges.end());
  // Degenerate triangles do not create edges.
  EXPECT_TRUE(boundary_edges({{1, 1, 2}}).empty());
}

TEST(RenderMesh, UniqueEdgesAreSortedAndDistinct) {
  EXPECT_EQ(unique_edges(kSquare), (std::vector<Edge2>{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {2, 3}}));
}

TEST(RenderMesh, FromSimulationMeshUsesNodesAndSkipsDeadFaces) {
  // Two triangles with a rest-space seam: node 0 has two rest vertices (0 and 4).
  const std::vector<Vec3> node_x = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  const std::vector<Vec3> vert_u = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0), Vec3(0, 0, 0.1)};
  const std::vector<int> vert_node = {0, 1, 2, 3, 0};
  Mesh mesh = Mesh::from_triangles(node_x, vert_u, vert_node, {{0, 1, 2}, {4, 2, 3}});
  RenderMesh r = render_mesh_from(mesh);
  ASSERT_EQ(r.positions.size(), 4u);
  EXPECT_TRUE(r.positions[2].isApprox(Vec3(1, 1, 0)));
  EXPECT_EQ(r.triangles, (std::vector<std::array<int, 3>>{{0, 1, 2}, {0, 2, 3}}));
  EXPECT_EQ(r.highlight_edges.size(), 4u);  // the seam is not a boundary in world space

  mesh.remove_face(0);
  r = render_mesh_from(mesh, false);
  EXPECT_EQ(r.triangles.size(), 1u);
  EXPECT_TRUE(r.highlight_edges.empty());
}

TEST(RenderMesh, BoundsSkipNonFinitePositions) {
  RenderMesh a, b;
  a.positions = {Vec3(0, 0, 0), Vec3(1, 2, 3), Vec3(std::nan(""), 0, 0)};
  b.positions = {Vec3(-1, 0, 5)};
  const Eigen::AlignedBox3d box = bounds_of(std::vector<RenderMesh>{a, b, RenderMesh()});
  EXPECT_TRUE(box.min().isApprox(Vec3(-1, 0, 0)));
  EXPECT_TRUE(box.max().isApprox(Vec3(1, 2, 5)));
  EXPECT_TRUE(bounds_of(RenderMesh()).isEmpty());
}

TEST(RenderMesh, CheckRejectsBadIndicesAndPositions) {
  RenderMesh m = make_render_mesh({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {{0, 1, 2}});
  EXPECT_NO_THROW(check_render_mesh(m, "cloth 0"));
  RenderMesh bad_triangle = m;
  bad_triangle.triangles.push_back({0, 1, 3});
  try {
    check_render_mesh(bad_triangle, "cloth 0");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cloth 0: triangle 1"), std::string::npos) << e.what();
  }
  RenderMesh bad_edge = m;
  bad_edge.highlight_edges.push_back({-1, 0});
  EXPECT_THROW(check_render_mesh(bad_edge, "cloth 0"), InputError);
  RenderMesh bad_position = m;
  bad_position.positions[1].y() = kInfinity;
  EXPECT_THROW(check_render_mesh(bad_position, "obstacle 2"), InputError);
}

// A 10 x 10 grid of points in the unit square at z = 0, and one point 80 m below (a shard falling away): the bulk
// box without the farthest 1% along each axis is the square; with fraction 0 it is the whole box.
TEST(RenderMesh, BulkBoundsLeaveOutTheFewPointsThatFallAway) {
  std::vector<Vec3> points;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) points.emplace_back(i / 9.0, j / 9.0, 0);
  points.emplace_back(0.5, 0.5, -80);
  points.emplace_back(kInfinity, 0, 0);  // non-finite points are ignored
  const Eigen::AlignedBox3d bulk = bulk_bounds(points, 0.01);
  EXPECT_TRUE(bulk.min().isApprox(Vec3(0, 0, 0))) << bulk.min().transpose();
  EXPECT_TRUE(bulk.max().isApprox(Vec3(1, 1, 0))) << bulk.max().transpose();
  const Eigen::AlignedBox3d all = bulk_bounds(points, 0);
  EXPECT_DOUBLE_EQ(all.min().z(), -80);
  EXPECT_DOUBLE_EQ(all.max().x(), 1);
  EXPECT_TRUE(bulk_bounds({}, 0.01).isEmpty());
  EXPECT_TRUE(bulk_bounds({Vec3(kInfinity, 0, 0)}, 0.01).isEmpty());
}

}  // namespace
}  // namespace arcsim
