// Writing extended OBJ: a written mesh reads back bit-identically; the file is readable by plain OBJ readers
// (vt pairs, f i/k); writing is atomic and reports unwritable paths.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "io/obj.hpp"
#include "math/errors.hpp"
#include "mesh/validate.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

class ObjWrite : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("arcsim_obj_write_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A 4 x 3 node grid on a curved (cylindrical) rest shape with irrational coordinates, cut along the middle
// column in rest space (a seam: the middle nodes have two rest vertices), and non-default state everywhere.
Mesh curved_seamed_sheet() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
  std::vector<Vec3> node_x, vert_u;
  std::vector<int> vert_node;
  const int nx = 4, ny = 3;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) node_x.push_back(Vec3(0.1 * i + jitter(rng), 0.1 * j + jitter(rng), jitter(rng)));
  // Rest vertex per node, plus a second one for the nodes of column 1 (used by the faces right of it).
  std::vector<int> left(nx * ny), right(nx * ny);
  for (int n = 0; n < nx * ny; ++n) {
    const int i = n % nx, j = n / nx;
    const double angle = 0.3 * i / 3.0;
    vert_u.push_back(Vec3(std::sin(angle) / 0.7, 0.1 * j + jitter(rng), (1 - std::cos(angle)) / 0.7));
    vert_node.push_back(n);
    left[n] = right[n] = static_cast<int>(vert_u.size()) - 1;
    if (i == 1) {
      vert_u.push_back(vert_u.back() + Vec3(0.05, 0, 0));
      vert_node.push_back(n);
      right[n] = static_cast<int>(vert_u.size()) - 1;
    }
  }
  std::vector<std::array<int, 3>> tris;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = i + nx * j, b = a + 1, c = a + nx + 1, d = a + nx;
      // Faces right of column 1 use its second rest vertices.
      auto vert = [&](int node) { return (i >= 1) ? right[node] : left[node]; };
      tris.push_back({vert(a), vert(b), vert(c)});
      tris.push_back({vert(a), vert(c), vert(d)});
    }
  Mesh mesh = Mesh::from_triangles(node_x, vert_u, vert_node, tris);
  for (size_t n = 0; n < mesh.nodes.size(); ++n) {
    mesh.nodes[n].v = Vec3(jitter(rng), n % 3 == 0 ? 0.0 : jitter(rng), -1.0 / 3.0);
    mesh.nodes[n].label = static_cast<int>(n % 4) - 1;
  }
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    Face& face = mesh.faces[f];
    face.material = static_cast<int>(f % 3);
    face.thickness = f % 2 ? 1e-3 / 3 : 0.0;
    if (f % 4 == 1) face.Sp = Mat3::Random() * 0.1;
    if (f % 4 == 2) face.Fp = Mat3::Identity() + Mat3::Random() * 1e-3;
    face.damage = f % 5 ? 0.0 : 0.7 / 3;
  }
  mesh.edges[3].rest_theta = M_PI / 7;  // a plastic rest angle
  mesh.edges[5].preserve = true;
  mesh.edges[6].damage = 1.0 / 9;
  return mesh;
}

// Reorders faces the way remeshing edits do (remove and re-add), so that some edges are stored in the
// opposite direction to the one a fresh build from the written file gives them.
void shuffle_faces(Mesh& mesh) {
  for (int f : {0, 3}) {
    const Face copy = mesh.faces[f];
    mesh.remove_face(f);
    mesh.add_face(copy.v, copy);
  }
  mesh.compact();
  mesh.update_rest_data();
}

void expect_same_mesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  ASSERT_EQ(a.verts.size(), b.verts.size());
  ASSERT_EQ(a.faces.size(), b.faces.size());
  ASSERT_EQ(a.edges.size(), b.edges.size());
  for (size_t n = 0; n < a.nodes.size(); ++n) {
    EXPECT_EQ(a.nodes[n].x, b.nodes[n].x) << "node " << n;  // Eigen == is exact
    EXPECT_EQ(a.nodes[n].v, b.nodes[n].v) << "node " << n;
    EXPECT_EQ(a.nodes[n].label, b.nodes[n].label) << "node " << n;
  }
  for (size_t k = 0; k < a.verts.size(); ++k) {
    EXPECT_EQ(a.verts[k].u, b.verts[k].u) << "vert " << k;
    EXPECT_EQ(a.verts[k].node, b.verts[k].node) << "vert " << k;
  }
  for (size_t f = 0; f < a.faces.size(); ++f) {
    EXPECT_EQ(a.faces[f].v, b.faces[f].v) << "face " << f;
    EXPECT_EQ(a.faces[f].material, b.faces[f].material) << "face " << f;
    EXPECT_EQ(a.faces[f].thickness, b.faces[f].thickness) << "face " << f;
    EXPECT_EQ(a.faces[f].Sp, b.faces[f].Sp) << "face " << f;
    EXPECT_EQ(a.faces[f].Fp, b.faces[f].Fp) << "face " << f;
    EXPECT_EQ(a.faces[f].damage, b.faces[f].damage) << "face " << f;
  }
  for (const Edge& ea : a.edges) {
    const int e = b.find_edge(ea.n[0], ea.n[1]);
    ASSERT_NE(e, kNone);
    EXPECT_EQ(ea.rest_theta, b.edges[e].rest_theta) << "edge " << ea.n[0] << "-" << ea.n[1];
    EXPECT_EQ(ea.damage, b.edges[e].damage);
    EXPECT_EQ(ea.preserve, b.edges[e].preserve);
  }
}

TEST_F(ObjWrite, RoundTripIsBitIdentical) {
  const Mesh mesh = curved_seamed_sheet();
  write_obj(mesh, path("a.obj"));
  const Mesh back = load_obj_mesh(path("a.obj"));
  EXPECT_EQ(check_mesh(back), "");
  expect_same_mesh(mesh, back);
  // The curved rest shape gives non-zero rest angles that were not written as records but recomputed.
  int curved = 0;
  for (const Edge& e : back.edges) curved += (e.rest_theta != 0);
  EXPECT_GT(curved, 3);
  // Writing the read-back mesh gives the same file.
  write_obj(back, path("b.obj"));
  EXPECT_EQ(read_text(path("a.obj")), read_text(path("b.obj")));
}

TEST_F(ObjWrite, RoundTripAfterEditsKeepsRestAnglesExactly) {
  Mesh mesh = curved_seamed_sheet();
  shuffle_faces(mesh);
  write_obj(mesh, path("a.obj"));
  expect_same_mesh(mesh, load_obj_mesh(path("a.obj")));
}

TEST_F(ObjWrite, DeadElementsAreSkipped) {
  Mesh mesh = curved_seamed_sheet();
  const Mesh expected = mesh;
  // Remove the two faces of the last grid cell: its far corner node and that node's rest vertex go with them,
  // and the edges left between the cell and its neighbours become boundary edges.
  const int last = static_cast<int>(mesh.faces.size()) - 1;
  for (int f : {last, last - 1}) {
    const Face face = mesh.faces[f];
    mesh.remove_face(f);
    for (int e : face.e)
      if (!mesh.edges[e].dead && mesh.edges[e].f[0] == kNone && mesh.edges[e].f[1] == kNone) mesh.remove_edge(e);
    for (int v : face.v)
      if (!mesh.verts[v].dead && mesh.verts[v].faces.empty()) {
        const int n = mesh.verts[v].node;
        mesh.remove_vert(v);
        if (mesh.nodes[n].verts.empty()) mesh.remove_node(n);
      }
  }
  write_obj(mesh, path("a.obj"));
  mesh.compact();
  const Mesh back = load_obj_mesh(path("a.obj"));
  EXPECT_EQ(back.nodes.size(), expected.nodes.size() - 1);
  EXPECT_EQ(back.faces.size(), expected.faces.size() - 2);
  expect_same_mesh(mesh, back);
}

TEST_F(ObjWrite, FileIsPlainObjForOtherTools) {
  const Mesh mesh = curved_seamed_sheet();
  write_obj(mesh, path("a.obj"));
  std::ifstream in(path("a.obj"));
  std::string line;
  size_t v = 0, vt = 0, ms = 0, f = 0;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string tag;
    words >> tag;
    std::vector<std::string> args;
    for (std::string w; words >> w;) args.push_back(w);
    if (tag == "v") ++v;
    if (tag == "ms") ++ms;
    if (tag == "vt") {
      ++vt;
      EXPECT_EQ(args.size(), 2u) << "vt must be a texture pair: " << line;
    }
    if (tag == "f") {
      ++f;
      ASSERT_EQ(args.size(), 3u);
      for (const std::string& corner : args) {
        const size_t slash = corner.find('/');
        ASSERT_NE(slash, std::string::npos) << line;
        EXPECT_LE(std::stoul(corner.substr(0, slash)), v);
        EXPECT_LE(std::stoul(corner.substr(slash + 1)), vt) << "vt defined before use";
      }
    }
  }
  EXPECT_EQ(v, mesh.nodes.size());
  EXPECT_EQ(vt, mesh.verts.size());
  EXPECT_EQ(ms, mesh.verts.size());
  EXPECT_EQ(f, mesh.faces.size());
}

TEST_F(ObjWrite, DefaultStateWritesNoExtraTags) {
  { std::ofstream(path("flat.obj")) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n"; }
  const Mesh mesh = load_obj_mesh(path("flat.obj"));
  write_obj(mesh, path("out.obj"));
  const std::string text = read_text(path("out.obj"));
  for (const char* tag : {"\nnv ", "\nnl ", "\ntm ", "\nth ", "\ntp ", "\nts ", "\ntd ", "\ne ", "\nea ", "\nep"})
    EXPECT_EQ(text.find(tag), std::string::npos) << tag;
  EXPECT_NE(text.find("\nf 1/1 2/2 3/3\n"), std::string::npos) << text;
}

TEST_F(ObjWrite, OverwritesAtomicallyAndLeavesNoTemporaryFile) {
  const Mesh mesh = curved_seamed_sheet();
  { std::ofstream(path("a.obj")) << "old contents\n"; }
  write_obj(mesh, path("a.obj"));
  EXPECT_NE(read_text(path("a.obj")), "old contents\n");
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename().string(), "a.obj") << "left behind: " << entry.path();
}

TEST_F(ObjWrite, UnwritablePathThrowsInputErrorAndLeavesNothing) {
  const Mesh mesh = curved_seamed_sheet();
  const std::string missing_dir = path("no/such/dir/a.obj");
  try {
    write_obj(mesh, missing_dir);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(missing_dir + ": cannot write", 0), 0u) << e.what();
  }
  // Target is a directory: the temporary file is written, the rename fails, and the temporary is removed.
  fs::create_directories(dir_ / "target.obj");
  EXPECT_THROW(write_obj(mesh, path("target.obj")), InputError);
  EXPECT_THROW(write_plain_obj(mesh, path("target.obj")), InputError);
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename().string(), "target.obj") << "left behind: " << entry.path();
}

TEST_F(ObjWrite, PlainObjHasWorldPositionsAndNodeFaces) {
  const Mesh mesh = curved_seamed_sheet();
  write_plain_obj(mesh, path("plain.obj"));
  const ObjData obj = read_obj(path("plain.obj"));
  EXPECT_FALSE(obj.has_rest_coords);
  ASSERT_EQ(obj.node_x.size(), mesh.nodes.size());
  for (size_t n = 0; n < mesh.nodes.size(); ++n) EXPECT_EQ(obj.node_x[n], mesh.nodes[n].x);
  ASSERT_EQ(obj.tris.size(), mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    for (int i = 0; i < 3; ++i) EXPECT_EQ(obj.vert_node[obj.tris[f][i]], mesh.face_node(static_cast<int>(f), i));
  EXPECT_EQ(obj.vert_u.size(), mesh.nodes.size()) << "no seams in a plain OBJ: one rest vertex per node";
}

}  // namespace
}  // namespace arcsim
