// Our isotropic material files (materials/*.json) parse cleanly and hold physically consistent values.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "io/scene_parser.hpp"
#include "math/errors.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

// The repository's materials/ folder: beside tests/ (found from this source file), else in the working directory.
fs::path materials_dir() {
  const fs::path from_source = fs::path(__FILE__).parent_path() / ".." / ".." / "materials";
  if (fs::is_directory(from_source)) return from_source;
  return "materials";
}

std::map<std::string, Material> load_all(std::vector<std::string>* warnings) {
  std::map<std::string, Material> out;
  for (const auto& entry : fs::directory_iterator(materials_dir()))
    if (entry.path().extension() == ".json")
      out[entry.path().stem().string()] = load_material_file(entry.path().string(), warnings);
  return out;
}

TEST(OurMaterials, AllTenParseWithoutWarnings) {
  ASSERT_TRUE(fs::is_directory(materials_dir())) << materials_dir();
  std::vector<std::string> warnings;
  std::map<std::string, Material> all;
  ASSERT_NO_THROW(all = load_all(&warnings));
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  for (const char* name : {"paper", "glass", "aluminium", "steel", "rubber", "cork", "foil", "vinyl",
                           "polycarbonate", "acrylic"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(all.count(name));
    const Material& m = all[name];
    EXPECT_EQ(m.name, name);
    EXPECT_FALSE(m.data_driven);
    EXPECT_GT(m.thickness, 0);
    EXPECT_LT(m.thickness, 0.01);  // sheets
    EXPECT_GT(m.density, 100);
    EXPECT_LT(m.density, 10000);
    EXPECT_GT(m.youngs_modulus, 0);
    EXPECT_GE(m.poisson_ratio, 0);
    EXPECT_LT(m.poisson_ratio, 0.5);
    EXPECT_GT(m.toughness, 0);  // every one of them breaks
    if (std::isfinite(m.yield_stress)) {
      // Yield before failure, and the yield curvature is the one where the surface reaches the yield strain.
      EXPECT_LT(m.yield_stress, m.toughness);
      EXPECT_NEAR(m.yield_curv, 2 * m.yield_stress / (m.youngs_modulus * m.thickness), 0.01 * m.yield_curv);
      EXPECT_GT(m.flow_rate, 0);
    }
  }
}

TEST(OurMaterials, HandbookValuesSpotChecks) {
  std::map<std::string, Material> all = load_all(nullptr);
  // Glass: E about 70 GPa, rho 2500, nu about 0.22, strength around 50 MPa, brittle.
  EXPECT_NEAR(all["glass"].youngs_modulus, 70e9, 5e9);
  EXPECT_NEAR(all["glass"].density, 2500, 100);
  EXPECT_NEAR(all["glass"].poisson_ratio, 0.22, 0.03);
  EXPECT_NEAR(all["glass"].toughness, 50e6, 20e6);
  EXPECT_TRUE(std::isinf(all["glass"].yield_stress));
  EXPECT_TRUE(std::isinf(all["acrylic"].yield_curv));
  // Steel is stiffer and denser than aluminium; foil is far thinner than sheet aluminium.
  EXPECT_GT(all["steel"].youngs_modulus, 2.5 * all["aluminium"].youngs_modulus);
  EXPECT_GT(all["steel"].density, 2.5 * all["aluminium"].density);
  EXPECT_LT(all["foil"].thickness, all["aluminium"].thickness / 20);
  // Rubber and cork are soft; rubber nearly incompressible, cork nearly zero Poisson's ratio.
  EXPECT_LT(all["rubber"].youngs_modulus, 10e6);
  EXPECT_GT(all["rubber"].poisson_ratio, 0.45);
  EXPECT_LT(all["cork"].poisson_ratio, 0.1);
  EXPECT_LT(all["cork"].density, 300);
}

TEST(OurMaterials, UsableFromASceneByDataKey) {
  const fs::path dir = fs::temp_directory_path() / ("arcsim-our-materials-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path glass = fs::absolute(materials_dir() / "glass.json");
  std::ofstream(dir / "sheet.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "s.json") << R"({"timestep": 1e-4, "disable": ["remeshing", "fracture"],
      "cloths": [{"mesh": "sheet.obj", "materials": [{"data": ")"
                                << glass.string() << R"(", "thickness": 6e-3}]}]})";
  Scene s;
  ASSERT_NO_THROW(s = load_scene((dir / "s.json").string()));
  fs::remove_all(dir);
  const Material& m = s.cloths.at(0).materials.at(0);
  EXPECT_DOUBLE_EQ(m.thickness, 6e-3);  // overridden inline
  EXPECT_DOUBLE_EQ(m.density, 2500);    // from glass.json
  EXPECT_EQ(m.name, "glass");
}

}  // namespace
}  // namespace arcsim
