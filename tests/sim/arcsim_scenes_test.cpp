// ARCSim 0.3's own cloth scenes run unmodified (remeshing off, as ARCSim's fixed mesh): without NaN or blow-up
// for their first 2 simulated seconds, and, for the collision scenes, with no intersecting triangle pair
// (cloth-cloth, non-adjacent, and cloth-obstacle; exact test) after any frame while the cloth is in contact.
// Skipped where the ARCSim example folder is absent.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "collision/penetration.hpp"
#include "collision/scene_fixtures.hpp"
#include "io/scene_parser.hpp"
#include "sim/simulation.hpp"

namespace arcsim {
namespace {

std::string arcsim_scenes() {
  const char* shared = std::getenv("ARCSIM_SHARED");
  return std::string(shared ? shared : "/work/shared") + "/arcsim-0.3-scenes";
}

std::string param_name(const ::testing::TestParamInfo<const char*>& param) {
  std::string name = param.param;
  for (char& ch : name)
    if (ch == '-') ch = '_';
  return name;
}

// Largest |world length / rest length - 1| over the cloth's edges (rest length in the rest space u).
double max_edge_strain(const Mesh& m) {
  double worst = 0;
  for (const Edge& e : m.edges) {
    const double world = (m.nodes[e.n[0]].x - m.nodes[e.n[1]].x).norm();
    const int f = e.f[0] != kNone ? e.f[0] : e.f[1];
    // The rest length from the rest verts of one adjacent face.
    Vec3 u[2];
    for (int k = 0; k < 2; ++k)
      for (int c = 0; c < 3; ++c)
        if (m.verts[m.faces[f].v[c]].node == e.n[k]) u[k] = m.verts[m.faces[f].v[c]].u;
    worst = std::max(worst, std::abs(world / (u[0] - u[1]).norm() - 1));
  }
  return worst;
}

// The handles' pull on the cloth at the simulation's time: the largest distance (m) of a handled node from
// where its handle holds it, and the sum of the handle springs' forces (N).
struct HandlePull {
  double worst_error = 0;
  Vec3 force = Vec3::Zero();
};
HandlePull handle_pull(const Simulation& sim) {
  std::vector<Motion> motions = sim.scene().motions;
  for (Motion& m : motions) m.finalize();
  HandlePull out;
  for (const Handle& h : sim.handles) {
    const Transform pose = h.motion >= 0 ? motions[h.motion].pose(sim.time()) : Transform();
    for (size_t i = 0; i < h.nodes.size(); ++i) {
      const Vec3 stretch = pose.apply(h.anchors[i]) - sim.cloths[h.cloth].mesh.nodes[h.nodes[i]].x;
      out.worst_error = std::max(out.worst_error, stretch.norm());
      out.force += sim.scene().magic.handle_stiffness * h.strength(sim.time()) * stretch;
    }
  }
  return out;
}

class ArcsimClothScene : public ::testing::TestWithParam<const char*> {};

// Each scene's phenomenon, checked at every frame, with bounds that a blown-up, frozen or torn-loose run fails:
// no triangles intersect, the handled nodes stay near their handles, and
//  - flag (3 m x 2 m, held at the two ends of its pole, in a 10 m/s wind along +x with gravity along +x): it
//    streams downwind, every node beyond the pole and its far edge more than 2.8 m downwind of it (it starts
//    at 45 degrees, 2.1 m). Its camel-knit material stretches a lot: the scene's strain limits [0.95, 1.05]
//    are parsed but strain limiting is not implemented yet, and edges reach 90% stretch next to the held
//    corners (44% a metre away). The bound below only catches a runaway; tighten it with strain limiting.
//  - square, square-pop (1 m paper sheet of 4 triangles held by its corners, which start moving inwards at
//    1 s): paper barely stretches or compresses (below 0.1%), and while it hangs still (before 1 s) the
//    handle springs carry exactly its weight.
TEST_P(ArcsimClothScene, SlowRunsTwoSecondsWithoutRemeshing) {
  const std::string name = GetParam();
  const std::string path = arcsim_scenes() + "/conf/" + name + ".json";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "ARCSim example scenes not found at " << path;
  Scene scene = load_scene(path);
  scene.disabled.insert("remeshing");
  Simulation sim(scene);
  sim.set_end_time(2.0);
  const Mesh& mesh = sim.cloths[0].mesh;
  double mass = 0;
  for (const Node& n : mesh.nodes) mass += n.mass;
  const Vec3 weight = mass * scene.gravity;
  double worst_strain = 0, worst_handle = 0, least_downwind = kInfinity, worst_balance = 0;
  int intersecting = 0;
  while (!sim.finished()) {
    sim.advance_frame();  // throws NumericalError on blow-up
    for (const Node& n : mesh.nodes) ASSERT_TRUE(n.x.allFinite() && n.v.allFinite()) << "frame " << sim.frame();
    worst_strain = std::max(worst_strain, max_edge_strain(mesh));
    const HandlePull pull = handle_pull(sim);
    worst_handle = std::max(worst_handle, pull.worst_error);
    intersecting += testing::count_intersecting_pairs(sim);
    if (name == "flag" && sim.time() > 1.0) {
      // Downwind distance from the pole (through the two handled nodes, along y).
      const double pole = 0.5 * (mesh.nodes[0].x.x() + mesh.nodes[3].x.x());
      double far = -kInfinity;
      for (const Node& n : mesh.nodes) {
        EXPECT_GT(n.x.x(), pole - 0.05) << "frame " << sim.frame();
        far = std::max(far, n.x.x() - pole);
      }
      least_downwind = std::min(least_downwind, far);
    }
    if (name != "flag" && sim.time() > 0.5 && sim.time() < 1.0)
      worst_balance = std::max(worst_balance, (pull.force + weight).norm() / weight.norm());
  }
  EXPECT_NEAR(sim.time(), 2.0, 1e-9);
  std::printf("[ result ] %s: largest edge strain %.3g, handle error %.3g m, far edge %.3g m downwind, force "
              "balance %.3g\n",
              name.c_str(), worst_strain, worst_handle, least_downwind, worst_balance);
  EXPECT_EQ(intersecting, 0);
  if (name == "flag") {
    EXPECT_GT(least_downwind, 2.8);
    EXPECT_LT(worst_strain, 1.0);
    EXPECT_LT(worst_handle, 0.1);  // 1e3 N/m springs holding its weight and the wind's drag
  } else {
    EXPECT_LT(worst_strain, 1e-3);
    EXPECT_LT(worst_balance, 1e-2);
    // The corners lag their inward-moving handles (the paper cannot shorten its edges), by about the 5 cm the
    // handles have moved at 2 s, never more.
    EXPECT_LT(worst_handle, 0.06);
  }
}

INSTANTIATE_TEST_SUITE_P(Arcsim, ArcsimClothScene, ::testing::Values("flag", "square", "square-pop"), param_name);

// How long each scene runs for the intersection check (s), and why that is long enough.
double contact_duration(const std::string& scene) {
  // sphere: the 4-face sheet, held by one edge, swings down onto the sphere (first contact within the
  // repulsion thickness at 0.8 s, measured) and lies on it from then on; 2.5 s includes the first half of the
  // sphere's 1.5 m descent (from 2 s), which drags the sheet down with it.
  if (scene == "sphere") return 2.5;
  // tshirt: released at 1 s from 0.5 m above the box floor; on the floor from 1.24 s (measured), then
  // folding onto itself; the box walls start closing in at 1.5 s. 2 s covers the landing, self-contact and
  // the first push of the walls.
  if (scene == "tshirt") return 2.0;
  // flag: self-contact while it flaps in the wind; square: paper sheet held by its corners whose handles
  // start moving at 1 s. Neither has obstacles.
  return 2.0;
}

class ArcsimCollisionScene : public ::testing::TestWithParam<const char*> {};

TEST_P(ArcsimCollisionScene, SlowNoIntersectionsWithoutRemeshing) {
  const std::string name = GetParam();
  const std::string path = arcsim_scenes() + "/conf/" + name + ".json";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "ARCSim example scenes not found at " << path;
  Scene scene = load_scene(path);
  scene.disabled.insert("remeshing");
  Simulation sim(scene);
  sim.set_end_time(contact_duration(name));
  const double near = scene.magic.repulsion_thickness;
  int intersecting = 0, first_bad = -1, frames_in_contact = 0;
  double first_contact = kInfinity;
  const auto t0 = std::chrono::steady_clock::now();
  while (!sim.finished()) {
    sim.advance_frame();
    const int crossing = testing::count_intersecting_pairs(sim);
    if (crossing > 0 && first_bad < 0) first_bad = sim.frame();
    intersecting += crossing;
    // In contact with an obstacle: a cloth node within the repulsion thickness of an obstacle's surface, or an
    // obstacle node within it of the cloth's (coarse cloths touch obstacles with their faces).
    double closest = kInfinity;
    const testing::ObstacleSurface cloth(sim.cloths[0].mesh);
    for (const Obstacle& o : sim.obstacles) {
      if (!o.active) continue;
      const testing::ObstacleSurface surface(o.mesh);
      for (const Node& n : sim.cloths[0].mesh.nodes) closest = std::min(closest, surface.distance(n.x));
      for (const Node& n : o.mesh.nodes) closest = std::min(closest, cloth.distance(n.x));
    }
    if (closest < near) {
      ++frames_in_contact;
      first_contact = std::min(first_contact, sim.time());
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("[ timing ] %s: %.2f s simulated, %d frames, %.2f s wall (collision %.2f s); obstacle contact from "
              "t = %.2f s in %d frames\n",
              name.c_str(), sim.time(), sim.frame(), seconds, sim.times.collision, first_contact,
              frames_in_contact);
  EXPECT_EQ(intersecting, 0) << "first frame with intersections: " << first_bad;
  // The scenes with obstacles must actually have reached them.
  if (!sim.obstacles.empty()) {
    EXPECT_GT(frames_in_contact, 5);
  }
}

INSTANTIATE_TEST_SUITE_P(Arcsim, ArcsimCollisionScene, ::testing::Values("sphere", "flag", "square", "tshirt"),
                         param_name);

}  // namespace
}  // namespace arcsim
