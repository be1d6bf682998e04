// mesh/pieces.hpp: pieces are faces joined through shared nodes, largest first, with their areas.
#include <gtest/gtest.h>

#include "mesh/pieces.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

TEST(Pieces, OneSheetIsOnePieceWithItsArea) {
  const Mesh m = testing::make_grid(4, 3, 2.0, 1.5);
  const std::vector<Piece> p = mesh_pieces(m);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].faces, 24);
  EXPECT_NEAR(p[0].rest_area, 3.0, 1e-12);
  EXPECT_NEAR(p[0].world_area, 3.0, 1e-12);
}

TEST(Pieces, SeparateSheetsLargestFirstAndDeadFacesLeftOut) {
  const Mesh a = testing::make_grid(2, 1, 1, 0.5), b = testing::make_grid(3, 3, 1, 1);
  // Both grids in one mesh, the second's nodes renumbered after the first's.
  std::vector<Vec3> x;
  std::vector<int> vert_node;
  std::vector<std::array<int, 3>> tris;
  for (const Mesh* m : {&a, &b}) {
    const int base = static_cast<int>(x.size());
    for (const Node& n : m->nodes) {
      x.push_back(n.x + Vec3(m == &a ? 0 : 5, 0, 0));
      vert_node.push_back(static_cast<int>(vert_node.size()));
    }
    for (int f = 0; f < static_cast<int>(m->faces.size()); ++f)
      tris.push_back({base + m->face_node(f, 0), base + m->face_node(f, 1), base + m->face_node(f, 2)});
  }
  Mesh both = Mesh::from_triangles(x, x, vert_node, tris);
  std::vector<Piece> p = mesh_pieces(both);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0].faces, 18);
  EXPECT_EQ(p[1].faces, 4);
  EXPECT_NEAR(p[1].rest_area, 0.5, 1e-12);
  const std::vector<int> of_face = face_pieces(both);
  EXPECT_EQ(of_face[0], 1);
  EXPECT_EQ(of_face[4], 0);
  // Killing the small grid's faces leaves one piece.
  for (int f = 0; f < 4; ++f) both.faces[f].dead = true;
  p = mesh_pieces(both);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].faces, 18);
  EXPECT_EQ(face_pieces(both)[0], -1);
}

}  // namespace
}  // namespace arcsim
