// The scene option "remeshing": {"plastic_transfer": "embedding" | "interpolate"}, and plastic-aware sizing
// (M' = Fp^-T M Fp^-1, paper §5.1) as the simulation's remeshing options use it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "io/scene_parser.hpp"
#include "math/errors.hpp"
#include "plasticity/plastic_tensors.hpp"
#include "remesh/remesh.hpp"
#include "sim/remesh_cloth.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

// Writes a one-cloth scene whose remeshing block is `remeshing` (JSON text) and loads it.
struct SceneWithRemeshing {
  fs::path dir;
  std::string path;
  explicit SceneWithRemeshing(const std::string& remeshing) {
    static int counter = 0;
    dir = fs::temp_directory_path() /
          ("arcsim-plastic-transfer-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::create_directories(dir);
    std::ofstream(dir / "sheet.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
    path = (dir / "scene.json").string();
    std::ofstream(path) << R"({"frame_time": 0.04, "frame_steps": 4, "end_time": 1, "cloths": [{
        "mesh": "sheet.obj",
        "materials": [{"thickness": 1e-3, "density": 2700, "elastic_modulus": 7e10, "poisson_ratio": 0.33}],
        "remeshing": {"size": [0.01, 0.1], "aspect_min": 0.2, "refine_compression": 0.01)"
                        << remeshing << "}}]}";
  }
  ~SceneWithRemeshing() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

TEST(PlasticTransferOption, DefaultsToEmbeddingAndParsesBothValues) {
  EXPECT_TRUE(load_scene(SceneWithRemeshing("").path).cloths.at(0).remeshing.plastic_embedding);
  EXPECT_TRUE(load_scene(SceneWithRemeshing(R"(, "plastic_transfer": "embedding")").path)
                  .cloths.at(0).remeshing.plastic_embedding);
  EXPECT_FALSE(load_scene(SceneWithRemeshing(R"(, "plastic_transfer": "interpolate")").path)
                   .cloths.at(0).remeshing.plastic_embedding);
}

TEST(PlasticTransferOption, BadValueIsAOneLineErrorNamingFileAndKey) {
  for (const std::string bad : {R"("linear")", "1"}) {
    SceneWithRemeshing scene(R"(, "plastic_transfer": )" + bad);
    std::string message;
    try {
      load_scene(scene.path);
    } catch (const InputError& e) {
      message = e.what();
    }
    ASSERT_FALSE(message.empty()) << bad;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(scene.path + ":", 0), 0u) << message;
    EXPECT_NE(message.find("cloths[0].remeshing.plastic_transfer"), std::string::npos) << message;
  }
}

TEST(PlasticAwareSizing, SimulationRemeshesAgainstThePlasticShape) {
  // The simulation's remeshing options apply M' = Fp^-T M Fp^-1.
  EXPECT_TRUE(remesh_options(Scene{}).extras.plastic_transform);
  // A sheet with a velocity gradient along x asks for edges of length 0.12 along x: its 0.1 cells stay.
  // Plastically stretched to twice its length along x (plastic edge = Fp^-1 e, Fp2 = diag(1/2, 1)), the same
  // rest edges are 0.2 long in the plastic shape, so the remesher must split them to 0.05.
  auto remeshed_faces = [](bool stretched, bool plastic_transform) {
    Mesh m = testing::make_grid(4, 4, 0.4, 0.4);
    Material mat;
    mat.thickness = 1e-3;
    mat.density = 1000;
    mat.youngs_modulus = 1e6;
    mat.poisson_ratio = 0.3;
    for (Face& f : m.faces) {
      f.thickness = mat.thickness;
      if (stretched) f.Fp = face_plastic_stretch_3d(f, Mat2(Vec2(0.5, 1).asDiagonal()));
    }
    for (Node& n : m.nodes) n.v = Vec3(n.x.x(), 0, 0);  // dv/dx = 1 1/s
    RemeshOptions o;
    o.sizing.remeshing.refine_velocity = 0.12;  // size = refine_velocity / |dv/dx| = 0.12 m
    o.sizing.remeshing.size_min = 0.01;
    o.sizing.remeshing.size_max = 1;
    o.extras.plastic_transform = plastic_transform;
    o.reproject = false;
    remesh_mesh(m, {mat}, o);
    double longest_x = 0;  // longest rest extent along x of an edge
    int faces = 0;
    for (const Face& f : m.faces) {
      if (f.dead) continue;
      ++faces;
      for (int i = 0; i < 3; ++i)
        longest_x = std::max(longest_x, std::abs(m.verts[f.v[(i + 1) % 3]].u.x() - m.verts[f.v[i]].u.x()));
    }
    return std::make_pair(faces, longest_x);
  };
  const auto elastic = remeshed_faces(false, true);
  const auto plastic = remeshed_faces(true, true);
  const auto plastic_ignored = remeshed_faces(true, false);
  EXPECT_NEAR(elastic.second, 0.1, 1e-9);
  EXPECT_LE(plastic.second, 0.05 + 1e-9);
  EXPECT_GT(plastic.first, elastic.first);
  EXPECT_EQ(plastic_ignored.first, elastic.first);
}

}  // namespace
}  // namespace arcsim
