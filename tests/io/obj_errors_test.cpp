// Malformed OBJ files: each must give one InputError line "<path>:<line>: <problem>" naming the faulty line.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "io/obj.hpp"
#include "math/errors.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

const char* kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";  // lines 1-3

class ObjErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("arcsim_obj_errors_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Reads `text` (and builds the mesh) and returns the error message; fails the test if none is thrown.
  std::string error_of(const std::string& text) {
    const std::string path = (dir_ / "bad.obj").string();
    std::ofstream(path, std::ios::binary) << text;
    try {
      load_obj_mesh(path);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no InputError for:\n" << text;
    return "";
  }
  // Checks the message names the file and line and mentions `fragment`.
  void expect_error(const std::string& text, int line, const std::string& fragment) {
    const std::string message = error_of(text);
    const std::string prefix = (dir_ / "bad.obj").string() + ":" + std::to_string(line) + ": ";
    EXPECT_EQ(message.rfind(prefix, 0), 0u) << "message: " << message << "\nexpected prefix: " << prefix;
    EXPECT_NE(message.find(fragment), std::string::npos) << "message: " << message << "\nexpected: " << fragment;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line";
  }
  fs::path dir_;
};

TEST_F(ObjErrors, MissingFile) {
  const std::string path = (dir_ / "absent.obj").string();
  try {
    read_obj(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": cannot open");
  }
}

TEST_F(ObjErrors, BadNumber) {
  expect_error("v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n", 2, "bad number 'zero'");
  expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0.5.5\nf 1 2 3\n", 3, "bad number '0.5.5'");
  expect_error(std::string(kTriangle) + "vt 0 x\nf 1 2 3\n", 4, "bad number 'x'");
  expect_error(std::string(kTriangle) + "f 1 2 3\ntd 1e999\n", 5, "bad number");
}

TEST_F(ObjErrors, TooFewOrTooManyNumbers) {
  expect_error("v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", 2, "too few values for 'v'");
  expect_error(std::string(kTriangle) + "vt 1\nf 1 2 3\n", 4, "too few values for 'vt'");
  expect_error(std::string(kTriangle) + "ms 1 2\nf 1 2 3\n", 4, "too few values for 'ms'");
  expect_error(std::string(kTriangle) + "nv 1 2 3 4\nf 1 2 3\n", 4, "too many values for 'nv'");
  expect_error(std::string(kTriangle) + "f 1 2 3\ntp 1 2 3 4 5 6 7 8\n", 5, "too few values for 'tp'");
  expect_error(std::string(kTriangle) + "f 1 2 3\ne 1\n", 5, "too few values for 'e'");
}

TEST_F(ObjErrors, NonFiniteCoordinates) {
  expect_error("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", 2, "non-finite");
  expect_error(std::string(kTriangle) + "vt inf 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n", 4, "non-finite");
  expect_error(std::string(kTriangle) + "ms 0 0 -inf\nf 1 2 3\n", 4, "non-finite");
  expect_error(std::string(kTriangle) + "nv 0 NaN 0\nf 1 2 3\n", 4, "non-finite");
  expect_error(std::string(kTriangle) + "f 1 2 3\ne 1 2\nea nan\n", 6, "non-finite");
}

TEST_F(ObjErrors, NodeIndexOutOfRange) {
  expect_error(std::string(kTriangle) + "f 1 2 4\n", 4, "node index 4 out of range (3 defined)");
  expect_error(std::string(kTriangle) + "f 1 0 3\n", 4, "node index 0");
  expect_error(std::string(kTriangle) + "f -4 -2 -1\n", 4, "relative node index -4 out of range");
  expect_error(std::string(kTriangle) + "f 1 2 99999999999999999999\n", 4, "bad integer");
  expect_error(std::string(kTriangle) + "f 1 2 -9223372036854775808\n", 4, "relative node index");
}

TEST_F(ObjErrors, RestIndexOutOfRange) {
  expect_error(std::string(kTriangle) + "vt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/4\n", 7,
               "vt index 4 out of range (3 defined)");
  // With ms lines present the /k indices count ms lines, whatever the number of vt lines.
  expect_error(std::string(kTriangle) + "vt 0 0\nvt 1 0\nvt 0 1\nms 0 0 0\nms 1 0 0\nf 1/1 2/2 3/3\n", 9,
               "ms index 3 out of range (2 defined)");
  expect_error(std::string(kTriangle) + "vt 0 0\nf 1/-2 2 3\nvt 1 0\n", 5, "relative vt index -2");
}

TEST_F(ObjErrors, BadFaces) {
  expect_error(std::string(kTriangle) + "f 1 2\n", 4, "face with 2 corners");
  expect_error(std::string(kTriangle) + "f\n", 4, "face with 0 corners");
  expect_error(std::string(kTriangle) + "f 1/a 2 3\n", 4, "bad integer 'a'");
  expect_error(std::string(kTriangle) + "f /1 2 3\n", 4, "no node index");
  expect_error(std::string(kTriangle) + "f 1/1/1/1 2 3\n", 4, "bad face corner");
  // One rest vertex cannot belong to two nodes.
  expect_error(std::string(kTriangle) + "vt 0 0\nvt 1 0\nf 1/1 2/2 3/1\n", 6, "rest vertex 1 (vt) used with nodes 1 and 3");
}

TEST_F(ObjErrors, HugePolygonIsRejectedNotTriangulated) {
  std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  for (int i = 0; i < 1001; ++i) text += " " + std::to_string(1 + i % 3);
  expect_error(text + "\n", 4, "face with 1001 corners (at most 1000)");
}

TEST_F(ObjErrors, FileWithoutFaces) {
  const std::string message = error_of("# nothing but a comment\nv 0 0 0\n");
  EXPECT_EQ(message, (dir_ / "bad.obj").string() + ": no faces");
  EXPECT_EQ(error_of(""), (dir_ / "bad.obj").string() + ": no faces");
}

TEST_F(ObjErrors, TagsWithoutTheElementTheyDescribe) {
  expect_error("nv 0 0 0\n" + std::string(kTriangle) + "f 1 2 3\n", 1, "'nv' before any 'v' line");
  expect_error("nl 1\n" + std::string(kTriangle) + "f 1 2 3\n", 1, "'nl' before any 'v' line");
  expect_error(std::string(kTriangle) + "tm 1\nf 1 2 3\n", 4, "'tm' before any 'f' line");
  expect_error(std::string(kTriangle) + "f 1 2 3\nea 0.5\n", 5, "'ea' before any 'e' line");
}

TEST_F(ObjErrors, BadValues) {
  expect_error(std::string(kTriangle) + "nl 1.5\nf 1 2 3\n", 4, "bad integer '1.5'");
  expect_error(std::string(kTriangle) + "f 1 2 3\ntm -1\n", 5, "negative material index");
  expect_error(std::string(kTriangle) + "f 1 2 3\nth -0.001\n", 5, "negative thickness");
  expect_error(std::string(kTriangle) + "f 1 2 3\ntd -1\n", 5, "negative damage");
}

TEST_F(ObjErrors, EdgeRecordThatIsNotAnEdge) {
  expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\ne 1 4\nea 0.1\n", 7,
               "edge 1-4 is not a side of any face");
  expect_error(std::string(kTriangle) + "f 1 2 3\ne 1 7\n", 5, "node index 7 out of range");
}

TEST_F(ObjErrors, LineNumbersCountEveryLineWithCrlf) {
  expect_error("# header\r\n\r\nv 0 0 0\r\nv 1 0 0\r\n\r\nv 0 1 0\r\n# gap\r\nf 1 2 5\r\n", 8, "node index 5");
}

TEST_F(ObjErrors, BinaryGarbageGivesAReadableOneLineMessage) {
  std::string garbage = "v 0 0 0\nv \x01\x02\xff";
  garbage += std::string(200, 'z') + " 0 0\n";
  const std::string message = error_of(garbage);
  EXPECT_NE(message.find(":2: bad number"), std::string::npos) << message;
  EXPECT_LT(message.size(), 200u + (dir_ / "bad.obj").string().size());
  for (char c : message) EXPECT_TRUE(std::isprint(static_cast<unsigned char>(c))) << int(c);
}

// Mesh-level problems come from validate_triangles, with the file and the line of the face.
TEST_F(ObjErrors, InvalidTopologyIsReportedThroughValidation) {
  const std::string degenerate = error_of(std::string(kTriangle) + "f 1 2 2\n");
  EXPECT_EQ(degenerate.rfind((dir_ / "bad.obj").string() + ":4:", 0), 0u) << degenerate;
  const std::string unused = error_of(std::string(kTriangle) + "v 5 5 5\nf 1 2 3\n");
  EXPECT_EQ(unused.rfind((dir_ / "bad.obj").string() + ":", 0), 0u) << unused;
  EXPECT_NE(unused.find("node 4"), std::string::npos) << unused;
}

TEST_F(ObjErrors, DirectoryInsteadOfFile) {
  EXPECT_THROW(read_obj(dir_.string()), InputError);
}

// Random corruptions of a valid file must give a mesh or an InputError: no other exception, no crash (the
// sanitizer build checks memory), no hang.
TEST_F(ObjErrors, CorruptedFilesNeverCrash) {
  const std::string valid =
      "v 0 0 0\nnv 0 0 1\nv 1 0 0\nnl 2\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 0\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\nms 0 0 0\nms 1 0 0\nms 1 1 0\nms 0 1 0\nms 0.5 0.5 0.1\n"
      "f 1/1 2/2 5/5\ntm 1\nth 0.5\nf 2/2 3/3 5/5\ntp 1 0 0 0 1 0 0 0 1\nf 3/3 4/4 5/5\nts 1 0 0 0 1 0 0 0 1\n"
      "f -4/-4 -1/-1 -2/-2\ntd 0.5\ne 1 5\nea 0.25\ned 0.5\nep\n";
  const std::string alphabet = "0123456789 -+./#\nvtfemsnlpadh\x01";
  std::mt19937 rng(2024);
  int loaded = 0, rejected = 0;
  for (int trial = 0; trial < 250; ++trial) {
    std::string text = valid;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < edits; ++k) {
      const size_t at = rng() % text.size();
      const char c = alphabet[rng() % alphabet.size()];
      switch (rng() % 3) {
        case 0: text[at] = c; break;
        case 1: text.insert(at, 1, c); break;
        default: text.erase(at, 1 + rng() % 6); break;
      }
      if (text.empty()) text = "x";
    }
    const std::string path = (dir_ / "fuzz.obj").string();
    std::ofstream(path, std::ios::binary) << text;
    try {
      load_obj_mesh(path);
      ++loaded;
    } catch (const InputError& e) {
      ++rejected;
      EXPECT_EQ(std::string(e.what()).rfind(path + ":", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(loaded, 0);
  EXPECT_GT(rejected, 0);
}

TEST_F(ObjErrors, BuildMeshRejectsInconsistentData) {
  ObjData obj;
  obj.node_x = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  obj.vert_u = obj.node_x;
  obj.vert_node = {0, 1, 2};
  obj.tris = {{0, 1, 2}};
  EXPECT_NO_THROW(build_mesh(obj, "hand.obj"));  // the per-element vectors may be empty: defaults

  ObjData wrong_size = obj;
  wrong_size.tri_thickness = {0.1, 0.2};
  EXPECT_THROW(build_mesh(wrong_size, "hand.obj"), InputError);

  ObjData bad_edge = obj;
  bad_edge.edges.push_back({0, 5});
  try {
    build_mesh(bad_edge, "hand.obj");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "hand.obj: edge record 1-6 is not an edge of the mesh");
  }

  ObjData bad_vert = obj;
  bad_vert.vert_node[2] = 3;
  EXPECT_THROW(build_mesh(bad_vert, "hand.obj"), InputError);
}

}  // namespace
}  // namespace arcsim
