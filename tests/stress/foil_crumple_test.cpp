// Stress case (issue 14): foil crumpled by a sphere into many self-contacts, with remeshing and plasticity.
// A 20 cm square of household aluminium foil (materials/foil.json: 16 um, E = 69 GPa, yield curvature 61.6 1/m)
// lies on a ring (a torus, 5 cm hole radius, 1 cm tube radius); a 3 cm sphere pushes it down through the hole
// to 15 cm below the ring. The sheet, more than twice as wide as the hole, is drawn through it and gathers into
// folds pressed against each other around the sphere. Remeshed at every frame end, plastic, no fracture.
// In every frame: no NaN, a valid mesh, no intersecting triangle pairs (within the sheet, or with the sphere
// or the ring). And it must really crumple: the sheet ends below the ring, wrapped around the sphere, with many
// non-neighbouring parts of it within the repulsion thickness (1 mm) of each other, and it yields.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "collision/candidates.hpp"
#include "collision/contact_geometry.hpp"
#include "collision/proximity.hpp"
#include "collision/scene_fixtures.hpp"
#include "io/errors.hpp"
#include "io/scene_parser.hpp"
#include "mesh/validate.hpp"
#include "sim/simulation.hpp"
#include "stress/repository.hpp"
#include "support/files.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;
using namespace testing;
using arcsim::testing::TempDir;

// A torus about the z axis: major radius R, tube radius r (m), nu x nv quads split into triangles.
Mesh make_torus(double R, double r, int nu, int nv) {
  std::vector<Vec3> x;
  std::vector<std::array<int, 3>> tris;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
      x.emplace_back((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
    }
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const int a = i * nv + j, b = (i + 1) % nu * nv + j, c = (i + 1) % nu * nv + (j + 1) % nv,
                d = i * nv + (j + 1) % nv;
      tris.push_back({a, b, c});
      tris.push_back({a, c, d});
    }
  std::vector<int> vert_node(x.size());
  for (size_t i = 0; i < x.size(); ++i) vert_node[i] = static_cast<int>(i);
  return Mesh::from_triangles(x, x, vert_node, tris);
}

// The scene: the sphere pressed from touching the sheet to 15 cm below the ring in `press` s, the run lasting
// `end` s, remeshed between size_min and size_max (m). z is up; the ring's top is at z = 1 cm.
std::string foil_scene(const fs::path& root, const fs::path& ring, double press, double end, double size_min,
                       double size_max) {
  const std::string square = (root / "meshes/square.obj").string(), sphere = (root / "meshes/sphere.obj").string(),
                    foil = (root / "materials/foil.json").string();
  return R"({
    "frame_time": 0.01, "frame_steps": 5, "end_time": )" + std::to_string(end) + R"(,
    "cloths": [{"mesh": ")" + square + R"(", "transform": {"scale": 0.2, "translate": [-0.1, -0.1, 0.0115]},
        "materials": [{"data": ")" + foil + R"(", "damping": 1e-4}],
        "remeshing": {"refine_angle": 0.3, "refine_compression": 0.01, "refine_velocity": 1,
                      "size": [)" + std::to_string(size_min) + ", " + std::to_string(size_max) + R"(],
                      "aspect_min": 0.2}}],
    "motions": [[{"time": 0, "transform": {"translate": [0, 0, 0.047]}},
                 {"time": )" + std::to_string(press) + R"(, "transform": {"translate": [0, 0, -0.15]},
                  "velocity": {"translate": [0, 0, 0]}}]],
    "obstacles": [{"mesh": ")" + sphere + R"(", "transform": {"scale": 0.03}, "motion": 0},
                  {"mesh": ")" + ring.string() + R"("}],
    "gravity": [0, 0, -9.8],
    "wind": {"density": 0},
    "disable": ["fracture"]
  })";
}

// Self-contacts of cloth 0 now: vertex-face and edge-edge pairs of the sheet within `thickness` (m) of each
// other that are not material neighbours (proximity's own test, collision/proximity.hpp, on the sheet alone).
int self_contacts(const Simulation& sim, double thickness) {
  ContactGeometry g;
  build_contact_geometry({ContactBody{&sim.cloths[0].mesh, true}}, ContactStage::kBeforeStep, 1e-3, g);
  BvhCache cache;
  ProximityParams params;
  params.thickness = thickness;
  return static_cast<int>(find_proximities(g, cache, params).size());
}

struct FoilRun {
  int frames = 0, crossing = 0, most_self_contacts = 0, most_faces = 0;
  long long impacts = 0, zones = 0, proximities = 0, fallback_zones = 0;
  double plastic_work = 0, highest_end = -1;
  std::string invalid, failure;
};

FoilRun run_foil(const std::string& text) {
  TempDir dir;
  const fs::path path = dir.path / "foil.json";
  std::ofstream(path) << text;
  Simulation sim(load_scene(path.string()));
  FoilRun r;
  try {
    while (!sim.finished()) {
      sim.clear_collision_totals();
      sim.advance_frame();
      ++r.frames;
      const ImpactZoneTotals& t = sim.collision_totals();
      r.impacts += t.impacts;
      r.zones += t.zones;
      r.proximities += t.proximities;
      r.fallback_zones += t.fallback_zones;
      for (double w : sim.plastic_work) r.plastic_work += w;
      r.crossing += count_intersecting_pairs(sim);
      r.most_self_contacts = std::max(r.most_self_contacts, self_contacts(sim, 1e-3));
      r.most_faces = std::max(r.most_faces, static_cast<int>(sim.cloths[0].mesh.faces.size()));
      if (r.invalid.empty()) r.invalid = check_mesh(sim.cloths[0].mesh);
      if (r.invalid.empty()) r.invalid = sim.nonfinite_state();
    }
  } catch (const NumericalError& e) {
    r.failure = e.what();
  }
  for (const Node& n : sim.cloths[0].mesh.nodes) r.highest_end = std::max(r.highest_end, n.x.z());
  std::printf("[ result ] foil: %d frames, up to %d faces, %lld impacts in %lld zones (%lld fallback), %lld "
              "proximity contacts, up to %d self-contacts in a frame, plastic work %.3g J, highest node at the end "
              "z = %.3f m, %d crossing pairs\n",
              r.frames, r.most_faces, r.impacts, r.zones, r.fallback_zones, r.proximities, r.most_self_contacts,
              r.plastic_work, r.highest_end, r.crossing);
  return r;
}

void expect_crumpled_cleanly(const FoilRun& r, int min_self_contacts) {
  EXPECT_EQ(r.failure, "");
  EXPECT_EQ(r.invalid, "");
  EXPECT_EQ(r.crossing, 0) << "intersecting triangle pairs summed over the frames";
  // Drawn through the ring (top at z = 1 cm; the hole is 5 cm in radius, the sheet 20 cm wide).
  EXPECT_LT(r.highest_end, 0);
  EXPECT_GT(r.plastic_work, 0);
  EXPECT_GT(r.impacts, 0);
  EXPECT_GE(r.most_self_contacts, min_self_contacts) << "the sheet did not fold onto itself";
}

fs::path write_ring(const TempDir& dir) {
  const fs::path ring = dir.path / "ring.obj";
  write_plain_obj(make_torus(0.06, 0.01, 32, 8), ring.string());
  return ring;
}

TEST(StressFoil, SpherePushesFoilThroughARingIntoFolds) {
  const fs::path root = repository_root("materials/foil.json");
  ASSERT_FALSE(root.empty()) << "materials/foil.json not found";
  TempDir dir;
  const FoilRun r = run_foil(foil_scene(root, write_ring(dir), 0.2, 0.25, 0.015, 0.04));
  EXPECT_EQ(r.frames, 25);
  expect_crumpled_cleanly(r, 50);
}

// Finer (5 mm to 2 cm) and on to 0.6 s, the folds settling around the sphere.
TEST(StressFoilSlowCheck, FinelyRemeshedFoilThroughARingHoldsToTheEnd) {
  const fs::path root = repository_root("materials/foil.json");
  ASSERT_FALSE(root.empty()) << "materials/foil.json not found";
  TempDir dir;
  const FoilRun r = run_foil(foil_scene(root, write_ring(dir), 0.3, 0.6, 0.005, 0.02));
  EXPECT_EQ(r.frames, 60);
  expect_crumpled_cleanly(r, 200);
}

}  // namespace
}  // namespace arcsim
