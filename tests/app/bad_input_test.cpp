// Malformed scenes, meshes, material files and arguments, run through the real binary: each must exit with
// code 2 and print exactly one stderr line "arcsim: ..." that names the file and the key, line or element at
// fault. None may crash (the sanitizer run executes the ASan binary through ARCSIM_BIN).
#include <gtest/gtest.h>

#include <map>

#include "app_test_support.hpp"

namespace arcsim::app_test {
namespace {

const char kMaterial[] = "{\"thickness\": 1e-3, \"density\": 500, \"elastic_modulus\": 1e6, \"poisson_ratio\": 0.3}";

struct BadInputCase {
  const char* name;
  std::map<std::string, std::string> files;  // relative path -> content, written into a fresh folder
  std::vector<std::string> args;             // after `simulate`; "@" stands for the folder
  std::vector<std::string> expected;         // substrings of the error line
};

// The tiny sheet with `edit` appended (extra OBJ lines).
std::string sheet_plus(const std::string& edit) { return tiny_sheet_obj() + edit; }

// A scene naming `mesh`, with a material and extra top-level keys.
std::string scene_with(const std::string& material, const std::string& extra = "",
                       const std::string& mesh = "sheet.obj") {
  return tiny_scene(mesh, material, extra);
}

// A scene whose material carries `key_value` (e.g. "\"thickness\": -1e-3") instead of the default's.
std::string scene_with_material(const std::string& key_value) {
  return scene_with("{\"density\": 500, \"elastic_modulus\": 1e6, " + key_value + "}");
}

// A scene of the tiny sheet with the given handles.
std::string scene_with_handles(const std::string& handles) {
  return "{\"frame_time\": 0.02, \"end_frame\": 1, \"cloths\": [{\"mesh\": \"sheet.obj\", \"materials\": [" +
         std::string(kMaterial) + "]}], \"handles\": " + handles + ", \"disable\": [\"remeshing\"]}\n";
}

std::vector<BadInputCase> bad_input_cases() {
  const std::string scene = "scene.json";
  const std::string good_sheet = tiny_sheet_obj();
  const std::string thick = "\"thickness\": 1e-3";
  return {
      {"MissingSceneFile", {}, {"@/absent.json"}, {"absent.json", "cannot open"}},
      {"SceneIsAFolder", {{"folder.json/x", ""}}, {"@/folder.json"}, {"folder.json", "cannot open"}},
      {"JsonSyntaxError",
       {{scene, "{\n  \"frame_time\": 0.02\n  \"end_frame\": 3\n}\n"}},
       {"@/scene.json"},
       {"scene.json:3:"}},
      {"TrailingText", {{scene, scene_with(kMaterial) + "}\n"}}, {"@/scene.json"}, {"scene.json:"}},
      {"WrongType",
       {{scene, "{\"frame_time\": \"fast\", \"cloths\": []}"}},
       {"@/scene.json"},
       {"scene.json", "frame_time", "must be"}},
      {"MissingTiming",
       {{"sheet.obj", good_sheet}, {scene, "{\"cloths\": [{\"mesh\": \"sheet.obj\", \"materials\": [" +
                                              std::string(kMaterial) + "]}]}"}},
       {"@/scene.json"},
       {"scene.json", "frame_time"}},
      {"ZeroFrameSteps",
       {{"sheet.obj", good_sheet},
        {scene, "{\"frame_time\": 0.02, \"frame_steps\": 0, \"cloths\": [{\"mesh\": \"sheet.obj\", "
                "\"materials\": [" + std::string(kMaterial) + "]}], \"disable\": [\"remeshing\"]}"}},
       {"@/scene.json"},
       {"scene.json", "frame_steps"}},
      {"NegativeThickness",
       {{"sheet.obj", good_sheet}, {scene, scene_with_material("\"thickness\": -1e-3")}},
       {"@/scene.json"},
       {"scene.json", "cloths[0].materials[0].thickness"}},
      {"InfiniteModulusFrom1e999",
       {{"sheet.obj", good_sheet},
        {scene, scene_with("{" + thick + ", \"density\": 500, \"elastic_modulus\": 1e999}")}},
       {"@/scene.json"},
       {"scene.json:3:", "1e999"}},  // jsoncpp's parser rejects it, at its line and column
      {"InfinityLiteral",
       {{"sheet.obj", good_sheet},
        {scene, scene_with("{" + thick + ", \"density\": 500, \"elastic_modulus\": Infinity}")}},
       {"@/scene.json"},
       {"scene.json", "cloths[0].materials[0].elastic_modulus", "finite"}},
      {"NaNLiteral",
       {{"sheet.obj", good_sheet}, {scene, scene_with_material(thick + ", \"poisson_ratio\": NaN")}},
       {"@/scene.json"},
       {"scene.json", "cloths[0].materials[0].poisson_ratio", "NaN"}},
      {"NaNAsAString",
       {{"sheet.obj", good_sheet}, {scene, scene_with_material(thick + ", \"poisson_ratio\": \"NaN\"")}},
       {"@/scene.json"},
       {"scene.json", "cloths[0].materials[0].poisson_ratio"}},
      {"PoissonRatioOneHalf",
       {{"sheet.obj", good_sheet}, {scene, scene_with_material(thick + ", \"poisson_ratio\": 0.5")}},
       {"@/scene.json"},
       {"scene.json", "cloths[0].materials[0].poisson_ratio", "0.5"}},
      {"MissingMeshFile",
       {{scene, scene_with(kMaterial, "", "absent.obj")}},
       {"@/scene.json"},
       {"scene.json", "cloths[0].mesh", "absent.obj"}},
      {"MissingMaterialDataFile",
       {{"sheet.obj", good_sheet}, {scene, scene_with("{\"data\": \"absent-material.json\"}")}},
       {"@/scene.json"},
       {"cloths[0].materials[0].data", "absent-material.json"}},
      {"BadValueInMaterialFile",
       {{"sheet.obj", good_sheet},
        {"soft.json", "{\"thickness\": 1e-3, \"density\": -5, \"elastic_modulus\": 1e6}"},
        {scene, scene_with("{\"data\": \"soft.json\"}")}},
       {"@/scene.json"},
       {"soft.json", "density"}},
      {"UnknownHandleNode",
       {{"sheet.obj", good_sheet}, {scene, scene_with_handles("[{\"nodes\": [0, 99]}]")}},
       {"@/scene.json"},
       {"scene.json", "handles[", "node 99"}},
      {"HandleLabelNotInMesh",
       {{"sheet.obj", good_sheet}, {scene, scene_with_handles("[{\"label\": 7}]")}},
       {"@/scene.json"},
       {"scene.json", "handles[", "label"}},
      {"MaterialIndexOutOfRangeInMesh",
       {{"bad.obj", sheet_plus("tm 3\n")}, {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj", "material 3"}},
      {"NonManifoldEdge",
       {{"bad.obj", good_sheet + "v 0.5 0.5 1\nf 2 5 10\n"}, {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj:21", "non-manifold edge (node 2, node 5)"}},
      {"DuplicateFace",
       {{"bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\nf 4 3 1\n"},
        {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj:7", "duplicates face 2"}},
      {"OrientationFlippedFace",
       {{"bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 4 3\n"},
        {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj:6", "inconsistent orientation"}},
      {"RepeatedNodeInFace",
       {{"bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 2\n"}, {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj:4", "degenerate"}},
      {"ZeroAreaFace",
       {{"bad.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"}, {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj:4", "area"}},
      {"FaceIndexOutOfRange",
       {{"bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 99\n"}, {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj:4", "99", "out of range"}},
      {"FaceIndexZero",
       {{"bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n"}, {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj:4", "index 0"}},
      {"UnreferencedVertex",
       {{"bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 5 5 5\nf 1 2 3\n"}, {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj", "referenced by no face (node 4)"}},
      {"BadNumberInObj",
       {{"bad.obj", "v 0 0 0\nv 1 zero 0\nv 1 1 0\nf 1 2 3\n"}, {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj:2", "zero"}},
      {"NonFiniteNumberInObj",
       {{"bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 nan\nf 1 2 3\n"}, {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj:3", "nan"}},
      {"EmptyMesh",
       {{"bad.obj", ""}, {scene, scene_with(kMaterial, "", "bad.obj")}},
       {"@/scene.json"},
       {"bad.obj", "no faces"}},
      {"BrokenObstacleMesh",
       {{"sheet.obj", good_sheet},
        {"post.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n"},
        {scene, scene_with(kMaterial, ", \"obstacles\": [{\"mesh\": \"post.obj\"}]")}},
       {"@/scene.json"},
       {"post.obj:3", "out of range"}},
      {"OutputFolderIsAFile",
       {{"sheet.obj", good_sheet}, {scene, scene_with(kMaterial)}, {"taken", "a file"}},
       {"@/scene.json", "@/taken"},
       {"taken", "not a folder"}},
  };
}

class BadInput : public ::testing::TestWithParam<BadInputCase> {};

TEST_P(BadInput, ExitsTwoWithOneLineNamingTheCulprit) {
  ARCSIM_REQUIRE_BINARY();
  const BadInputCase& c = GetParam();
  TempFolder tmp;
  for (const auto& [name, text] : c.files) tmp.write(name, text);
  std::vector<std::string> args = {"simulate"};
  for (std::string a : c.args) {
    if (a.rfind("@", 0) == 0) a = tmp.path().string() + a.substr(1);
    args.push_back(a);
  }
  const RunResult r = run_arcsim(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  const std::vector<std::string> lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_EQ(lines[0].rfind("arcsim: ", 0), 0u) << lines[0];
  for (const std::string& part : c.expected)
    EXPECT_NE(lines[0].find(part), std::string::npos) << part << " in: " << lines[0];
  EXPECT_EQ(r.out, "");
}

INSTANTIATE_TEST_SUITE_P(ScenesMeshesAndArguments, BadInput, ::testing::ValuesIn(bad_input_cases()),
                         [](const ::testing::TestParamInfo<BadInputCase>& test) { return test.param.name; });

}  // namespace
}  // namespace arcsim::app_test
