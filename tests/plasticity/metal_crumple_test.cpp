// conf/metal-crumple.json (issue 6, acceptance 4): an aluminium sheet clamped on its border is dented by a
// sphere that then lifts off. Runs the scene file to its end and checks that the dent is permanent, that the
// plastic state is consistent (volume conserved per face) and that the plastic work per frame is reported; a
// control run with the module off springs back; the remeshing variant (conf/metal-crumple-remesh.json) keeps
// its dent too. About 2 s each optimised, much longer under the sanitizers, hence the Slow suite.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "io/scene_parser.hpp"
#include "plasticity/plastic_tensors.hpp"
#include "sim/simulation.hpp"

namespace arcsim {
namespace {

namespace fs = std::filesystem;

// The repository's conf/ folder (tests run from the repository root; also found next to bin/ or this file).
fs::path project_conf() {
  std::error_code no_throw;
  const fs::path binary = fs::read_symlink("/proc/self/exe", no_throw);
  for (const fs::path& candidate : {fs::path("conf"), binary.parent_path().parent_path() / "conf",
                                    fs::path(__FILE__).parent_path() / "../../conf"})
    if (fs::exists(candidate / "metal-crumple.json", no_throw)) return candidate;
  return {};
}

// Largest downward displacement of the sheet from its flat start (m).
double deepest_dent(const Mesh& mesh) {
  double deepest = 0;
  for (const Node& n : mesh.nodes) deepest = std::max(deepest, -n.x.z());
  return deepest;
}

TEST(MetalCrumpleSlow, DentStaysAfterTheSphereLiftsOff) {
  const fs::path conf = project_conf();
  ASSERT_FALSE(conf.empty()) << "conf/metal-crumple.json not found";
  Simulation sim(load_scene((conf / "metal-crumple.json").string()));
  ASSERT_TRUE(sim.scene().enabled("plasticity"));
  const double h0 = sim.cloths[0].materials[0].thickness;

  double loaded = 0, total_work = 0;
  int frames = 0, frames_with_work = 0;
  while (!sim.finished()) {
    sim.advance_frame();
    ++frames;
    if (sim.time() <= 0.3 + 1e-9) loaded = std::max(loaded, deepest_dent(sim.cloths[0].mesh));
    ASSERT_EQ(sim.plastic_work.size(), 1u);
    const double work = sim.plastic_work[0];
    EXPECT_GE(work, -1e-12) << "frame " << sim.frame();  // the flow rules only release elastic energy
    total_work += work;
    frames_with_work += work > 1e-6 ? 1 : 0;
  }
  EXPECT_EQ(frames, 40);
  const Mesh& mesh = sim.cloths[0].mesh;

  // Unloaded: the sphere is clear of the sheet and the sheet has come to rest.
  double lowest_obstacle = kInfinity;
  for (const Node& n : sim.obstacles[0].mesh.nodes) lowest_obstacle = std::min(lowest_obstacle, n.x.z());
  double highest_node = -kInfinity, fastest = 0;
  for (const Node& n : mesh.nodes) {
    highest_node = std::max(highest_node, n.x.z());
    fastest = std::max(fastest, n.v.norm());
  }
  EXPECT_GT(lowest_obstacle, highest_node + 0.02);
  EXPECT_LT(fastest, 1e-3);

  // The dent: pressed ~2.5 cm, most of it stays (an elastic sheet would spring back flat).
  EXPECT_GT(loaded, 0.02);
  const double kept = deepest_dent(mesh);
  EXPECT_GT(kept, 0.6 * loaded) << "loaded " << loaded << " m, kept " << kept << " m";

  // Plastic state: bending and stretching both yielded; thinning conserves volume face by face
  // (det(P) h / h0 = 1 with P = Fp^-1 the in-plane plastic stretch).
  int bent = 0, stretched = 0;
  for (const Face& f : mesh.faces) {
    bent += f.Sp.norm() > 1 ? 1 : 0;  // 1/m
    const Mat2 Fp2 = face_plastic_stretch_2d(f);
    stretched += (Fp2 - Mat2::Identity()).norm() > 1e-3 ? 1 : 0;
    EXPECT_NEAR(f.thickness / h0 / Fp2.determinant(), 1.0, 1e-9);
    EXPECT_TRUE(f.Fp.allFinite() && f.Sp.allFinite());
  }
  EXPECT_GT(bent, 10);
  EXPECT_GT(stretched, 10);
  EXPECT_GT(frames_with_work, 3);
  EXPECT_GT(total_work, 0.1);  // J
}

TEST(MetalCrumpleSlow, WithPlasticityDisabledTheSheetSpringsBack) {
  // The control: the same scene with the module off is elastic, keeps no dent and reports no plastic work.
  const fs::path conf = project_conf();
  ASSERT_FALSE(conf.empty()) << "conf/metal-crumple.json not found";
  Scene scene = load_scene((conf / "metal-crumple.json").string());
  scene.disabled.insert("plasticity");
  Simulation sim(scene);
  double loaded = 0;
  while (!sim.finished()) {
    sim.advance_frame();
    if (sim.time() <= 0.3 + 1e-9) loaded = std::max(loaded, deepest_dent(sim.cloths[0].mesh));
    for (double w : sim.plastic_work) EXPECT_EQ(w, 0);
  }
  EXPECT_GT(loaded, 0.02);
  EXPECT_LT(deepest_dent(sim.cloths[0].mesh), 0.1 * loaded);
  for (const Face& f : sim.cloths[0].mesh.faces) {
    EXPECT_TRUE(f.Fp.isIdentity(0));
    EXPECT_TRUE(f.Sp.isZero(0));
  }
}

TEST(MetalCrumpleSlow, RemeshedSheetKeepsItsDent) {
  // conf/metal-crumple-remesh.json (issue 6 acceptance 5's scene): the same press with adaptive remeshing and
  // the plastic embedding. It runs to its end, refines where the sheet bends, keeps its dent, and nothing makes
  // it spring up after unloading (a rest state that no longer matched the world after the edits made the dent
  // snap through and the sheet ride up with the sphere, with 1e7 J and more of spurious plastic work).
  const fs::path conf = project_conf();
  ASSERT_FALSE(conf.empty()) << "conf/metal-crumple.json not found";
  Simulation sim(load_scene((conf / "metal-crumple-remesh.json").string()));
  ASSERT_TRUE(sim.scene().enabled("remeshing"));
  double loaded = 0, largest_frame_work = 0;
  int most_faces = 0;
  while (!sim.finished()) {
    sim.advance_frame();
    if (sim.time() <= 0.3 + 1e-9) loaded = std::max(loaded, deepest_dent(sim.cloths[0].mesh));
    largest_frame_work = std::max(largest_frame_work, sim.plastic_work[0]);
    int faces = 0;
    for (const Face& f : sim.cloths[0].mesh.faces) faces += f.dead ? 0 : 1;
    most_faces = std::max(most_faces, faces);
  }
  const Mesh& mesh = sim.cloths[0].mesh;
  EXPECT_GT(most_faces, 250);  // it refined (200 faces at the start)
  EXPECT_GT(loaded, 0.02);
  EXPECT_GT(deepest_dent(mesh), 0.6 * loaded);
  double highest = -kInfinity;
  for (const Node& n : mesh.nodes) highest = std::max(highest, n.x.z());
  EXPECT_LT(highest, 1e-3);             // m: the sphere only pushed down
  EXPECT_LT(largest_frame_work, 100);   // J: 42 J at most when measured (issue 16: 2.6e8 J on other machines)
}

// --- Rounding sensitivity and the energy balance (issue 16) ------------------------------------------------
//
// The remeshed scene once released 2.6e8 J of plastic work in one frame on some machines and 38 J on others:
// the impact zone of the sheet node pressed onto the sphere's lowest vertex had constraints with nearly
// opposite normals (src/collision/ccd.cpp, with_plane_normal), met only by moving a node of small weight by
// 27 cm in one step. Which way the rounding fell decided the outcome, so these runs perturb every initial
// node position by up to 1e-12 m (seeded) and require each to hold the figures of merit.
//
// The energy balance, from the simulation's energy audit (sim/simulation.hpp, StepEnergies), per frame:
//  - the plastic work the flow rules report is elastic energy the sheet really released: at most the drop of
//    its mechanical energy across the plasticity phase (weakening releases a little more);
//  - the plastic work so far is at most the work done on the sheet so far by the dynamics (contacts, clamps,
//    gravity, the collision response; net of damping) plus the energy it started with;
//  - the collision response does no more work in a step than the sphere can: the largest force the sheet can
//    hold (the yield stress times the thickness along the whole border: a membrane cannot carry more across
//    any curve around the contact) times the sphere's displacement plus the projection thickness (the
//    response may push the sheet that much beyond the sphere's own motion: it enforces that gap). Healthy
//    runs stay below it with ~7 J to spare near the end of the press; the 27 cm jump added 1e8 J in a step.
struct PerturbedRun {
  double largest_frame_work = 0;  // J
  double loaded = 0, kept = 0, highest = 0;  // m
  double worst_release_excess = -kInfinity;  // J: reported plastic work - energy released, worst frame
  double worst_balance = -kInfinity;         // J: plastic work so far - (work done so far + initial energy)
  double worst_collision_excess = -kInfinity;  // J: collision work in a step - its bound
  double plastic_total = 0, work_total = 0;  // J
  int fallback_zones = 0;
};

Vec3 obstacle_centroid(const Mesh& m) {
  Vec3 c = Vec3::Zero();
  for (const Node& n : m.nodes) c += n.x;
  return c / static_cast<double>(m.nodes.size());
}

// Yield stress (Pa) x thickness (m) x length of the sheet's border (m): the largest force (N) it can carry.
double border_force_bound(const Simulation& sim) {
  const Mesh& mesh = sim.cloths[0].mesh;
  const Material& m = sim.cloths[0].materials[0];
  double border = 0;
  for (const Edge& e : mesh.edges)
    if (!e.dead && e.is_boundary()) border += (mesh.nodes[e.n[1]].x - mesh.nodes[e.n[0]].x).norm();
  return m.yield_stress * m.thickness * border;
}

PerturbedRun run_perturbed(const fs::path& scene_file, unsigned seed) {
  Simulation sim(load_scene(scene_file.string()));
  sim.audit_energy = true;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(-1e-12, 1e-12);
  for (Node& n : sim.cloths[0].mesh.nodes) {
    const Vec3 d(jitter(rng), jitter(rng), jitter(rng));
    n.x += d;
    n.x0 += d;
  }
  const double force_bound = border_force_bound(sim);
  const MagicParams& magic = sim.scene().magic;
  const double projection =
      magic.projection_thickness >= 0 ? magic.projection_thickness : 0.1 * magic.repulsion_thickness;  // m
  PerturbedRun out;
  double initial = kInfinity, work_done = 0, released = 0, plastic = 0;
  while (!sim.finished()) {
    const Vec3 c0 = obstacle_centroid(sim.obstacles[0].mesh);
    sim.advance_step();
    const StepEnergies& e = sim.step_energies.at(0);
    if (initial == kInfinity) initial = e.start;
    work_done += e.after_collision - e.start;
    released += e.after_collision - e.after_plasticity;
    const double sphere_move = (obstacle_centroid(sim.obstacles[0].mesh) - c0).norm();
    const double collision_work = e.after_collision - e.after_physics;
    out.worst_collision_excess =
        std::max(out.worst_collision_excess, collision_work - force_bound * (sphere_move + projection));
    if (sim.step() % sim.frame_steps() != 0) continue;
    // A frame ended: plastic_work holds this frame's total.
    const double frame_work = sim.plastic_work[0];
    plastic += frame_work;
    out.largest_frame_work = std::max(out.largest_frame_work, frame_work);
    out.worst_release_excess = std::max(out.worst_release_excess, frame_work - released);
    released = 0;
    out.worst_balance = std::max(out.worst_balance, plastic - (work_done + initial));
    if (sim.time() <= 0.3 + 1e-9) out.loaded = std::max(out.loaded, deepest_dent(sim.cloths[0].mesh));
  }
  out.fallback_zones = sim.collision_totals().fallback_zones;  // never cleared here: the whole run
  out.kept = deepest_dent(sim.cloths[0].mesh);
  out.highest = -kInfinity;
  for (const Node& n : sim.cloths[0].mesh.nodes) out.highest = std::max(out.highest, n.x.z());
  out.plastic_total = plastic;
  out.work_total = work_done;
  return out;
}

void print_run(const char* scene, unsigned seed, const PerturbedRun& r) {
  std::printf("%s seed %u: largest frame %.3g J; plastic %.4g J, work done %.4g J; worst release excess %.2g J; "
              "collision work at most %.3g J above the sphere's bound; dent %.4g m of %.4g m\n",
              scene, seed, r.largest_frame_work, r.plastic_total, r.work_total, r.worst_release_excess,
              r.worst_collision_excess, r.kept, r.loaded);
}

void expect_healthy(const PerturbedRun& r, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_LT(r.largest_frame_work, 100);  // J
  EXPECT_LE(r.worst_release_excess, 0.01 * r.largest_frame_work + 1e-9)
      << "the flow rules reported more work than the sheet released (J)";
  EXPECT_LE(r.worst_balance, 1e-6 * r.work_total + 1e-4) << "plastic work exceeded the work done on the sheet: plastic "
                                   << r.plastic_total << " J, work done " << r.work_total << " J";
  EXPECT_LT(r.worst_collision_excess, 1e-3) << "the collision response did more work than the sphere can (J)";
  EXPECT_GT(r.loaded, 0.02);
  EXPECT_GT(r.kept, 0.6 * r.loaded) << "the dent sprang back";
  EXPECT_LT(r.highest, 1e-3) << "the sheet rose: dragged up by the sphere";
  EXPECT_EQ(r.fallback_zones, 0) << "impact zones fell back to rigid motion";
}

TEST(MetalCrumpleSlow, RemeshedSheetHoldsUnderRoundingPerturbations) {
  const fs::path conf = project_conf();
  ASSERT_FALSE(conf.empty()) << "conf/metal-crumple.json not found";
  // Before the fix, 5 of seeds 0-11 broke on the machine this was written on (seeds 2-5 here: 1.1e11, 4.1e4,
  // 6.6e7 and 2.0e7 J in one frame, the sheet dragged up through the sphere); eight seeds make it all but
  // certain that some break on any machine (collision/ccd_test.cpp's PairsAroundAnApex test fails
  // deterministically without the fix).
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const PerturbedRun r = run_perturbed(conf / "metal-crumple-remesh.json", seed);
    print_run("metal-crumple-remesh", seed, r);
    expect_healthy(r, "metal-crumple-remesh.json, seed " + std::to_string(seed));
  }
}

TEST(MetalCrumpleSlow, FixedMeshSheetHoldsUnderRoundingPerturbations) {
  const fs::path conf = project_conf();
  ASSERT_FALSE(conf.empty()) << "conf/metal-crumple.json not found";
  for (unsigned seed : {1u, 2u}) {
    const PerturbedRun r = run_perturbed(conf / "metal-crumple.json", seed);
    print_run("metal-crumple", seed, r);
    expect_healthy(r, "metal-crumple.json, seed " + std::to_string(seed));
  }
}

}  // namespace
}  // namespace arcsim
