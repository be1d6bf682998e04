// Plastic memory through remeshing (issue 6 acceptance 2) on a strip the SIMULATOR bends: an aluminium strip,
// clamped by its first cell, is formed into a circular arc well past yield_curv by handles that carry every
// other node column along the arc, then let go; the strip springs back onto the plastic shape the flow rule
// left and settles. The settled mesh then goes through forced refine / coarsen cycles, with the local plastic
// embedding and with naive interpolation: the embedding keeps the rest curvature within 1% and the world
// shape within 1% of the strip's length; the interpolation's loss is printed.
//
// WHY every column is driven: with a pure end moment (only the far end cell held and swung round the circle)
// the strip did not become an arc. Bending plasticity is perfectly plastic (paper Eq. 10, no hardening), so
// once the whole strip yields nothing prefers a uniform curvature: a 2 s bend left plastic folds of 0.04 to
// 0.12 rad per 2 cm cell (a 3.5 mm departure from the fitted circle) and a 0.4 s bend a wave of 0.02 to 0.15.
//
// The clamp holds the two node rows of the first cell (one row would be a hinge), so the bent region is the
// strip from x = kCell to its free end. Curvatures are circle fits over that region (cylinder_fit.hpp): of the
// world nodes, and of the strip unfolded into plastic space (build_plastic_embedding).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <utility>

#include <Eigen/Geometry>

#include "cylinder_fit.hpp"
#include "io/obj.hpp"
#include "plasticity/plastic_embedding.hpp"
#include "remesh/remesh.hpp"
#include "sim/simulation.hpp"
#include "support/files.hpp"
#include "support/mesh_factory.hpp"
#include "plastic_fixtures.hpp"

namespace arcsim {
namespace {

constexpr double kLength = 0.4, kWidth = 0.04;  // m
constexpr int kCells = 20, kRows = 2;           // grid cells along and across the strip
constexpr double kCell = kLength / kCells;      // m, the clamped first cell
constexpr double kYieldCurvature = 1;           // 1/m
constexpr double kBendCurvature = 5;            // 1/m, the arc the handles impose (R = 0.2 m)
constexpr double kBendTime = 1.0, kReleaseTime = 1.1, kFadeTime = 0.05, kEndTime = 2.1;  // s
constexpr double kFine = 0.01, kCoarse = 0.03;  // m, the two uniform sizes of a remesh cycle

Material thin_aluminium() {
  Material m = testing::aluminium_sheet(kYieldCurvature, 1e-3, "aluminium strip");
  m.damping = 1e-2;  // s: settles the springback within the second after the release
  return m;
}

// Pose that puts the strip's material line x = s (s >= kCell) where it lies on an arc of curvature kappa
// (1/m) starting at (kCell, 0, 0) along x and turning towards +z: on the arc, along the bending axis y.
Transform column_pose(double kappa, double s) {
  Transform t;
  if (kappa <= 0) return t;
  const double phi = kappa * (s - kCell);  // rad, the arc's turn up to s
  const Vec3 on_arc(kCell + std::sin(phi) / kappa, 0, (1 - std::cos(phi)) / kappa);
  t.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(-phi, Vec3::UnitY()));  // takes e_x to (cos phi, 0, sin phi)
  t.translation = on_arc - t.rotation * Vec3(s, 0, 0);
  return t;
}

// The forming of column s as keyframes: the curvature grows linearly in time from 0 to kBendCurvature over
// kBendTime (zero rate at both ends), each key with its exact rate so that the cubic path stays close to the
// family of arcs between keys.
Motion column_motion(double s) {
  constexpr int kKeys = 65;
  const double rate = kBendCurvature / kBendTime;  // 1/(m s)
  Motion motion;
  for (int k = 0; k < kKeys; ++k) {
    Keyframe key;
    key.time = kBendTime * k / (kKeys - 1);
    const double kappa = kBendCurvature * k / (kKeys - 1);
    key.transform = column_pose(kappa, s);
    key.has_velocity = true;
    if (k > 0 && k < kKeys - 1) {
      const double dk = 1e-6;  // 1/m, central difference of the translation along the family of arcs
      const Vec3 d_translation = column_pose(kappa + dk, s).translation - column_pose(kappa - dk, s).translation;
      key.velocity = rate * d_translation / (2 * dk);
      key.angular_velocity = Vec3(0, -rate * (s - kCell), 0);
    }
    motion.keys.push_back(key);
  }
  return motion;
}

Scene bending_scene(const std::string& mesh_path, const Mesh& grid) {
  Scene s;
  s.path = "plastic-bending-test-scene";
  s.frame_time = 0.01;
  s.frame_steps = 5;
  s.step_time = s.frame_time / s.frame_steps;
  s.end_time = kEndTime;
  s.gravity = Vec3::Zero();
  s.wind.density = 0;
  s.disabled = {"remeshing", "fracture", "collision", "proximity", "separation", "popfilter", "strainlimiting"};
  s.magic.handle_stiffness = 1e6;  // N/m: the handles carry the bending with sub-millimetre slack
  ClothSpec cloth;
  cloth.mesh = mesh_path;
  cloth.materials = {thin_aluminium()};
  s.cloths = {cloth};
  HandleSpec clamp;
  for (int column = 0; column <= kCells; ++column) {
    const double x = column * kCell;
    HandleSpec former;
    for (size_t n = 0; n < grid.nodes.size(); ++n)
      if (std::abs(grid.nodes[n].x.x() - x) < 1e-9)
        (column <= 1 ? clamp : former).nodes.push_back(static_cast<int>(n));
    if (column <= 1) continue;
    former.motion = static_cast<int>(s.motions.size());
    former.end_time = kReleaseTime;
    former.fade_time = kFadeTime;
    s.motions.push_back(column_motion(x));
    s.handles.push_back(former);
  }
  s.handles.push_back(clamp);
  return s;
}

double kinetic_energy(const Mesh& m) {
  double e = 0;  // J
  for (const Node& n : m.nodes) e += 0.5 * n.mass * n.v.squaredNorm();
  return e;
}

bool in_bent_region(const Vec3& u) { return u.x() > kCell - 1e-9; }

struct Shape {
  testing::CylinderFit rest, world;  // circle fits of the bent region: plastic space, world
  double rest_residual = 0;          // m, largest distance of a plastic-space node from its fit
  Vec3 ends[2];                      // m, world centres of the end lines x = 0 and x = L
  std::vector<Vec3> world_nodes;     // world positions of the bent region's nodes
  int faces = 0;
  double end_to_end() const { return (ends[1] - ends[0]).norm(); }
};

Shape measure(const Mesh& m) {
  Shape s;
  std::vector<int> faces;
  for (size_t f = 0; f < m.faces.size(); ++f) {
    if (m.faces[f].dead) continue;
    faces.push_back(static_cast<int>(f));
  }
  s.faces = static_cast<int>(faces.size());
  const PlasticEmbedding plastic = build_plastic_embedding(m, faces);
  std::vector<Vec3> us, ys;
  int end_count[2] = {0, 0};
  s.ends[0] = s.ends[1] = Vec3::Zero();
  for (size_t i = 0; i < m.nodes.size(); ++i) {
    const Node& n = m.nodes[i];
    if (n.dead) continue;
    const Vec3& u = m.verts[n.verts[0]].u;
    if (u.x() < 1e-9) s.ends[0] += n.x, ++end_count[0];
    if (u.x() > kLength - 1e-9) s.ends[1] += n.x, ++end_count[1];
    if (!in_bent_region(u)) continue;
    us.push_back(u);
    ys.push_back(plastic.at(static_cast<int>(i)));
    s.world_nodes.push_back(n.x);
  }
  s.ends[0] /= end_count[0];
  s.ends[1] /= end_count[1];
  s.rest = testing::fit_cylinder(us, ys);
  s.world = testing::fit_cylinder(us, s.world_nodes);
  for (const Vec3& y : ys) s.rest_residual = std::max(s.rest_residual, s.rest.distance(y));
  return s;
}

// Largest distance (m) of `after`'s bent-region world nodes from the circle fitted before the cycles.
double off_arc(const Shape& before, const Shape& after) {
  double worst = 0;
  for (const Vec3& x : after.world_nodes) worst = std::max(worst, before.world.distance(x));
  return worst;
}

// Smallest and largest plastic fold (rad, |rest angle|; the rest is flat) of the interior grid lines across
// the bent region, past its first line where the arc leaves the clamp with half a fold. Grid meshes only.
std::pair<double, double> fold_range(const Mesh& m) {
  double smallest = kInfinity, largest = 0;
  for (const Edge& ed : m.edges) {
    if (ed.dead || ed.is_boundary()) continue;
    const Vec3 &a = m.verts[m.nodes[ed.n[0]].verts[0]].u, &b = m.verts[m.nodes[ed.n[1]].verts[0]].u;
    if (std::abs(a.x() - b.x()) > 1e-9 || a.x() < kCell + 1e-9) continue;
    smallest = std::min(smallest, std::abs(ed.rest_theta));
    largest = std::max(largest, std::abs(ed.rest_theta));
  }
  return {smallest, largest};
}

struct Bent {
  Mesh mesh;
  std::vector<Material> materials;
  double loaded_curvature = 0;  // 1/m, world fit of the bent region at the end of the bend (handle on)
  double kinetic_energy = 0;    // J, at the end of the settling
};

// Runs the scene: the bend, the release and the settling; returns the settled strip.
Bent bend_and_release() {
  testing::TempDir dir;
  const Mesh grid = testing::make_grid(kCells, kRows, kLength, kWidth);
  const std::string path = (dir.path / "strip.obj").string();
  write_obj(grid, path);
  Simulation sim(bending_scene(path, grid));
  Bent out;
  while (!sim.finished()) {
    sim.advance_frame();
    // The loaded arc: just before the release, after the bend.
    if (std::abs(sim.time() - kReleaseTime) < 0.5 * sim.scene().frame_time)
      out.loaded_curvature = measure(sim.cloths[0].mesh).world.curvature();
  }
  out.kinetic_energy = kinetic_energy(sim.cloths[0].mesh);
  out.mesh = sim.cloths[0].mesh;
  // Handles mark their nodes preserved for good; the released formers hold nothing, so their nodes may go
  // like any other (else the coarsening could never remove an original node). The clamp keeps its rows.
  for (size_t n = 0; n < out.mesh.nodes.size(); ++n)
    out.mesh.nodes[n].preserve = out.mesh.verts[out.mesh.nodes[n].verts[0]].u.x() < kCell + 1e-9;
  out.materials = sim.cloths[0].materials;
  return out;
}

struct CycleRun {
  Shape initial, final;
  int refined_faces = 0;
  double seconds = 0;  // remeshing wall time
};

// `cycles` of refine to kFine then coarsen to kCoarse, compacting after each pass, on a copy of the strip.
CycleRun run_cycles(const Bent& bent, bool embedding, int cycles) {
  Mesh m = bent.mesh;
  CycleRun run;
  run.initial = measure(m);
  RemeshOptions o;
  o.sizing.remeshing.size_min = kFine;
  o.sizing.remeshing.size_max = kCoarse;
  o.sizing.remeshing.plastic_embedding = embedding;
  const auto start = std::chrono::steady_clock::now();
  for (int c = 0; c < cycles; ++c) {
    for (double size : {kFine, kCoarse}) {
      o.extras.uniform_size = size;
      remesh_mesh(m, bent.materials, o);
      m.compact();
      if (size == kFine) run.refined_faces = std::max(run.refined_faces, static_cast<int>(m.faces.size()));
    }
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.final = measure(m);
  return run;
}

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

void print(const char* name, const CycleRun& r) {
  const Shape &i = r.initial, &s = r.final;
  std::printf("  %-11s faces %3d (fine %3d)  rest curvature %.4f -> %.4f 1/m (%+.3f%%)  world curvature "
              "%+.3f%%  end-to-end %+.3f%% L  off-arc %.3f%% L  remeshing %.2f s\n",
              name, s.faces, r.refined_faces, i.rest.curvature(), s.rest.curvature(),
              100 * (s.rest.curvature() / i.rest.curvature() - 1),
              100 * (s.world.curvature() / i.world.curvature() - 1),
              100 * (s.end_to_end() - i.end_to_end()) / kLength, 100 * off_arc(i, s) / kLength, r.seconds);
}

// The acceptance on the embedding; the interpolation is measured and printed.
void check_memory(const Bent& bent, int cycles) {
  const CycleRun kept = run_cycles(bent, true, cycles), naive = run_cycles(bent, false, cycles);
  std::printf("simulator-bent strip after %d cycles (initial: rest curvature %.4f 1/m, world curvature %.4f 1/m, "
              "end-to-end %.4f m)\n",
              cycles, kept.initial.rest.curvature(), kept.initial.world.curvature(), kept.initial.end_to_end());
  print("embedding", kept);
  print("interpolate", naive);
  EXPECT_GT(kept.refined_faces, 2 * kept.initial.faces) << "the cycles did not refine";
  EXPECT_LT(rel(kept.final.rest.curvature(), kept.initial.rest.curvature()), 0.01);
  EXPECT_LT(rel(kept.final.world.curvature(), kept.initial.world.curvature()), 0.01);
  EXPECT_LT(std::abs(kept.final.end_to_end() - kept.initial.end_to_end()), 0.01 * kLength);
  EXPECT_LT(off_arc(kept.initial, kept.final), 0.01 * kLength);
}

TEST(PlasticBendingMemory, FormingMotionsFollowTheArc) {
  // Between keys the cubic path of every column stays on the family of arcs: the pose's rotation says which
  // arc (its turn is kappa (s - kCell)), and the column must then sit on that arc.
  double worst = 0;  // m
  for (double s : {2 * kCell, 0.5 * kLength, kLength}) {
    Motion motion = column_motion(s);
    motion.finalize();
    for (int i = 0; i <= 400; ++i) {
      const Transform pose = motion.pose(kBendTime * i / 400);
      const Vec3 tangent = pose.rotation * Vec3::UnitX();
      const Transform exact = column_pose(std::atan2(tangent.z(), tangent.x()) / (s - kCell), s);
      for (double y : {0.0, kWidth})
        worst = std::max(worst, (pose.apply(Vec3(s, y, 0)) - exact.apply(Vec3(s, y, 0))).norm());
    }
  }
  EXPECT_LT(worst, 1e-4 * kLength);
  // At the end of the bend the free end is on the circle of radius 1/kBendCurvature about (kCell, 0, R), at
  // the arc's turn from the clamp.
  Motion end = column_motion(kLength);
  end.finalize();
  const double R = 1 / kBendCurvature, phi = kBendCurvature * (kLength - kCell);
  EXPECT_LT((end.pose(kBendTime).apply(Vec3(kLength, 0, 0)) -
             Vec3(kCell + R * std::sin(phi), 0, R * (1 - std::cos(phi)))).norm(), 1e-12);
}

// The forming, release and settling (~1 s optimised), then 10 cycles. The bend must be plastic and uniform.
TEST(PlasticBendingMemorySlow, SimulatorBentStripKeepsItsArcThroughTenCycles) {
  const Bent bent = bend_and_release();
  const Shape settled = measure(bent.mesh);
  const auto folds = fold_range(bent.mesh);
  std::printf("formed arc: world curvature %.4f 1/m (imposed %.4f); settled: world %.4f 1/m, plastic %.4f 1/m "
              "(fit residual %.2e m), plastic folds in [%.4f, %.4f] rad, kinetic energy %.2e J\n",
              bent.loaded_curvature, kBendCurvature, settled.world.curvature(), settled.rest.curvature(),
              settled.rest_residual, folds.first, folds.second, bent.kinetic_energy);
  EXPECT_NEAR(bent.loaded_curvature, kBendCurvature, 0.02 * kBendCurvature);  // the handles made the arc
  EXPECT_GT(settled.rest.curvature(), 0.5 * kBendCurvature);  // plastic: most of the bend stays
  EXPECT_LT(settled.rest_residual, 1e-3 * kLength);            // a uniform arc
  EXPECT_GT(folds.first, 0.9 * folds.second);
  EXPECT_NEAR(settled.world.curvature(), settled.rest.curvature(), 0.02 * settled.rest.curvature());
  EXPECT_LT(bent.kinetic_energy, 1e-8);  // J: settled (the strip weighs 43 g)
  check_memory(bent, 10);
}

// Issue 6 acceptance 2 on the simulator-bent strip (`make slowcheck`): +0.83% rest curvature, 0.96% L off the
// arc with the embedding; interpolation loses 4%. (At commit 0c4c6f7, with split nodes held at their estimated
// sagitta, this state broke down near cycle 85: +39% rest curvature, |Sp| > 1000 1/m.)
TEST(PlasticBendingMemorySlowCheck, SimulatorBentStripKeepsItsArcThroughHundredCycles) {
  check_memory(bend_and_release(), 100);
}

}  // namespace
}  // namespace arcsim
