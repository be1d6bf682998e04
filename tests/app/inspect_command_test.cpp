// `arcsim inspect`: measures pieces and finds intersections and invalid frames in a run folder, with exit 3 for
// a folder that fails a check and exit 2 for bad input. Frames are written by hand so each case is known.
#include <gtest/gtest.h>

#include "app/app_test_support.hpp"

namespace arcsim::app_test {
namespace {

// Two triangles far apart: two pieces.
const char kTwoPieces[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 1 2 3\nf 4 5 6\n";
// Two triangles of one sheet (no shared node) crossing each other.
const char kCrossing[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0.2 0.2 -1\nv 0.2 0.2 1\nv 2 2 0.5\nf 1 2 3\nf 4 5 6\n";
// Three faces on one edge: not a manifold mesh.
const char kNonManifold[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";

TEST(Inspect, ReportsPiecesOfCleanFramesAndExitsZero) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder dir;
  dir.write("00000_00.obj", tiny_sheet_obj());
  dir.write("00001_00.obj", kTwoPieces);
  const RunResult r = run_arcsim({"inspect", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 2u) << r.out;
  EXPECT_NE(lines[0].find("\"frame\":0,"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("\"faces\":8,\"nodes\":9,\"pieces\":1,\"piece_faces\":[8],\"piece_rest_area\":[1]"),
            std::string::npos)
      << lines[0];
  EXPECT_NE(lines[1].find("\"pieces\":2,\"piece_faces\":[1,1],\"piece_rest_area\":[0.5,0.5]"), std::string::npos)
      << lines[1];
  EXPECT_NE(lines[1].find("\"intersections\":0,\"clean\":true"), std::string::npos) << lines[1];
  EXPECT_NE(r.err.find("2 frames valid, no intersections"), std::string::npos) << r.err;

  const RunResult last = run_arcsim({"inspect", dir.path().string(), "--last"});
  ASSERT_EQ(last.exit_code, 0) << last.err;
  ASSERT_EQ(lines_of(last.out).size(), 1u);
  EXPECT_NE(last.out.find("\"frame\":1,"), std::string::npos);
}

TEST(Inspect, FindsCrossingTrianglesAndObstaclesAndExitsThree) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder dir;
  dir.write("00000_00.obj", tiny_sheet_obj());
  dir.write("00003_00.obj", kCrossing);
  const RunResult r = run_arcsim({"inspect", dir.path().string()});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  const std::vector<std::string> lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 2u) << "every frame is still reported";
  EXPECT_NE(lines[0].find("\"clean\":true"), std::string::npos);
  EXPECT_NE(lines[1].find("\"intersections\":1,\"clean\":false"), std::string::npos) << lines[1];
  EXPECT_NE(r.err.find("1 of 2 frames fail; first: frame 3: 1 intersecting triangle pair (first: sheet 0 face 1 "
                       "and sheet 0 face 2)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(lines_of(r.err).size(), 1u) << "one line";

  // A static obstacle through the sheet (the tiny sheet lies in z = 0; a vertical triangle pierces it).
  TempFolder with_obstacle;
  with_obstacle.write("00000_00.obj", tiny_sheet_obj());
  with_obstacle.write("obs00.obj", "v 0.3 0.3 -1\nv 0.3 0.3 1\nv 0.6 0.7 0\nf 1 2 3\n");
  const RunResult o = run_arcsim({"inspect", with_obstacle.path().string()});
  EXPECT_EQ(o.exit_code, 3);
  EXPECT_NE(o.err.find("and obstacle 0 face 1"), std::string::npos) << o.err;
}

TEST(Inspect, AnInvalidMeshIsReportedNotACrash) {
  ARCSIM_REQUIRE_BINARY();
  for (const std::string& text : {std::string(kNonManifold), std::string("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")}) {
    TempFolder dir;
    dir.write("00005_00.obj", text);
    const RunResult r = run_arcsim({"inspect", dir.path().string()});
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_NE(r.out.find("\"valid\":false,\"problem\":"), std::string::npos) << r.out;
    EXPECT_NE(r.err.find("frame 5: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("00005_00.obj"), std::string::npos) << "names the file: " << r.err;
  }
}

TEST(Inspect, BadInputExitsTwoWithOneLine) {
  ARCSIM_REQUIRE_BINARY();
  TempFolder empty;
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"inspect", (empty.path() / "missing").string()},
           {"inspect", empty.path().string()},
           {"inspect", empty.path().string(), "--every", "0"},
           {"inspect"}}) {
    const RunResult r = run_arcsim(args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(lines_of(r.err).size(), 1u) << r.err;
  }
}

}  // namespace
}  // namespace arcsim::app_test
