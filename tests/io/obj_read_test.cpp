// Reading ARCSim's extended OBJ: tags, face syntaxes, relative indices, polygons, seams, per-face and per-edge
// state, and what build_mesh makes of them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "io/obj.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

// A scratch folder per test, removed afterwards.
class ObjRead : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("arcsim_obj_read_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& text, const std::string& name = "mesh.obj") {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  fs::path dir_;
};

std::set<int> nodes_of(const ObjData& obj, int tri) {
  std::set<int> s;
  for (int k : obj.tris[tri]) s.insert(obj.vert_node[k]);
  return s;
}

// Signed area of a triangle of rest vertices projected on the xy plane.
double signed_area_xy(const ObjData& obj, int tri) {
  const Vec3 a = obj.vert_u[obj.tris[tri][0]], b = obj.vert_u[obj.tris[tri][1]], c = obj.vert_u[obj.tris[tri][2]];
  return 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
}

TEST_F(ObjRead, FlatSheetWithoutRestCoordinatesUsesWorldPositions) {
  const ObjData obj = read_obj(write("v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nf 1 2 3\nf 1 3 4\n"));
  ASSERT_EQ(obj.node_x.size(), 4u);
  EXPECT_FALSE(obj.has_rest_coords);
  ASSERT_EQ(obj.vert_u.size(), 4u);  // one rest vertex per node, shared by both faces
  for (size_t k = 0; k < obj.vert_u.size(); ++k) EXPECT_EQ(obj.vert_u[k], obj.node_x[obj.vert_node[k]]);
  ASSERT_EQ(obj.tris.size(), 2u);
  EXPECT_EQ(obj.tri_line, (std::vector<int>{5, 6}));
  EXPECT_EQ(obj.vert_node[obj.tris[1][2]], 3);
  EXPECT_EQ(obj.node_v[2], Vec3::Zero());
  EXPECT_EQ(obj.tri_material, (std::vector<int>{0, 0}));
  EXPECT_EQ(obj.tri_Fp[0], Mat3::Identity());
  EXPECT_EQ(obj.tri_Sp[1], Mat3::Zero());
  EXPECT_EQ(obj.unknown_tag_lines, 0);
}

TEST_F(ObjRead, TexturePairsAndTriplesGiveRestCoordinates) {
  const ObjData obj = read_obj(write("v 5 5 5\nv 6 5 5\nv 5 6 5\nvt 0 0\nvt 2 0 0.25\nvt 0 2\nf 1/1 2/2 3/3\n"));
  EXPECT_TRUE(obj.has_rest_coords);
  ASSERT_EQ(obj.vert_u.size(), 3u);
  EXPECT_EQ(obj.vert_u[0], Vec3(0, 0, 0));
  EXPECT_EQ(obj.vert_u[1], Vec3(2, 0, 0.25));  // third number is the rest z
  EXPECT_EQ(obj.vert_u[2], Vec3(0, 2, 0));     // two numbers: z = 0
  EXPECT_EQ(obj.vert_node, (std::vector<int>{0, 1, 2}));
}

TEST_F(ObjRead, MsLinesTakePrecedenceOverVtEvenWhenListedAfterTheFaces) {
  // The /k indices count ms lines once any ms line exists; vt (texture for other tools) is then ignored.
  const ObjData obj = read_obj(write("v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                     "vt 9 9\nvt 8 8\nvt 7 7\n"
                                     "f 1/3 2/2 3/1\n"
                                     "ms 0 1 3\nms 1 0 2\nms 0 0 1\n"));
  ASSERT_EQ(obj.vert_u.size(), 3u);
  EXPECT_EQ(obj.vert_u[obj.tris[0][0]], Vec3(0, 0, 1));
  EXPECT_EQ(obj.vert_u[obj.tris[0][1]], Vec3(1, 0, 2));
  EXPECT_EQ(obj.vert_u[obj.tris[0][2]], Vec3(0, 1, 3));
  EXPECT_EQ(obj.vert_node[obj.tris[0][0]], 0);
  EXPECT_EQ(obj.vert_node[obj.tris[0][2]], 2);
}

TEST_F(ObjRead, NodeTagsCommentsBlankLinesCrlfAndTabs) {
  const std::string text =
      "# a comment\r\n"
      "\r\n"
      "v 0 0 0   # trailing comment\r\n"
      "nv 1 2 3\r\n"
      "nl 7\r\n"
      "ny 4 4 4\r\n"
      "v\t1\t0\t0\r\n"
      "   \t \r\n"
      "v 0 1 0\r\n"
      "nl -2\r\n"
      "f 1 2 3\r\n";
  const ObjData obj = read_obj(write(text));
  ASSERT_EQ(obj.node_x.size(), 3u);
  EXPECT_EQ(obj.node_x[1], Vec3(1, 0, 0));
  EXPECT_EQ(obj.node_v[0], Vec3(1, 2, 3));
  EXPECT_EQ(obj.node_v[1], Vec3::Zero());
  EXPECT_EQ(obj.node_label, (std::vector<int>{7, 0, -2}));
  EXPECT_EQ(obj.tri_line, (std::vector<int>{11}));
  EXPECT_EQ(obj.unknown_tag_lines, 0);
}

TEST_F(ObjRead, UnknownTagsAreCountedStandardOnesSilentlyIgnored) {
  const ObjData obj = read_obj(write("mtllib x.mtl\no sheet\ng group\ns off\nusemtl m\n"
                                     "v 0 0 0\nvv 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\n"
                                     "pe 1 2\nfoo bar baz\nf 1//1 2//1 3//1\n"));
  EXPECT_EQ(obj.unknown_tag_lines, 3);  // vv, pe, foo
  EXPECT_EQ(obj.tris.size(), 1u);
}

TEST_F(ObjRead, AllFaceCornerSyntaxes) {
  const ObjData obj = read_obj(write("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                     "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
                                     "f 1/1/1 2/2/1 3/3/1\nf 1//1 3//1 4//1\n"));
  ASSERT_EQ(obj.tris.size(), 2u);
  // The second face gives no /k: nodes 1 and 3 reuse the rest vertices of the first face, node 4 gets one
  // created at its world position.
  EXPECT_EQ(obj.tris[1][0], obj.tris[0][0]);
  EXPECT_EQ(obj.tris[1][1], obj.tris[0][2]);
  EXPECT_EQ(obj.vert_u[obj.tris[1][2]], Vec3(0, 1, 0));
  EXPECT_EQ(obj.vert_u.size(), 4u);  // the unused vt 4 was dropped, the created one kept
}

TEST_F(ObjRead, UnusedTextureCoordinatesAreDropped) {
  const ObjData obj = read_obj(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 5 5\nvt 0 0\nvt 6 6\nvt 1 0\nvt 0 1\n"
                                     "f 1/2 2/4 3/5\n"));
  ASSERT_EQ(obj.vert_u.size(), 3u);
  EXPECT_EQ(obj.vert_u[0], Vec3(0, 0, 0));  // order of the used ones kept
  EXPECT_EQ(obj.vert_u[1], Vec3(1, 0, 0));
  EXPECT_EQ(obj.vert_u[2], Vec3(0, 1, 0));
  EXPECT_EQ(obj.tris[0], (std::array<int, 3>{0, 1, 2}));
}

TEST_F(ObjRead, RelativeIndicesCountBackFromTheLine) {
  const ObjData obj = read_obj(write("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                     "f -3/-3 -2/-2 -1/-1\n"
                                     "v 1 1 0\nvt 1 1\n"
                                     "f -3/-3 -1/-1 -2/-2\n"
                                     "e -3 -2\nea 0.5\n"));
  ASSERT_EQ(obj.tris.size(), 2u);
  EXPECT_EQ(nodes_of(obj, 0), (std::set<int>{0, 1, 2}));
  EXPECT_EQ(obj.vert_node[obj.tris[1][0]], 1);
  EXPECT_EQ(obj.vert_node[obj.tris[1][1]], 3);
  EXPECT_EQ(obj.vert_node[obj.tris[1][2]], 2);
  EXPECT_EQ(obj.vert_u[obj.tris[1][1]], Vec3(1, 1, 0));
  ASSERT_EQ(obj.edges.size(), 1u);
  EXPECT_EQ(obj.edges[0].n0, 1);
  EXPECT_EQ(obj.edges[0].n1, 2);
}

TEST_F(ObjRead, QuadIsSplitAlongTheDiagonalGivingTheLargerMinimumAngle) {
  // A flat rhombus: cutting along the long diagonal 1-3 would make two 11-degree slivers; the short diagonal
  // 2-4 keeps every angle above 22 degrees, so the fan starts at corner 2.
  const ObjData obj = read_obj(write("v -1 0 0\nv 0 -0.2 0\nv 1 0 0\nv 0 0.2 0\nf 1 2 3 4\ntm 3\n"));
  ASSERT_EQ(obj.tris.size(), 2u);
  EXPECT_EQ(nodes_of(obj, 0), (std::set<int>{1, 2, 3}));
  EXPECT_EQ(nodes_of(obj, 1), (std::set<int>{1, 3, 0}));
  EXPECT_EQ(obj.vert_node[obj.tris[0][0]], 1);  // fan root
  for (int t = 0; t < 2; ++t) {
    EXPECT_GT(signed_area_xy(obj, t), 0) << "orientation kept";
    EXPECT_EQ(obj.tri_line[t], 5);
    EXPECT_EQ(obj.tri_material[t], 3) << "face tags apply to every triangle of the polygon";
  }
}

TEST_F(ObjRead, PolygonFanCoversThePolygonOnce) {
  // An L-shaped hexagon (non-convex), total area 3. The fan from the reflex corner (node 4) has no angle below
  // 45 degrees; every other root gives a smaller minimum angle (and some give inverted triangles).
  const ObjData obj = read_obj(write("v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n"));
  ASSERT_EQ(obj.tris.size(), 4u);
  double area = 0;
  for (int t = 0; t < 4; ++t) {
    EXPECT_GT(signed_area_xy(obj, t), 0);
    area += signed_area_xy(obj, t);
  }
  EXPECT_NEAR(area, 3.0, 1e-14);
  EXPECT_EQ(obj.vert_node[obj.tris[0][0]], 3);
}

TEST_F(ObjRead, SeamNodeWithTwoRestVerticesBuildsASeam) {
  // Two triangles share world edge 2-3, but node 2 has a different rest vertex in each (a sewn seam, as in the
  // tshirt mesh): rest space is cut open along the shared edge.
  const std::string path = write(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
      "vt 0 0\nvt 1 0\nvt 0 1\nvt 3 0\nvt 4 1\nvt 3 1\n"
      "f 1/1 2/2 3/3\n"
      "f 2/4 4/5 3/6\n");
  const ObjData obj = read_obj(path);
  EXPECT_EQ(obj.vert_u.size(), 6u);
  const Mesh mesh = build_mesh(obj, path);
  ASSERT_EQ(mesh.nodes.size(), 4u);
  EXPECT_EQ(mesh.nodes[1].verts.size(), 2u);
  EXPECT_EQ(mesh.nodes[2].verts.size(), 2u);
  EXPECT_EQ(mesh.nodes[0].verts.size(), 1u);
  const int shared = mesh.find_edge(1, 2);
  ASSERT_NE(shared, kNone);
  EXPECT_FALSE(mesh.edges[shared].is_boundary()) << "one world edge between both faces";
  EXPECT_EQ(mesh.rest_dihedral(shared), 0.0);
  for (const Node& n : mesh.nodes) EXPECT_TRUE(n.preserve);
}

TEST_F(ObjRead, FaceStateTagsAttachToThePrecedingFace) {
  const ObjData obj = read_obj(write("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                     "f 1 2 3\ntm 2\nth 0.001\ntp 1 2 3 4 5 6 7 8 9\nts 1.5 0 0 0 0.5 0 0 0 1\ntd 0.25\n"
                                     "f 1 3 4\n"));
  ASSERT_EQ(obj.tris.size(), 2u);
  EXPECT_EQ(obj.tri_material, (std::vector<int>{2, 0}));
  EXPECT_EQ(obj.tri_thickness, (std::vector<double>{0.001, 0}));
  Mat3 sp;
  sp << 1, 2, 3, 4, 5, 6, 7, 8, 9;  // row-major in the file
  EXPECT_EQ(obj.tri_Sp[0], sp);
  EXPECT_EQ(obj.tri_Sp[1], Mat3::Zero());
  EXPECT_EQ(obj.tri_Fp[0], Vec3(1.5, 0.5, 1).asDiagonal().toDenseMatrix());
  EXPECT_EQ(obj.tri_Fp[1], Mat3::Identity());
  EXPECT_EQ(obj.tri_damage, (std::vector<double>{0.25, 0}));
}

// A unit right-angle fold in rest space: faces (1,2,3) in the xy plane and (2,1,4) in the xz plane, hinge 1-2.
const char* kFoldedRest =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\n"
    "ms 0 0 0\nms 1 0 0\nms 0 1 0\nms 0 0 1\n"
    "f 1/1 2/2 3/3\nf 2/2 1/1 4/4\n";

TEST_F(ObjRead, EdgesWithoutRecordGetTheRestDihedral) {
  const std::string path = write(kFoldedRest);
  const Mesh mesh = load_obj_mesh(path);
  const int hinge = mesh.find_edge(0, 1);
  ASSERT_NE(hinge, kNone);
  EXPECT_NEAR(std::abs(mesh.edges[hinge].rest_theta), M_PI / 2, 1e-12);
  EXPECT_FALSE(mesh.edges[hinge].preserve);
  // World space is flat, rest space folded: the rest angle comes from ms, not from v.
  EXPECT_NEAR(mesh.world_dihedral(hinge), 0.0, 1e-12);
}

TEST_F(ObjRead, EdgeRecordsSetRestAngleDamageAndPreserve) {
  const std::string path = write(std::string(kFoldedRest) + "e 2 1\nea 0.125\ned 0.5\nep\ne 1 3\nep 0\ned 2\n");
  const ObjData obj = read_obj(path);
  ASSERT_EQ(obj.edges.size(), 2u);
  EXPECT_TRUE(obj.edges[0].has_rest_theta);
  EXPECT_FALSE(obj.edges[1].has_rest_theta);
  const Mesh mesh = build_mesh(obj, path);
  const Edge& hinge = mesh.edges[mesh.find_edge(0, 1)];
  EXPECT_EQ(hinge.rest_theta, 0.125);
  EXPECT_EQ(hinge.damage, 0.5);
  EXPECT_TRUE(hinge.preserve);
  const Edge& side = mesh.edges[mesh.find_edge(0, 2)];
  EXPECT_EQ(side.rest_theta, 0.0);  // boundary edge, no ea: default
  EXPECT_EQ(side.damage, 2.0);
  EXPECT_FALSE(side.preserve);
}

TEST_F(ObjRead, BuildMeshCarriesNodeAndFaceStateAndMarksPreservedNodes) {
  // 3 x 3 nodes; the centre node (5) is interior. Label it in one run and not in another.
  std::string grid;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) grid += "v " + std::to_string(i) + " " + std::to_string(j) + " 0\n";
  std::string faces;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = 1 + i + 3 * j, b = a + 1, c = a + 4, d = a + 3;
      faces += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
      faces += "f " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(d) + "\n";
    }
  const Mesh plain = load_obj_mesh(write(grid + faces + "th 0.002\ntd 0.5\ntm 1\n", "plain.obj"));
  ASSERT_EQ(plain.nodes.size(), 9u);
  ASSERT_EQ(plain.faces.size(), 8u);
  for (int n = 0; n < 9; ++n) EXPECT_EQ(plain.nodes[n].preserve, n != 4) << "node " << n;
  EXPECT_EQ(plain.faces[7].thickness, 0.002);
  EXPECT_EQ(plain.faces[7].damage, 0.5);
  EXPECT_EQ(plain.faces[7].material, 1);
  EXPECT_EQ(plain.faces[6].thickness, 0.0);

  std::string labelled = grid;
  labelled.insert(labelled.find("v 1 1 0\n") + 8, "nl 4\nnv 0 0 -1\n");
  const Mesh mesh = load_obj_mesh(write(labelled + faces, "labelled.obj"));
  EXPECT_TRUE(mesh.nodes[4].preserve);
  EXPECT_EQ(mesh.nodes[4].label, 4);
  EXPECT_EQ(mesh.nodes[4].v, Vec3(0, 0, -1));
  EXPECT_EQ(mesh.nodes[4].x0, Vec3(1, 1, 0));
  EXPECT_DOUBLE_EQ(mesh.faces[0].rest_area, 0.5);
}

TEST_F(ObjRead, NumbersAreReadExactly) {
  const ObjData obj = read_obj(write("v 0.1 -2.5e-3 +3\nv 1e0 0 0\nv 0.30000000000000004 1 0\nf 1 2 3\n"));
  EXPECT_EQ(obj.node_x[0], Vec3(0.1, -2.5e-3, 3.0));
  EXPECT_EQ(obj.node_x[2].x(), 0.1 + 0.2);
}

}  // namespace
}  // namespace arcsim
