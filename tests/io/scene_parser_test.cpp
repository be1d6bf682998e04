// Scene parser: malformed scenes give one-line InputErrors naming the file and key path, warnings for unknown
// and ignored keys, path resolution order, material files (ours and DDE), timing styles and defaults.
#include <gtest/gtest.h>
#include <json/json.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "io/scene_parser.hpp"
#include "math/errors.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

// A fresh folder under the system temp dir, removed with everything in it at the end of the test.
class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    path_ = fs::temp_directory_path() /
            ("arcsim-scene-parser-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
    return p.string();
  }

 private:
  fs::path path_;
};

// Changes the working directory for the lifetime of the object.
class ScopedCwd {
 public:
  explicit ScopedCwd(const fs::path& dir) : old_(fs::current_path()) { fs::current_path(dir); }
  ~ScopedCwd() { fs::current_path(old_); }

 private:
  fs::path old_;
};

std::string to_text(const Json::Value& v) {
  Json::StreamWriterBuilder w;
  w["useSpecialFloats"] = true;  // NaN / Infinity written as such, to test their rejection
  return Json::writeString(w, v);
}

Json::Value parse_text(const std::string& text) {
  Json::CharReaderBuilder b;
  b["allowComments"] = true;
  Json::Value v;
  std::string errs;
  std::istringstream in(text);
  EXPECT_TRUE(Json::parseFromStream(b, in, &v, &errs)) << errs;
  return v;
}

// A small valid scene using every section; the malformed scenes below each break one thing in it.
Json::Value base_scene() {
  return parse_text(R"({
    "frame_time": 0.04, "frame_steps": 4, "end_time": 1,
    "cloths": [{
      "mesh": "sheet.obj",
      "transform": {"translate": [0, 0, 1], "rotate": [90, 0, 0, 2], "scale": 2},
      "velocity": {"linear": [1, 2, 3]},
      "materials": [{"thickness": 1e-4, "density": 800, "elastic_modulus": 4e9, "poisson_ratio": 0.2}],
      "remeshing": {"refine_angle": 0.3, "refine_compression": 0.01, "size": [0.01, 0.1], "aspect_min": 0.2}
    }],
    "motions": [[{"time": 0}, {"time": 1, "transform": {"translate": [1, 0, 0]}}]],
    "handles": [{"nodes": [0, 3], "motion": 0}],
    "obstacles": [{"mesh": "sheet.obj", "motion": 0}],
    "gravity": [0, 0, -9.8]
  })");
}

const char* const kSheetObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";

// Writes `scene` (plus the mesh it names) into a temp folder and loads it.
struct SceneFixture {
  TempDir dir;
  std::string scene_path;
  explicit SceneFixture(const Json::Value& scene) : SceneFixture(to_text(scene)) {}
  explicit SceneFixture(const std::string& text) {
    dir.write("sheet.obj", kSheetObj);
    scene_path = dir.write("scene.json", text);
  }
  Scene load() const { return load_scene(scene_path); }
};

std::string error_of(const SceneFixture& f) {
  try {
    f.load();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SceneParser, BaseSceneParsesWithValuesAndDefaults) {
  SceneFixture f(base_scene());
  const Scene s = f.load();
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  EXPECT_DOUBLE_EQ(s.frame_time, 0.04);
  EXPECT_EQ(s.frame_steps, 4);
  EXPECT_DOUBLE_EQ(s.step_time, 0.01);
  EXPECT_DOUBLE_EQ(s.end_time, 1);
  EXPECT_TRUE(std::isinf(s.end_frame));
  EXPECT_EQ(s.save_every, 1);
  EXPECT_TRUE(std::isinf(s.passive_time));
  ASSERT_EQ(s.cloths.size(), 1u);
  const ClothSpec& c = s.cloths[0];
  EXPECT_EQ(fs::path(c.mesh), f.dir.path() / "sheet.obj");
  // rotate 90 deg about +z (axis given unnormalised) maps x to y; scale 2; then translate.
  EXPECT_TRUE(c.transform.apply(Vec3(1, 0, 0)).isApprox(Vec3(0, 2, 1), 1e-12));
  EXPECT_TRUE(c.velocity.linear.isApprox(Vec3(1, 2, 3)));
  ASSERT_EQ(c.materials.size(), 1u);
  const Material& m = c.materials[0];
  EXPECT_FALSE(m.data_driven);
  EXPECT_DOUBLE_EQ(m.thickness, 1e-4);
  EXPECT_DOUBLE_EQ(m.density, 800);
  EXPECT_DOUBLE_EQ(m.youngs_modulus, 4e9);
  EXPECT_DOUBLE_EQ(m.poisson_ratio, 0.2);
  // ARCSim defaults of the keys the scene leaves out.
  EXPECT_DOUBLE_EQ(m.toughness, 0);
  EXPECT_TRUE(std::isinf(m.yield_curv));
  EXPECT_DOUBLE_EQ(m.bending_mult, 1);
  EXPECT_DOUBLE_EQ(m.damping, 0);
  EXPECT_TRUE(std::isinf(c.remeshing.refine_velocity));
  EXPECT_TRUE(std::isinf(c.remeshing.refine_fracture));
  EXPECT_DOUBLE_EQ(c.remeshing.size_min, 0.01);
  EXPECT_DOUBLE_EQ(c.remeshing.size_max, 0.1);
  EXPECT_EQ(c.reference, "linear");
  EXPECT_FALSE(c.reference_is_mesh);
  ASSERT_EQ(s.handles.size(), 1u);
  EXPECT_EQ(s.handles[0].type, "node");
  EXPECT_EQ(s.handles[0].label, -1);
  EXPECT_EQ(s.handles[0].nodes, (std::vector<int>{0, 3}));
  EXPECT_EQ(s.handles[0].motion, 0);
  ASSERT_EQ(s.obstacles.size(), 1u);
  EXPECT_EQ(s.obstacles[0].motion, 0);
  EXPECT_DOUBLE_EQ(s.friction, 0.6);
  EXPECT_DOUBLE_EQ(s.obs_friction, 0.3);
  EXPECT_DOUBLE_EQ(s.wind.density, 1);  // ARCSim's default: air drag on
  EXPECT_DOUBLE_EQ(s.magic.handle_stiffness, 1e3);
  EXPECT_DOUBLE_EQ(s.magic.projection_thickness, 0.1 * s.magic.repulsion_thickness);
  // Auto-disabled like ARCSim: no strain limits, no plasticity, no toughness.
  EXPECT_FALSE(s.enabled("strainlimiting"));
  EXPECT_FALSE(s.enabled("plasticity"));
  EXPECT_FALSE(s.enabled("fracture"));
  EXPECT_TRUE(s.enabled("remeshing"));
  ASSERT_EQ(s.motions.size(), 1u);
  EXPECT_TRUE(s.motions[0].pose(1).translation.isApprox(Vec3(1, 0, 0)));
  // The same mesh named twice is recorded once.
  EXPECT_EQ(s.referenced_files.size(), 1u);
}

TEST(SceneParser, TimingStyleB) {
  Json::Value j = base_scene();
  j.removeMember("frame_time");
  j.removeMember("frame_steps");
  j.removeMember("end_time");
  j["timestep"] = 1e-3;
  j["save_frames"] = 2;
  j["save_every"] = 5;
  j["duration"] = 3;
  SceneFixture f(j);
  const Scene s = f.load();
  EXPECT_DOUBLE_EQ(s.step_time, 1e-3);
  EXPECT_EQ(s.frame_steps, 2);
  EXPECT_DOUBLE_EQ(s.frame_time, 2e-3);
  EXPECT_EQ(s.save_every, 5);
  EXPECT_DOUBLE_EQ(s.end_time, 3);
  EXPECT_TRUE(s.warnings.empty());
}

// adaptive_time_step: off unless given; `true` or an object turns it on with min_step = step / 1024 by default.
TEST(SceneParser, AdaptiveTimeStep) {
  const Scene off = SceneFixture(base_scene()).load();
  EXPECT_FALSE(off.adaptive_step.enabled);
  Json::Value j = base_scene();
  j["adaptive_time_step"] = true;
  const Scene on = SceneFixture(j).load();
  EXPECT_TRUE(on.adaptive_step.enabled);
  EXPECT_DOUBLE_EQ(on.adaptive_step.min_step, 0.01 / 1024);
  EXPECT_EQ(on.adaptive_step.max_motion, kInfinity);
  EXPECT_TRUE(on.adaptive_step.reject_fallbacks);
  j["adaptive_time_step"] = parse_text(R"({"min_step": 1e-5, "max_motion": 0.002, "reject_fallbacks": false,
                                           "grow_after": 3, "max_correction": 1e-4})");
  const Scene set = SceneFixture(j).load();
  EXPECT_TRUE(set.adaptive_step.enabled);
  EXPECT_DOUBLE_EQ(set.adaptive_step.min_step, 1e-5);
  EXPECT_DOUBLE_EQ(set.adaptive_step.max_motion, 0.002);
  EXPECT_FALSE(set.adaptive_step.reject_fallbacks);
  EXPECT_EQ(set.adaptive_step.grow_after, 3);
  EXPECT_DOUBLE_EQ(set.adaptive_step.max_correction, 1e-4);
  EXPECT_TRUE(set.warnings.empty());
  j["adaptive_time_step"] = parse_text(R"({"enabled": false, "min_step": 1e-5})");
  EXPECT_FALSE(SceneFixture(j).load().adaptive_step.enabled);
}

TEST(SceneParser, StyleAIgnoresDurationWithWarning) {
  Json::Value j = base_scene();
  j.removeMember("end_time");
  j["duration"] = 20;
  SceneFixture f(j);
  const Scene s = f.load();
  EXPECT_TRUE(std::isinf(s.end_time));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("duration"), std::string::npos);
  EXPECT_NE(s.warnings[0].find("ignored"), std::string::npos);
  EXPECT_NE(s.warnings[0].find(f.scene_path), std::string::npos);
}

TEST(SceneParser, CommentsAllowed) {
  std::string text = to_text(base_scene());
  text = "// a scene\n" + text.substr(0, 1) + "/* block */\n" + text.substr(1);
  SceneFixture f(text);
  EXPECT_NO_THROW(f.load());
}

// --- malformed scenes -------------------------------------------------------------------------------------------

struct BadCase {
  const char* name;
  std::function<void(Json::Value&)> mutate;
  const char* key_path;  // must appear in the message, after the file name
  const char* problem;   // must appear in the message too
};

Json::Value& material0(Json::Value& j) { return j["cloths"][0]["materials"][0]; }
Json::Value& remeshing0(Json::Value& j) { return j["cloths"][0]["remeshing"]; }

const std::vector<BadCase>& bad_cases() {
  static const std::vector<BadCase> cases = {
      {"poisson_half", [](Json::Value& j) { material0(j)["poisson_ratio"] = 0.5; },
       "cloths[0].materials[0].poisson_ratio", "must be in [0, 0.5), got 0.5"},
      {"poisson_negative", [](Json::Value& j) { material0(j)["poisson_ratio"] = -0.1; },
       "cloths[0].materials[0].poisson_ratio", "got -0.1"},
      {"thickness_negative", [](Json::Value& j) { material0(j)["thickness"] = -1e-4; },
       "cloths[0].materials[0].thickness", "must be > 0"},
      {"thickness_missing", [](Json::Value& j) { material0(j).removeMember("thickness"); },
       "cloths[0].materials[0].thickness", "required"},
      {"density_negative", [](Json::Value& j) { material0(j)["density"] = -800; },
       "cloths[0].materials[0].density", "must be >= 0"},
      {"modulus_string", [](Json::Value& j) { material0(j)["elastic_modulus"] = "4 GPa"; },
       "cloths[0].materials[0].elastic_modulus", "must be a number, got a string"},
      {"modulus_negative", [](Json::Value& j) { material0(j)["elastic_modulus"] = -1; },
       "cloths[0].materials[0].elastic_modulus", "must be >= 0"},
      {"modulus_nan", [](Json::Value& j) { material0(j)["elastic_modulus"] = std::nan(""); },
       "cloths[0].materials[0].elastic_modulus", "NaN"},
      {"modulus_inf", [](Json::Value& j) { material0(j)["elastic_modulus"] = INFINITY; },
       "cloths[0].materials[0].elastic_modulus", "must be finite"},
      {"damping_negative", [](Json::Value& j) { material0(j)["damping"] = -1e-3; },
       "cloths[0].materials[0].damping", "must be >= 0"},
      {"strain_limits_reversed", [](Json::Value& j) { material0(j)["strain_limits"] = parse_text("[1.1, 0.9]"); },
       "cloths[0].materials[0].strain_limits", "larger than max"},
      {"materials_empty", [](Json::Value& j) { j["cloths"][0]["materials"] = Json::Value(Json::arrayValue); },
       "cloths[0].materials", "at least one material"},
      {"frame_steps_zero", [](Json::Value& j) { j["frame_steps"] = 0; }, "frame_steps", "must be >= 1, got 0"},
      {"frame_steps_fraction", [](Json::Value& j) { j["frame_steps"] = 2.5; }, "frame_steps", "integer"},
      {"frame_time_zero", [](Json::Value& j) { j["frame_time"] = 0; }, "frame_time", "must be > 0"},
      {"timestep_negative",
       [](Json::Value& j) {
         j.removeMember("frame_time");
         j["timestep"] = -1e-3;
       },
       "timestep", "must be > 0"},
      {"no_timing",
       [](Json::Value& j) {
         j.removeMember("frame_time");
         j.removeMember("frame_steps");
         j.removeMember("end_time");
       },
       "", "no time step"},
      {"size_min_above_max", [](Json::Value& j) { remeshing0(j)["size"] = parse_text("[0.1, 0.01]"); },
       "cloths[0].remeshing.size", "larger than max"},
      {"size_negative", [](Json::Value& j) { remeshing0(j)["size"] = parse_text("[-0.1, 0.01]"); },
       "cloths[0].remeshing.size[0]", "must be > 0"},
      {"size_wrong_length", [](Json::Value& j) { remeshing0(j)["size"] = parse_text("[0.1]"); },
       "cloths[0].remeshing.size", "array of 2"},
      {"size_missing_with_remeshing", [](Json::Value& j) { remeshing0(j).removeMember("size"); },
       "cloths[0].remeshing.size", "required while the remeshing module is enabled"},
      {"aspect_missing_with_remeshing", [](Json::Value& j) { remeshing0(j).removeMember("aspect_min"); },
       "cloths[0].remeshing.aspect_min", "required"},
      {"compression_missing_with_remeshing",
       [](Json::Value& j) { remeshing0(j).removeMember("refine_compression"); },
       "cloths[0].remeshing.refine_compression", "required"},
      {"remeshing_object_missing", [](Json::Value& j) { j["cloths"][0].removeMember("remeshing"); },
       "cloths[0].remeshing.size", "required"},
      {"refine_fracture_missing_with_toughness", [](Json::Value& j) { material0(j)["toughness"] = 4e7; },
       "cloths[0].remeshing.refine_fracture", "toughness > 0"},
      {"toughness_negative", [](Json::Value& j) { material0(j)["toughness"] = -1e7; },
       "cloths[0].materials[0].toughness", "must be >= 0"},
      {"toughness_nan", [](Json::Value& j) { material0(j)["toughness"] = std::nan(""); },
       "cloths[0].materials[0].toughness", "NaN"},
      {"toughness_inf", [](Json::Value& j) { material0(j)["toughness"] = INFINITY; },
       "cloths[0].materials[0].toughness", "must be finite"},
      {"fracture_bending_mult_negative", [](Json::Value& j) { material0(j)["fracture_bending_mult"] = -0.5; },
       "cloths[0].materials[0].fracture_bending_mult", "must be >= 0"},
      {"fracture_bending_mult_inf", [](Json::Value& j) { material0(j)["fracture_bending_mult"] = INFINITY; },
       "cloths[0].materials[0].fracture_bending_mult", "must be finite"},
      {"max_cracks_negative", [](Json::Value& j) { j["magic"]["max_cracks"] = -1; }, "magic.max_cracks",
       "must be >= 0"},
      {"max_cracks_fraction", [](Json::Value& j) { j["magic"]["max_cracks"] = 2.5; }, "magic.max_cracks",
       "integer"},
      {"zone_rings_zero", [](Json::Value& j) { j["fracture"]["zone_rings"] = 0; }, "fracture.zone_rings",
       "must be in [1, 20], got 0"},
      {"zone_rings_nan", [](Json::Value& j) { j["fracture"]["zone_rings"] = std::nan(""); }, "fracture.zone_rings",
       ""},
      {"fracture_substepping_not_bool", [](Json::Value& j) { j["fracture"]["substepping"] = "yes"; },
       "fracture.substepping", ""},
      {"substep_openings_unknown", [](Json::Value& j) { j["fracture"]["substep_openings"] = "all"; },
       "fracture.substep_openings", "must be \"one\" or \"independent\", got \"all\""},
      {"virtual_iterations_zero", [](Json::Value& j) { j["fracture"]["virtual_iterations"] = 0; },
       "fracture.virtual_iterations", "must be in [1, 50], got 0"},
      {"substep_openings_not_string", [](Json::Value& j) { j["fracture"]["substep_openings"] = 1; },
       "fracture.substep_openings", ""},
      {"handle_motion_out_of_range", [](Json::Value& j) { j["handles"][0]["motion"] = 5; }, "handles[0].motion",
       "out of range"},
      {"handle_cloth_out_of_range", [](Json::Value& j) { j["handles"][0]["cloth"] = 1; }, "handles[0].cloth",
       "out of range"},
      {"handle_type_unknown", [](Json::Value& j) { j["handles"][0]["type"] = "magnet"; }, "handles[0].type",
       "unknown handle type \"magnet\""},
      {"handle_without_nodes", [](Json::Value& j) { j["handles"][0].removeMember("nodes"); }, "handles[0].nodes",
       "required"},
      {"handle_negative_node", [](Json::Value& j) { j["handles"][0]["nodes"][1] = -2; }, "handles[0].nodes[1]",
       "must be >= 0"},
      {"glue_three_nodes",
       [](Json::Value& j) {
         j["handles"][0]["type"] = "glue";
         j["handles"][0].removeMember("motion");
         j["handles"][0]["nodes"].append(2);
       },
       "handles[0].nodes", "exactly 2"},
      {"handle_end_before_start",
       [](Json::Value& j) {
         j["handles"][0]["start_time"] = 2;
         j["handles"][0]["end_time"] = 1;
       },
       "handles[0].end_time", "before start_time"},
      {"obstacle_motion_out_of_range", [](Json::Value& j) { j["obstacles"][0]["motion"] = 1; },
       "obstacles[0].motion", "out of range"},
      {"obstacle_proxy_unknown", [](Json::Value& j) { j["obstacles"][0]["proxy"] = "wall"; },
       "obstacles[0].proxy", "unknown collision proxy"},
      {"obstacle_pattern_without_conversion", [](Json::Value& j) { j["obstacles"] = "sheet.obj"; }, "obstacles",
       "integer conversion"},
      {"obstacle_pattern_bad_conversion", [](Json::Value& j) { j["obstacles"] = "obs%s.obj"; }, "obstacles",
       "integer conversion"},
      {"mesh_missing", [](Json::Value& j) { j["cloths"][0]["mesh"] = "nowhere.obj"; }, "cloths[0].mesh",
       "not found"},
      {"mesh_not_string", [](Json::Value& j) { j["cloths"][0]["mesh"] = 3; }, "cloths[0].mesh", "must be a string"},
      {"zero_rotation_axis", [](Json::Value& j) { j["cloths"][0]["transform"]["rotate"] = parse_text("[30, 0, 0, 0]"); },
       "cloths[0].transform.rotate", "axis is zero"},
      {"cloth_scale_zero", [](Json::Value& j) { j["cloths"][0]["transform"]["scale"] = 0; },
       "cloths[0].transform.scale", "must be > 0"},
      {"gravity_two_numbers", [](Json::Value& j) { j["gravity"] = parse_text("[0, -9.8]"); }, "gravity",
       "array of 3"},
      {"gravity_nan", [](Json::Value& j) { j["gravity"][1] = std::nan(""); }, "gravity[1]", "NaN"},
      {"keyframes_not_increasing", [](Json::Value& j) { j["motions"][0][1]["time"] = 0; }, "motions[0][1].time",
       "must increase"},
      {"keyframe_without_time", [](Json::Value& j) { j["motions"][0][0].removeMember("time"); },
       "motions[0][0].time", "required"},
      {"motion_empty", [](Json::Value& j) { j["motions"][0] = Json::Value(Json::arrayValue); }, "motions[0]",
       "at least one keyframe"},
      {"motfile_form", [](Json::Value& j) { j["motions"] = parse_text(R"({"motfile": "a.mot", "fps": 30})"); },
       "motions", "not supported"},
      {"morphs", [](Json::Value& j) { j["morphs"] = parse_text(R"([{"cloth": 0}])"); }, "morphs", "not supported"},
      {"disable_not_array", [](Json::Value& j) { j["disable"] = "plasticity"; }, "disable", "must be an array"},
      {"disable_entry_not_string", [](Json::Value& j) { j["disable"] = parse_text("[1]"); }, "disable[0]",
       "must be a string"},
      {"friction_negative", [](Json::Value& j) { j["friction"] = -0.1; }, "friction", "must be >= 0"},
      {"magic_bool_as_number", [](Json::Value& j) { j["magic"]["add_jitter"] = 1; }, "magic.add_jitter",
       "true or false"},
      {"wind_not_object", [](Json::Value& j) { j["wind"] = 3; }, "wind", "must be an object"},
      {"aspect_above_one", [](Json::Value& j) { remeshing0(j)["aspect_min"] = 2; }, "cloths[0].remeshing.aspect_min",
       "must be in [0, 1]"},
      {"no_cloths", [](Json::Value& j) { j.removeMember("cloths"); }, "cloths", "required"},
      {"adaptive_not_object", [](Json::Value& j) { j["adaptive_time_step"] = 3; }, "adaptive_time_step",
       "must be an object"},
      {"adaptive_min_step_negative", [](Json::Value& j) { j["adaptive_time_step"]["min_step"] = -1e-3; },
       "adaptive_time_step.min_step", "must be >= 0"},
      {"adaptive_min_step_above_step", [](Json::Value& j) { j["adaptive_time_step"]["min_step"] = 0.02; },
       "adaptive_time_step.min_step", "must not exceed the scene's time step (0.01 s)"},
      {"adaptive_max_motion_zero", [](Json::Value& j) { j["adaptive_time_step"]["max_motion"] = 0; },
       "adaptive_time_step.max_motion", "must be > 0"},
      {"fracture_max_rings_below_rings", [](Json::Value& j) { j["fracture"] = parse_text(R"({"zone_rings": 5,
                                                                                            "max_zone_rings": 4})"); },
       "fracture.max_zone_rings", "in [5, 40]"},
      {"fracture_support_stress_zero", [](Json::Value& j) { j["fracture"]["support_stress"] = 0; },
       "fracture.support_stress", "must be > 0"},
      {"adaptive_max_correction_negative", [](Json::Value& j) { j["adaptive_time_step"]["max_correction"] = -1; },
       "adaptive_time_step.max_correction", "must be > 0"},
      {"adaptive_grow_after_zero", [](Json::Value& j) { j["adaptive_time_step"]["grow_after"] = 0; },
       "adaptive_time_step.grow_after", ">= 1"},
      {"solver_block_max_nodes_negative", [](Json::Value& j) { j["solver"]["block_max_nodes"] = -1; },
       "solver.block_max_nodes", ">= 0"},
      {"solver_block_max_nodes_fraction", [](Json::Value& j) { j["solver"]["block_max_nodes"] = 2.5; },
       "solver.block_max_nodes", "integer"},
      {"solver_pcg_tolerance_one", [](Json::Value& j) { j["solver"]["pcg_tolerance"] = 1; }, "solver.pcg_tolerance",
       "must be in (0, 1)"},
  };
  return cases;
}

TEST(SceneParserErrors, EachMalformedSceneNamesFileAndKeyPath) {
  ASSERT_GE(bad_cases().size(), 15u);
  for (const BadCase& c : bad_cases()) {
    SCOPED_TRACE(c.name);
    Json::Value j = base_scene();
    c.mutate(j);
    SceneFixture f(j);
    const std::string message = error_of(f);
    ASSERT_FALSE(message.empty()) << "no InputError";
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(f.scene_path + ":", 0), 0u) << message;
    const std::string where = std::string(c.key_path).empty() ? "" : f.scene_path + ": " + c.key_path + ":";
    EXPECT_NE(message.find(where), std::string::npos) << message;
    EXPECT_NE(message.find(c.problem), std::string::npos) << message;
  }
}

TEST(SceneParserErrors, ExactMessageFormat) {
  Json::Value j = base_scene();
  material0(j)["poisson_ratio"] = 0.5;
  SceneFixture f(j);
  EXPECT_EQ(error_of(f), f.scene_path + ": cloths[0].materials[0].poisson_ratio: must be in [0, 0.5), got 0.5");
}

TEST(SceneParserErrors, RequirementsLiftedWhenModuleDisabled) {
  Json::Value j = base_scene();
  remeshing0(j).removeMember("size");
  remeshing0(j).removeMember("aspect_min");
  j["disable"] = parse_text(R"(["remeshing"])");
  SceneFixture f(j);
  const Scene s = f.load();
  EXPECT_FALSE(s.enabled("remeshing"));
  EXPECT_FALSE(s.cloths[0].remeshing.has_size);

  Json::Value k = base_scene();
  material0(k)["toughness"] = 4e7;
  k["disable"] = parse_text(R"(["fracture"])");
  SceneFixture g(k);
  EXPECT_NO_THROW(g.load());

  Json::Value l = base_scene();
  material0(l)["toughness"] = 4e7;
  remeshing0(l)["refine_fracture"] = 0.4;
  SceneFixture h(l);
  const Scene t = h.load();
  EXPECT_TRUE(t.enabled("fracture"));
  EXPECT_DOUBLE_EQ(t.cloths[0].remeshing.refine_fracture, 0.4);
  EXPECT_DOUBLE_EQ(t.cloths[0].materials[0].toughness, 4e7);
}

TEST(SceneParserErrors, SyntaxErrorGivesFileLineColumn) {
  SceneFixture f(std::string("{\n  \"frame_time\": 0.04,\n  \"cloths\": ]\n}\n"));
  const std::string message = error_of(f);
  EXPECT_EQ(message.rfind(f.scene_path + ":3:13: ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

TEST(SceneParserErrors, DuplicateKeyAndTrailingGarbage) {
  SceneFixture dup(std::string("{\"frame_time\": 1, \"frame_time\": 2}"));
  EXPECT_NE(error_of(dup).find("Duplicate key"), std::string::npos);
  SceneFixture extra(to_text(base_scene()) + " }");
  EXPECT_EQ(error_of(extra).rfind(extra.scene_path + ":", 0), 0u);
}

TEST(SceneParserErrors, TopLevelMustBeObject) {
  SceneFixture f(std::string("[1, 2]"));
  EXPECT_NE(error_of(f).find("top level must be a JSON object"), std::string::npos);
  EXPECT_THROW(load_scene((f.dir.path() / "missing.json").string()), InputError);
  EXPECT_THROW(load_scene(f.dir.path().string()), InputError);  // a folder, not a file
}

TEST(SceneParserErrors, MissingMeshListsPathsTried) {
  Json::Value j = base_scene();
  j["cloths"][0]["mesh"] = "meshes/nowhere.obj";
  SceneFixture f(j);
  const std::string message = error_of(f);
  EXPECT_NE(message.find((f.dir.path() / "meshes/nowhere.obj").lexically_normal().string()), std::string::npos);
  EXPECT_NE(message.find((f.dir.path().parent_path() / "meshes/nowhere.obj").string()), std::string::npos);
}

// --- warnings ---------------------------------------------------------------------------------------------------

bool has_warning(const Scene& s, const std::string& a, const std::string& b = "") {
  for (const std::string& w : s.warnings)
    if (w.find(a) != std::string::npos && w.find(b) != std::string::npos) return true;
  return false;
}

TEST(SceneParserWarnings, UnknownKeysNamedByPath) {
  Json::Value j = base_scene();
  j["colour"] = "red";
  material0(j)["stiffness"] = 3;
  j["magic"]["turbo"] = true;
  j["handles"][0]["strength"] = 2;
  j["motions"][0][1]["transform"]["shear"] = 1;
  SceneFixture f(j);
  const Scene s = f.load();
  EXPECT_EQ(s.warnings.size(), 5u);
  EXPECT_TRUE(has_warning(s, f.scene_path + ": colour: unknown key"));
  EXPECT_TRUE(has_warning(s, "cloths[0].materials[0].stiffness: unknown key"));
  EXPECT_TRUE(has_warning(s, "magic.turbo: unknown key"));
  EXPECT_TRUE(has_warning(s, "handles[0].strength: unknown key"));
  EXPECT_TRUE(has_warning(s, "motions[0][1].transform.shear: unknown key"));
}

TEST(SceneParserWarnings, KeysArcsimNeverReadAreIgnored) {
  Json::Value j = base_scene();
  j["remeshing_frames"] = 1;
  material0(j)["bending_factor"] = 10;
  material0(j)["bend_width"] = 0;
  material0(j)["initiation_factor"] = 2;
  SceneFixture f(j);
  const Scene s = f.load();
  EXPECT_EQ(s.warnings.size(), 4u);
  for (const char* key : {"remeshing_frames", "bending_factor", "bend_width", "initiation_factor"})
    EXPECT_TRUE(has_warning(s, key, "ignored")) << key;
  EXPECT_DOUBLE_EQ(s.cloths[0].materials[0].bending_mult, 1);  // bending_factor has no effect
}

TEST(SceneParserWarnings, DisableList) {
  Json::Value j = base_scene();
  j["disable"] = parse_text(R"(["popfilter", "", "bogus"])");
  SceneFixture f(j);
  const Scene s = f.load();
  EXPECT_FALSE(s.enabled("popfilter"));
  EXPECT_TRUE(s.enabled("collision"));
  ASSERT_EQ(s.warnings.size(), 1u);  // "" is silently fine
  EXPECT_TRUE(has_warning(s, "disable[2]", "\"bogus\""));
}

// --- handles, obstacles, magic ---------------------------------------------------------------------------------

TEST(SceneParser, HandleTypesAndFields) {
  Json::Value j = base_scene();
  j["handles"] = parse_text(R"([
    {"label": 4, "motion": 0, "start_time": 1, "end_time": 2, "fade_time": 0.5},
    {"type": "circle", "label": 2, "circumference": 0.5, "u": [0.1, 0.2], "center": [0, 0, 1],
     "axis0": [1, 0, 0], "axis1": [0, 0, 1]},
    {"type": "glue", "nodes": [1, 2]},
    {"type": "soft", "center": [0.5, 0.5, 0], "radius": 0.1, "motion": 0},
    {"label": 3, "nodes": [7]}
  ])");
  SceneFixture f(j);
  const Scene s = f.load();
  ASSERT_EQ(s.handles.size(), 5u);
  EXPECT_EQ(s.handles[0].label, 4);
  EXPECT_TRUE(s.handles[0].nodes.empty());
  EXPECT_DOUBLE_EQ(s.handles[0].start_time, 1);
  EXPECT_DOUBLE_EQ(s.handles[0].end_time, 2);
  EXPECT_DOUBLE_EQ(s.handles[0].fade_time, 0.5);
  EXPECT_EQ(s.handles[1].type, "circle");
  EXPECT_DOUBLE_EQ(s.handles[1].circumference, 0.5);
  EXPECT_TRUE(s.handles[1].u.isApprox(Vec2(0.1, 0.2)));
  EXPECT_TRUE(s.handles[1].axis1.isApprox(Vec3(0, 0, 1)));
  EXPECT_EQ(s.handles[2].type, "glue");
  EXPECT_EQ(s.handles[2].nodes, (std::vector<int>{1, 2}));
  EXPECT_EQ(s.handles[3].type, "soft");
  EXPECT_DOUBLE_EQ(s.handles[3].radius, 0.1);
  EXPECT_EQ(s.handles[3].motion, 0);
  // label wins over nodes, as in ARCSim, with a warning.
  EXPECT_TRUE(s.handles[4].nodes.empty());
  EXPECT_TRUE(has_warning(s, "handles[4].nodes", "label"));
}

TEST(SceneParser, ObstaclePatternLoadsNumberedFilesAndMotions) {
  Json::Value j = base_scene();
  j["obstacles"] = "obs/part_%02d.obj";
  j["motions"].append(j["motions"][0]);
  SceneFixture f(j);
  for (int i = 0; i < 3; ++i) f.dir.write("obs/part_0" + std::to_string(i) + ".obj", kSheetObj);
  f.dir.write("obs/part_04.obj", kSheetObj);  // after the gap: not loaded
  const Scene s = f.load();
  ASSERT_EQ(s.obstacles.size(), 3u);
  EXPECT_EQ(fs::path(s.obstacles[2].mesh), f.dir.path() / "obs/part_02.obj");
  EXPECT_EQ(s.obstacles[0].motion, 0);
  EXPECT_EQ(s.obstacles[1].motion, 1);
  EXPECT_EQ(s.obstacles[2].motion, -1);  // only two motions

  Json::Value k = base_scene();
  k["obstacles"] = "obs/none_%d.obj";
  SceneFixture g(k);
  const std::string message = error_of(g);
  EXPECT_NE(message.find("obstacles: file \"obs/none_0.obj\" not found"), std::string::npos) << message;
}

TEST(SceneParser, FractureSubstepOpenings) {
  Json::Value j = base_scene();
  {
    SceneFixture f(j);
    EXPECT_TRUE(f.load().fracture.independent_openings);  // the default
  }
  j["fracture"]["substep_openings"] = "one";
  {
    SceneFixture f(j);
    EXPECT_FALSE(f.load().fracture.independent_openings);  // the strict Algorithm 1
  }
  j["fracture"]["substep_openings"] = "independent";
  SceneFixture f(j);
  EXPECT_TRUE(f.load().fracture.independent_openings);
}

// `solver`: the defaults of physics/solver_settings.hpp unless given.
TEST(SceneParser, SolverSettings) {
  const Scene defaults = SceneFixture(base_scene()).load();
  EXPECT_EQ(defaults.solver.block_max_nodes, SolverSettings().block_max_nodes);
  EXPECT_EQ(defaults.solver.pcg_min_nodes, SolverSettings().pcg_min_nodes);
  Json::Value j = base_scene();
  j["solver"] = parse_text(R"({"block_max_nodes": 0, "pcg_min_nodes": 5000, "pcg_tolerance": 1e-8,
                               "pcg_max_iterations": 20})");
  const Scene set = SceneFixture(j).load();
  EXPECT_EQ(set.solver.block_max_nodes, 0);
  EXPECT_EQ(set.solver.pcg_min_nodes, 5000);
  EXPECT_DOUBLE_EQ(set.solver.pcg_tolerance, 1e-8);
  EXPECT_EQ(set.solver.pcg_max_iterations, 20);
  EXPECT_TRUE(set.warnings.empty());
}

TEST(SceneParser, MagicAndWind) {
  Json::Value j = base_scene();
  j["magic"] = parse_text(R"({"repulsion_thickness": 1e-4, "collision_stiffness": 1e13, "max_cracks": 400,
                              "add_jitter": true, "relax_method": 1})");
  j["wind"] = parse_text(R"({"density": 0, "velocity": [10, 0, 0], "drag": 2})");
  SceneFixture f(j);
  const Scene s = f.load();
  EXPECT_DOUBLE_EQ(s.magic.repulsion_thickness, 1e-4);
  EXPECT_DOUBLE_EQ(s.magic.projection_thickness, 1e-5);  // 0.1 x the given repulsion thickness
  EXPECT_DOUBLE_EQ(s.magic.collision_stiffness, 1e13);
  EXPECT_EQ(s.magic.max_cracks, 400);
  EXPECT_TRUE(s.magic.add_jitter);
  EXPECT_EQ(s.magic.relax_method, 1);
  EXPECT_DOUBLE_EQ(s.wind.density, 0);
  EXPECT_DOUBLE_EQ(s.wind.drag, 2);
  EXPECT_TRUE(s.wind.velocity.isApprox(Vec3(10, 0, 0)));
}

TEST(SceneParser, ReferenceShapes) {
  Json::Value j = base_scene();
  j["cloths"][0]["reference"] = "sphere";
  SceneFixture f(j);
  EXPECT_EQ(f.load().cloths[0].reference, "sphere");

  Json::Value k = base_scene();
  k["cloths"][0]["reference"] = "rest.obj";
  SceneFixture g(k);
  g.dir.write("rest.obj", kSheetObj);
  const Scene s = g.load();
  EXPECT_TRUE(s.cloths[0].reference_is_mesh);
  EXPECT_EQ(fs::path(s.cloths[0].reference), g.dir.path() / "rest.obj");
  EXPECT_EQ(s.referenced_files.size(), 2u);

  Json::Value l = base_scene();
  l["cloths"][0]["reference"] = "missing-rest.obj";
  SceneFixture h(l);
  EXPECT_NE(error_of(h).find("cloths[0].reference: file"), std::string::npos);
}

// --- path resolution --------------------------------------------------------------------------------------------

TEST(SceneParserPaths, SceneFolderThenParentThenCwd) {
  TempDir root;
  Json::Value j = base_scene();
  j["cloths"][0]["mesh"] = "meshes/m.obj";
  j["obstacles"][0]["mesh"] = "meshes/o.obj";
  const std::string scene = root.write("conf/scene.json", to_text(j));
  root.write("work/meshes/m.obj", kSheetObj);  // current working directory
  root.write("meshes/m.obj", kSheetObj);       // scene folder's parent
  root.write("work/meshes/o.obj", kSheetObj);  // only in the working directory
  ScopedCwd cwd(root.path() / "work");
  {
    const Scene s = load_scene(scene);
    EXPECT_EQ(fs::path(s.cloths[0].mesh), root.path() / "meshes/m.obj");  // the parent beats the cwd
    EXPECT_EQ(s.obstacles[0].mesh, "meshes/o.obj");                      // found relative to the cwd
  }
  root.write("conf/meshes/m.obj", kSheetObj);  // the scene folder beats both
  const Scene s = load_scene(scene);
  EXPECT_EQ(fs::path(s.cloths[0].mesh), root.path() / "conf/meshes/m.obj");
  EXPECT_EQ(s.referenced_files.size(), 2u);

  const std::vector<std::string> tried = scene_path_candidates("meshes/x.obj", scene);
  ASSERT_EQ(tried.size(), 3u);
  EXPECT_EQ(fs::path(tried[0]), root.path() / "conf/meshes/x.obj");
  EXPECT_EQ(fs::path(tried[1]), root.path() / "meshes/x.obj");
  EXPECT_EQ(tried[2], "meshes/x.obj");
}

TEST(SceneParserPaths, AbsolutePathUsedAsIs) {
  TempDir other;
  const std::string mesh = other.write("abs.obj", kSheetObj);
  Json::Value j = base_scene();
  j["cloths"][0]["mesh"] = mesh;
  SceneFixture f(j);
  EXPECT_EQ(f.load().cloths[0].mesh, mesh);
  EXPECT_EQ(scene_path_candidates(mesh, f.scene_path), std::vector<std::string>{mesh});
}

// --- materials ---------------------------------------------------------------------------------------------------

const char* const kDdeFile = R"(// a tiny DDE file
{
  "density": 0.1,
  "stretching": [[500, 100, 400, 300], [1,1,1,1], [1,1,1,1], [1,1,1,1], [1,1,1,1], [1,1,1,1]],
  "bending": [[1e-3, 2e-3, 3e-3, 4e-3, 5e-3], [2e-3, 0, 0, 0, 0], [3e-3, 0, 0, 0, 0]]
})";

TEST(SceneParserMaterials, DataDrivenFile) {
  Json::Value j = base_scene();
  material0(j) = parse_text(R"({"data": "dde.json", "thicken": 2, "density_mult": 3, "yield_curv": 200,
                                "strain_limits": [0.95, 1.05], "thickness": 1e-3})");
  SceneFixture f(j);
  f.dir.write("dde.json", kDdeFile);
  const Scene s = f.load();
  const Material& m = s.cloths[0].materials[0];
  EXPECT_TRUE(m.data_driven);
  EXPECT_EQ(m.name, "dde");
  EXPECT_DOUBLE_EQ(m.dde_area_density, 0.1);
  EXPECT_DOUBLE_EQ(m.thicken, 2);
  EXPECT_DOUBLE_EQ(m.density_mult, 3);
  EXPECT_DOUBLE_EQ(m.area_density(0), 0.6);
  EXPECT_DOUBLE_EQ(m.dde_stretching[0][1], 100);
  EXPECT_DOUBLE_EQ(m.dde_bending[2][0], 3e-3);
  EXPECT_DOUBLE_EQ(m.dde_bending[0][4], 5e-3);
  EXPECT_DOUBLE_EQ(m.yield_curv, 200);
  EXPECT_TRUE(m.strain_limits.isApprox(Vec2(0.95, 1.05)));
  EXPECT_TRUE(s.enabled("plasticity"));
  EXPECT_TRUE(s.enabled("strainlimiting"));
  EXPECT_TRUE(has_warning(s, "cloths[0].materials[0].thickness", "isotropic"));
  EXPECT_EQ(s.referenced_files.size(), 2u);
}

TEST(SceneParserMaterials, DataDrivenFileShapeErrorsNameTheDataFile) {
  struct Case {
    const char* text;
    const char* key;
  };
  const Case cases[] = {
      {R"({"density": 0.1, "stretching": [[1,0,1,1]], "bending": [[0,0,0,0,0],[0,0,0,0,0],[0,0,0,0,0]]})",
       "stretching: must have 6 rows"},
      {R"({"density": 0.1, "stretching": [[1,0,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1],[1,1,1]],
           "bending": [[0,0,0,0,0],[0,0,0,0,0],[0,0,0,0,0]]})",
       "stretching[5]: must be an array of 4"},
      {R"({"density": 0.1, "stretching": [[1,0,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1]],
           "bending": [[0,0,0,0,0],[0,0,0,0,0]]})",
       "bending: must have 3 rows"},
      {R"({"stretching": [[1,0,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1]],
           "bending": [[0,0,0,0,0],[0,0,0,0,0],[0,0,0,0,0]]})",
       "density: required"},
      {R"({"density": 0.1, "stretching": [[-1,0,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1],[1,1,1,1]],
           "bending": [[0,0,0,0,0],[0,0,0,0,0],[0,0,0,0,0]]})",
       "stretching[0]: small-strain sample"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.key);
    Json::Value j = base_scene();
    material0(j) = parse_text(R"({"data": "bad.json"})");
    SceneFixture f(j);
    const std::string data = f.dir.write("bad.json", c.text);
    const std::string message = error_of(f);
    EXPECT_EQ(message.rfind(data + ": " + c.key, 0), 0u) << message;
    EXPECT_NE(message.find(f.scene_path + ": cloths[0].materials[0].data"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
}

TEST(SceneParserMaterials, OurIsotropicFileGivesDefaultsInlineKeysOverride) {
  Json::Value j = base_scene();
  material0(j) = parse_text(R"({"data": "glassy.json", "thickness": 2e-3, "damping": 1e-5})");
  SceneFixture f(j);
  f.dir.write("glassy.json", R"(// ours
    {"name": "glassy", "thickness": 3e-3, "density": 2500, "elastic_modulus": 70e9, "poisson_ratio": 0.22,
     "toughness": 45e6, "yield_stress": 1e8, "flow_rate": 1e-5, "sparkle": 1})");
  Json::Value& rem = j["cloths"][0]["remeshing"];
  rem["refine_fracture"] = 0.3;
  SceneFixture g(j);
  g.dir.write("glassy.json", R"({"thickness": 3e-3, "density": 2500, "elastic_modulus": 70e9,
     "poisson_ratio": 0.22, "toughness": 45e6, "yield_stress": 1e8, "flow_rate": 1e-5, "sparkle": 1})");
  // Without refine_fracture the file's toughness makes the scene invalid, and the message says so.
  EXPECT_NE(error_of(f).find("refine_fracture"), std::string::npos);
  const Scene s = g.load();
  const Material& m = s.cloths[0].materials[0];
  EXPECT_FALSE(m.data_driven);
  EXPECT_DOUBLE_EQ(m.thickness, 2e-3);  // inline wins
  EXPECT_DOUBLE_EQ(m.density, 2500);    // from the file
  EXPECT_DOUBLE_EQ(m.youngs_modulus, 70e9);
  EXPECT_DOUBLE_EQ(m.poisson_ratio, 0.22);
  EXPECT_DOUBLE_EQ(m.toughness, 45e6);
  EXPECT_DOUBLE_EQ(m.yield_stress, 1e8);
  EXPECT_DOUBLE_EQ(m.flow_rate, 1e-5);
  EXPECT_DOUBLE_EQ(m.damping, 1e-5);
  EXPECT_TRUE(s.enabled("plasticity"));  // stretching plasticity counts
  EXPECT_TRUE(s.enabled("fracture"));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], (g.dir.path() / "glassy.json").string() + ": sparkle: unknown key, ignored");
}

TEST(SceneParserMaterials, BadValueInOurFileNamesTheFile) {
  Json::Value j = base_scene();
  material0(j) = parse_text(R"({"data": "soft.json"})");
  SceneFixture f(j);
  const std::string data = f.dir.write("soft.json", R"({"thickness": 1e-3, "poisson_ratio": 0.7})");
  EXPECT_EQ(error_of(f).rfind(data + ": poisson_ratio: must be in [0, 0.5), got 0.7", 0), 0u) << error_of(f);
  EXPECT_THROW(load_material_file(data), InputError);
}

TEST(SceneParserMaterials, LoadMaterialFileRejectsDde) {
  TempDir d;
  const std::string path = d.write("dde.json", kDdeFile);
  try {
    load_material_file(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("data-driven"), std::string::npos);
  }
}

}  // namespace
}  // namespace arcsim
