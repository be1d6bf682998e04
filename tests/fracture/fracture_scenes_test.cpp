// Fracture in whole simulations (issue 12's acceptance 2-5): strips driven by handles whose anchors the test
// moves every step, so the load is known exactly.
//  - Onset: a strip in uniform uniaxial tension (nu = 0) first cracks when its Green strain reaches
//    toughness / E. The criterion compares the membrane stress S = E h G (N/m) with the area toughness
//    tau = toughness * h, so G_crit = toughness / E, whatever the mesh. Measured on remeshed strips with
//    size_min 4, 2 and 1 mm and on an irregular initial mesh: each within 5% of G_crit, and within 5% of each
//    other. The strain is read from the clamps: stretch = (mean x of the right clamp - mean x of the left
//    clamp) / rest distance; with nu = 0 and no gravity the strip between them is uniformly stretched.
//  - Mode I: a strip with a slit cut into its left border, pulled apart across the slit, tears straight on from
//    the slit's tip (every new crack edge within 2 size_min of the slit's line, rest space) all the way through
//    (two pieces), with no other crack.
//  - Bending: a glass strip bent into a circular arc of growing curvature kappa by its clamped ends cracks
//    when the surface strain 1/2 alpha h kappa gives the critical Green strain: e + e^2/2 = toughness / E
//    (Eq. 8 with II* = diag(kappa, 0)), within 10%, across the strip. With fracture_bending_mult 0 it does
//    not crack at twice that curvature.
//  - Compression: a strip pushed to 85% of its length buckles and never cracks.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "collision/scene_fixtures.hpp"
#include "mesh/edits.hpp"
#include "mesh/mesh_stats.hpp"
#include "mesh/validate.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using namespace testing;

// A strip over [0, length] x [0, width] (rest space = initial world, z = 0).
struct StripSpec {
  double length = 0.1, width = 0.02;  // m
  double cell = 0.005;                // m, initial grid spacing
  bool irregular = false;             // jitter interior nodes by up to 30% of a cell
  double size_min = 0, size_max = 0;  // m; 0: no remeshing
  Material material;
  double dt = 1e-3;                   // s
  // Clamp columns: nodes with rest x within this of either end are held by stiff handles.
  double clamp = 1e-9;
  std::function<void(Mesh&)> prepare;  // edits of the mesh before it is written (a slit)
  double repulsion_thickness = -1, projection_thickness = -1;  // m; < 0: the scene defaults
};

Material tough_sheet(double youngs, double toughness, double thickness) {
  Material m;
  m.name = "test strip";
  m.thickness = thickness;
  m.density = 1000;
  m.youngs_modulus = youngs;
  m.poisson_ratio = 0;
  m.toughness = toughness;
  return m;
}

Mesh strip_mesh(const StripSpec& s) {
  const int nx = static_cast<int>(std::lround(s.length / s.cell));
  const int ny = static_cast<int>(std::lround(s.width / s.cell));
  Mesh mesh = make_grid(nx, ny, s.length, s.width, Diagonal::kAlternating);
  if (s.irregular) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> jitter(-0.3 * s.cell, 0.3 * s.cell);
    for (Node& n : mesh.nodes) {
      const Vec3 p = n.x;
      const bool border = p.x() < 1e-9 || p.x() > s.length - 1e-9 || p.y() < 1e-9 || p.y() > s.width - 1e-9;
      if (border) continue;
      n.x += Vec3(jitter(rng), jitter(rng), 0);
      n.x0 = n.x;
      for (int v : n.verts) mesh.verts[v].u = n.x;
    }
    mesh.update_rest_data();
  }
  if (s.prepare) s.prepare(mesh);
  return mesh;
}

// A running strip: the simulation and its two clamps (node lists, rest positions).
struct StripSim {
  TempDir dir;
  std::unique_ptr<Simulation> sim;
  std::vector<int> left, right;  // handle indices into sim->handles: 0 = left clamp, 1 = right clamp
};

void build(StripSim& run, const StripSpec& s) {
  write_obj(strip_mesh(s), (run.dir.path / "strip.obj").string());
  Scene scene = base_scene(s.dt, kInfinity);
  scene.gravity = Vec3::Zero();
  scene.disabled = {"plasticity", "strainlimiting", "separation", "popfilter"};
  if (!(s.size_min > 0)) scene.disabled.insert("remeshing");
  scene.magic.handle_stiffness = 1e9;
  if (s.repulsion_thickness > 0) scene.magic.repulsion_thickness = s.repulsion_thickness;
  if (s.projection_thickness > 0) scene.magic.projection_thickness = s.projection_thickness;
  scene.cloths.push_back(cloth_spec(run.dir.path / "strip.obj", make_transform(Vec3::Zero()), s.material));
  RemeshingParams& r = scene.cloths[0].remeshing;
  r.refine_angle = 0.3;
  r.refine_compression = 0.01;
  r.refine_fracture = 0.5;
  r.size_min = s.size_min;
  r.size_max = s.size_max;
  r.aspect_min = 0.3;
  r.has_size = r.has_aspect_min = r.has_refine_compression = r.has_refine_fracture = true;
  // Two handles; move_clamp chooses their nodes before every step.
  scene.handles = {HandleSpec(), HandleSpec()};
  run.sim = std::make_unique<Simulation>(scene);
}

// Handle h holds every node whose rest position satisfies `held` (recollected each time: remeshing splits the
// clamped border too, and a new node there must be clamped like its neighbours), at `place(rest position)`.
void move_clamp(Simulation& sim, int h, const std::function<bool(const Vec3&)>& held,
                const std::function<Vec3(const Vec3&)>& place) {
  Handle& handle = sim.handles[h];
  Mesh& mesh = sim.cloths[0].mesh;
  handle.holds_line = true;  // a clamp along a border: nodes remeshing adds on it within the step join it
  handle.nodes.clear();
  handle.anchors.clear();
  for (size_t n = 0; n < mesh.nodes.size(); ++n) {
    if (mesh.nodes[n].dead) continue;
    const Vec3& u = mesh.verts[mesh.nodes[n].verts[0]].u;
    if (!held(u)) continue;
    mesh.nodes[n].preserve = true;
    handle.nodes.push_back(static_cast<int>(n));
    handle.anchors.push_back(place(u));
  }
}

double mean_x(const Simulation& sim, int h) {
  const Mesh& mesh = sim.cloths[0].mesh;
  double sum = 0;
  for (int n : sim.handles[h].nodes) sum += mesh.nodes[n].x.x();
  return sum / sim.handles[h].nodes.size();
}

double mean_rest_x(const Simulation& sim, int h) {
  const Mesh& mesh = sim.cloths[0].mesh;
  double sum = 0;
  for (int n : sim.handles[h].nodes) sum += mesh.verts[mesh.nodes[n].verts[0]].u.x();
  return sum / sim.handles[h].nodes.size();
}

int cracks_of_last_step(const Simulation& sim) {
  int n = 0;
  for (const FractureStats& f : sim.fracture_stats) n += f.cracks;
  return n;
}

// Green strain at which a strip pulled at a constant rate first cracks (-1: it did not within max_steps).
double onset_strain(const StripSpec& s, double strain_per_step, int max_steps, int* faces_at_onset = nullptr) {
  StripSim run;
  build(run, s);
  Simulation& sim = *run.sim;
  const auto left = [&](const Vec3& u) { return u.x() < s.clamp + 1e-9; };
  const auto right = [&](const Vec3& u) { return u.x() > s.length - s.clamp - 1e-9; };
  move_clamp(sim, 0, left, [](const Vec3& u) { return u; });
  move_clamp(sim, 1, right, [](const Vec3& u) { return u; });
  const double rest = mean_rest_x(sim, 1) - mean_rest_x(sim, 0);
  for (int step = 1; step <= max_steps; ++step) {
    // Stretch lambda with (lambda^2 - 1)/2 = step * strain_per_step.
    const double lambda = std::sqrt(1 + 2 * step * strain_per_step);
    move_clamp(sim, 0, left, [](const Vec3& u) { return u; });
    move_clamp(sim, 1, right, [&](const Vec3& u) { return Vec3(u.x() + (lambda - 1) * rest, u.y(), 0); });
    sim.advance_step();
    const double stretch = (mean_x(sim, 1) - mean_x(sim, 0)) / rest;
    const double strain = 0.5 * (stretch * stretch - 1);
    if (cracks_of_last_step(sim) > 0) {
      if (faces_at_onset) *faces_at_onset = static_cast<int>(sim.cloths[0].mesh.faces.size());
      return strain;
    }
  }
  return -1;
}

StripSpec tension_strip(double size_min) {
  StripSpec s;
  s.material = tough_sheet(1e9, 1e7, 1e-3);  // G_crit = 1%
  s.cell = 0.005;
  s.size_min = size_min;
  s.size_max = 0.01;
  return s;
}

constexpr double kTensionCritical = 1e7 / 1e9;

void expect_onset(const std::vector<double>& strains) {
  double lo = kInfinity, hi = -kInfinity;
  for (double g : strains) {
    EXPECT_NEAR(g, kTensionCritical, 0.05 * kTensionCritical);
    lo = std::min(lo, g);
    hi = std::max(hi, g);
  }
  EXPECT_LT((hi - lo) / kTensionCritical, 0.05);
}

TEST(FractureOnset, UniformTensionCracksAtToughnessOverYoungsModulus) {
  // Coarse remeshed strips: 4 mm and 2 mm minimum size, 0.5% of the critical strain per step.
  std::vector<double> strains;
  for (double size_min : {0.004, 0.002}) {
    int faces = 0;
    const double g = onset_strain(tension_strip(size_min), kTensionCritical / 200, 300, &faces);
    ASSERT_GT(g, 0) << "no crack with size_min " << size_min;
    strains.push_back(g);
    RecordProperty("onset_" + std::to_string(size_min), std::to_string(g));
  }
  expect_onset(strains);
}

TEST(FractureOnset, SlowCheckOnsetDoesNotDependOnTheMesh) {
  std::vector<double> strains;
  for (double size_min : {0.004, 0.002, 0.001}) {
    const double g = onset_strain(tension_strip(size_min), kTensionCritical / 200, 300);
    ASSERT_GT(g, 0) << "no crack with size_min " << size_min;
    strains.push_back(g);
  }
  StripSpec irregular = tension_strip(0.002);
  irregular.irregular = true;
  const double g = onset_strain(irregular, kTensionCritical / 200, 300);
  ASSERT_GT(g, 0) << "no crack on the irregular mesh";
  strains.push_back(g);
  for (double s : strains) std::printf("onset Green strain %.6g (predicted %.6g)\n", s, kTensionCritical);
  expect_onset(strains);
}

// Rest-space border edges that were not border before: the crack lips. (A border node a crack reached is split
// and its halves cut apart by the lip gap, in the rest shape too: hence the 0.1 mm tolerance.)
std::vector<int> crack_edges(const Mesh& mesh, double length, double width) {
  constexpr double kTolerance = 1e-4;  // m
  std::vector<int> out;
  for (size_t e = 0; e < mesh.edges.size(); ++e) {
    const Edge& edge = mesh.edges[e];
    if (edge.dead || !edge.is_boundary()) continue;
    bool on_border = true;
    for (int side = 0; side < 2; ++side) {
      const Vec3 u = mesh.verts[mesh.nodes[edge.n[side]].verts[0]].u;
      const bool border = u.x() < kTolerance || u.x() > length - kTolerance || u.y() < kTolerance ||
                          u.y() > width - kTolerance;
      on_border = on_border && border;
    }
    if (!on_border) out.push_back(static_cast<int>(e));
  }
  return out;
}

Vec3 rest_midpoint(const Mesh& mesh, int e) {
  const Edge& edge = mesh.edges[e];
  const int f = edge.f[0] != kNone ? edge.f[0] : edge.f[1];
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    const int n = mesh.face_node(f, i);
    if (n == edge.n[0] || n == edge.n[1]) sum += mesh.verts[mesh.faces[f].v[i]].u;
  }
  return 0.5 * sum;
}

// The first cracking step of a strip pulled fast (a quarter of the critical strain per step, so that many nodes
// break at once), with one opening per substep or independent openings.
FractureStats first_cracking_step(bool independent, std::string& mesh_problem, int& pieces) {
  StripSpec s = tension_strip(0.004);
  s.width = 0.04;
  StripSim run;
  build(run, s);
  Simulation& sim = *run.sim;
  sim.fracture.independent_openings = independent;
  const auto left = [&](const Vec3& u) { return u.x() < s.clamp + 1e-9; };
  const auto right = [&](const Vec3& u) { return u.x() > s.length - s.clamp - 1e-9; };
  move_clamp(sim, 0, left, [](const Vec3& u) { return u; });
  move_clamp(sim, 1, right, [](const Vec3& u) { return u; });
  const double rest = mean_rest_x(sim, 1) - mean_rest_x(sim, 0);
  for (int step = 1; step <= 40; ++step) {
    const double lambda = std::sqrt(1 + 2 * step * kTensionCritical / 4);
    move_clamp(sim, 0, left, [](const Vec3& u) { return u; });
    move_clamp(sim, 1, right, [&](const Vec3& u) { return Vec3(u.x() + (lambda - 1) * rest, u.y(), 0); });
    sim.advance_step();
    if (cracks_of_last_step(sim) > 0) break;
  }
  mesh_problem = check_mesh(sim.cloths[0].mesh);
  pieces = count_components(sim.cloths[0].mesh);
  FractureStats total;
  for (const FractureStats& f : sim.fracture_stats) total += f;
  return total;
}

TEST(FractureSubstepOpenings, StrictAndIndependentBothGiveValidMeshes) {
  // Both modes crack the overloaded strip and leave a valid mesh; independent openings need no more substeps
  // for at least as many cracks per substep (the strict mode opens exactly one per substep).
  std::string strict_problem, independent_problem;
  int strict_pieces = 0, independent_pieces = 0;
  const FractureStats strict = first_cracking_step(false, strict_problem, strict_pieces);
  const FractureStats independent = first_cracking_step(true, independent_problem, independent_pieces);
  EXPECT_EQ(strict_problem, "");
  EXPECT_EQ(independent_problem, "");
  ASSERT_GT(strict.cracks, 0);
  ASSERT_GT(independent.cracks, 0);
  EXPECT_LE(strict.cracks, strict.substeps);  // one opening (or refusal) per substep
  EXPECT_LE(independent.substeps, strict.substeps);
  RecordProperty("strict", std::to_string(strict.cracks) + " cracks in " + std::to_string(strict.substeps) +
                               " substeps, " + std::to_string(strict_pieces) + " pieces");
  RecordProperty("independent", std::to_string(independent.cracks) + " cracks in " +
                                    std::to_string(independent.substeps) + " substeps, " +
                                    std::to_string(independent_pieces) + " pieces");
}

// One run of the notched strip below: the slit's lips apart by the gap crack openings leave (twice the
// projection thickness), pulled apart at `rate` (m per side per step) until it is in two pieces. Returns the
// largest distance (m) of a crack edge's rest midpoint from the slit's line.
double mode_one_deviation(StripSpec s, double repulsion, double projection, double rate, bool irregular) {
  s.repulsion_thickness = repulsion;
  s.projection_thickness = projection;
  const double slit = 0.012;
  s.prepare = [&](Mesh& mesh) {
    if (irregular) {
      // Interior nodes jittered by up to 30% of a cell, except the slit's: the crack ahead of it finds its
      // own way through triangles of every orientation.
      std::mt19937 rng(11);
      std::uniform_real_distribution<double> jitter(-0.3 * s.cell, 0.3 * s.cell);
      for (Node& n : mesh.nodes) {
        const Vec3 p = n.x;
        const bool border = p.x() < 1e-9 || p.x() > s.length - 1e-9 || p.y() < 1e-9 || p.y() > s.width - 1e-9;
        const bool on_slit = std::abs(p.y() - s.width / 2) < 1e-9 && p.x() < slit + 1e-9;
        if (border || on_slit) continue;
        n.x += Vec3(jitter(rng), jitter(rng), 0);
        n.x0 = n.x;
        for (int v : n.verts) mesh.verts[v].u = n.x;
      }
      mesh.update_rest_data();
    }
    // Node splits along the grid line y = width / 2 from the border inwards (what a crack would do).
    for (double x = 0; x < slit - 1e-9; x += s.cell) {
      int from = kNone, to = kNone;
      for (size_t n = 0; n < mesh.nodes.size(); ++n) {
        const Vec3& p = mesh.nodes[n].x;
        if (std::abs(p.y() - s.width / 2) > 1e-9) continue;
        if (std::abs(p.x() - x) < 1e-9 && from == kNone) from = static_cast<int>(n);
        if (std::abs(p.x() - (x + s.cell)) < 1e-9) to = static_cast<int>(n);
      }
      ASSERT_NE(from, kNone);
      ASSERT_NE(to, kNone);
      const EditResult r = split_node(mesh, from, {mesh.find_edge(from, to)});
      ASSERT_TRUE(r.ok);
      // In the rest shape too, so that the slit is cut, not strained open (as openings cut it): coincident
      // lips have no contact normal, and closer lips would be wedged apart by their repulsion.
      for (int n : {from, r.added_nodes[0]}) {
        Vec3 centroid = Vec3::Zero();
        const std::vector<int> faces = mesh.node_faces(n);
        for (int f : faces)
          for (int i = 0; i < 3; ++i) centroid += mesh.nodes[mesh.face_node(f, i)].x / (3.0 * faces.size());
        const double shift = centroid.y() > mesh.nodes[n].x.y() ? projection : -projection;
        mesh.nodes[n].x.y() += shift;
        mesh.nodes[n].x0 = mesh.nodes[n].x;
        for (int v : mesh.nodes[n].verts) mesh.verts[v].u.y() += shift;
      }
    }
    mesh.update_rest_data();
    mesh.compact();
  };
  StripSim run;
  build(run, s);
  Simulation& sim = *run.sim;
  int cracks = 0, pieces = 1;
  for (int step = 1; step <= 400 && pieces < 2; ++step) {
    const double opening = rate * step;  // m per side
    move_clamp(sim, 0, [&](const Vec3& u) { return u.y() < 1e-9; },
               [&](const Vec3& u) { return Vec3(u.x(), u.y() - opening, 0); });
    move_clamp(sim, 1, [&](const Vec3& u) { return u.y() > s.width - 1e-9; },
               [&](const Vec3& u) { return Vec3(u.x(), u.y() + opening, 0); });
    sim.advance_step();
    cracks += cracks_of_last_step(sim);
    EXPECT_EQ(check_mesh(sim.cloths[0].mesh), "") << "step " << step;
    pieces = count_components(sim.cloths[0].mesh);
  }
  EXPECT_GT(cracks, 0);
  EXPECT_EQ(pieces, 2) << "the strip did not tear through";
  const Mesh& mesh = sim.cloths[0].mesh;
  double worst = 0;
  for (int e : crack_edges(mesh, s.length, s.width))
    worst = std::max(worst, std::abs(rest_midpoint(mesh, e).y() - s.width / 2));
  std::printf("mode I, %s mesh, thicknesses %.0e / %.0e m, opening %.2g m per step: %d cracks, largest "
              "deviation %.3g mm (size_min %.3g mm)\n", irregular ? "irregular" : "grid", repulsion, projection,
              rate, cracks, 1e3 * worst, 1e3 * s.size_min);
  return worst;
}

// Slow: half a minute optimised (eight runs), so it runs optimised only.
TEST(FractureModeISlow, NotchedStripTearsStraightAcross) {
  // Pulled along y across a slit along x at y = width / 2 from the left border to x = 12 mm.
  StripSpec s;
  s.length = 0.06;
  s.width = 0.04;
  s.cell = 0.004;
  s.size_min = 0.002;
  s.size_max = 0.004;
  s.material = tough_sheet(1e9, 1e7, 1e-3);
  // Several loading rates: one rate alone gives one sample of a path. Collision thicknesses of ARCSim's
  // fracture scenes (repulsion 1e-4 m, projection 1e-5 m: lips 2e-5 m apart) and the defaults (1e-3, 1e-4:
  // lips 0.2 mm apart, 10% of a 2 mm face). History of the worst deviation at these rates: 4.6 to 8.1 mm while
  // nodes that remeshing added between clamp nodes were loose for a step; 3.3 to 4.6 mm with them held
  // (Handle::holds_line), with the defaults and lips that repelled each other across the full repulsion
  // thickness (a wedge at the tip); 3.2 to 5.9 mm with the defaults once lips repelled only within the lip gap
  // (collision/proximity.hpp), while the gap was a plastic stretch of the lip faces that remeshing averaged
  // into strains; now that openings cut the rest shape, the lip gap itself (0.01 and 0.1 mm): straight along
  // the grid line. The acceptance: under 2 size_min.
  // The irregular mesh (interior nodes jittered, the slit kept) gives the crack no grid line to follow.
  struct Case {
    double repulsion, projection;
    std::vector<double> rates;  // m per side per step
    bool irregular;
  };
  for (const Case& c : {Case{1e-4, 1e-5, {1.9e-6, 2.0e-6, 2.1e-6, 2.2e-6}, false},
                        Case{1e-3, 1e-4, {1.9e-6, 2.2e-6}, false}, Case{1e-4, 1e-5, {2.0e-6}, true},
                        Case{1e-3, 1e-4, {2.0e-6}, true}}) {
    for (const double rate : c.rates) {
      SCOPED_TRACE(std::string(c.irregular ? "irregular" : "grid") + ", projection thickness " +
                   std::to_string(c.projection) + " m, opening " + std::to_string(rate * 1e6) + " um per step");
      EXPECT_LT(mode_one_deviation(s, c.repulsion, c.projection, rate, c.irregular), 2 * s.size_min);
    }
  }
}

// Places a clamp column at rest x so that the strip's centre line is an arc of curvature kappa about its middle.
Vec3 on_arc(const Vec3& u, double length, double kappa) {
  const double s = u.x() - length / 2;
  if (std::abs(kappa) < 1e-12) return u;
  const double radius = 1 / kappa;
  return Vec3(length / 2 + radius * std::sin(s / radius), u.y(), radius * (1 - std::cos(s / radius)));
}

// A glass strip bent at a constant curvature rate until it first cracks, then held at that curvature.
struct BendingRun {
  double onset = -1;          // 1/m: curvature of the first crack (-1: none up to max_kappa)
  int pieces_at_onset = 0;    // connected pieces right after the first cracking step
  double shortest_edge = 0;   // m: shortest live rest edge right after it
  double median_edge = 0;     // m: median rest edge length of the initial mesh
  int cracks_while_held = 0;  // openings during the hold steps
};

BendingRun bend_until_crack(double alpha, double kappa_rate, double max_kappa, int hold_steps) {
  StripSpec s;
  s.length = 0.1;
  s.width = 0.02;
  s.cell = 0.0025;
  s.clamp = 0.003;  // two columns per end: the clamp holds the end's slope
  s.material = tough_sheet(50e9, 2e7, 1e-3);
  s.material.density = 2600;
  s.material.fracture_bending_mult = alpha;
  StripSim run;
  build(run, s);
  Simulation& sim = *run.sim;
  BendingRun out;
  out.median_edge = mesh_size_stats(sim.cloths[0].mesh).rest_edge_median;
  for (int step = 1; step * kappa_rate <= max_kappa + 1e-12; ++step) {
    const double kappa = step * kappa_rate;
    const auto place = [&](const Vec3& u) { return on_arc(u, s.length, kappa); };
    move_clamp(sim, 0, [&](const Vec3& u) { return u.x() < s.clamp + 1e-9; }, place);
    move_clamp(sim, 1, [&](const Vec3& u) { return u.x() > s.length - s.clamp - 1e-9; }, place);
    sim.advance_step();
    if (cracks_of_last_step(sim) > 0) {
      out.onset = kappa;
      break;
    }
  }
  if (out.onset < 0) return out;
  const Mesh& mesh = sim.cloths[0].mesh;
  EXPECT_EQ(check_mesh(mesh), "");
  out.pieces_at_onset = count_components(mesh);
  out.shortest_edge = mesh_size_stats(mesh).rest_edge_min;
  for (int step = 0; step < hold_steps; ++step) {
    sim.advance_step();  // the clamps stay where they are
    out.cracks_while_held += cracks_of_last_step(sim);
  }
  return out;
}

double critical_curvature(double alpha) {
  const double h = 1e-3;
  const double g = 2e7 / 50e9;                 // critical Green strain
  const double e = -1 + std::sqrt(1 + 2 * g);  // e + e^2/2 = g
  return 2 * e / (alpha * h);
}

// The onset, and the crack runs across in its step. Without remeshing the crack's cuts are kept from making
// slivers by the mesh's own edge length (snap and sliver limits): 17 um x 1 um faces were cut before, and the
// implicit step then failed to factorise their bending stiffness.
TEST(FractureBending, GlassStripCracksAtTheCriticalSurfaceStrain) {
  const double kappa_crit = critical_curvature(0.8);
  const BendingRun r = bend_until_crack(0.8, kappa_crit / 100, 2 * kappa_crit, 0);
  std::printf("bending: cracked at kappa %.4g 1/m, predicted %.4g 1/m; %d pieces; shortest edge %.3g mm "
              "(median %.3g mm)\n", r.onset, kappa_crit, r.pieces_at_onset, 1e3 * r.shortest_edge,
              1e3 * r.median_edge);
  ASSERT_GT(r.onset, 0) << "no crack up to twice the critical curvature";
  EXPECT_NEAR(r.onset, kappa_crit, 0.1 * kappa_crit);
  EXPECT_GE(r.pieces_at_onset, 2) << "the crack did not run across the strip";
  EXPECT_GE(r.shortest_edge, 0.05 * r.median_edge) << "a crack cut a sliver";
}

// DISABLED (issue 12, acceptance 4's aftermath, not met): held at the onset curvature, the broken strip should
// stop cracking. Measured 2026-12-02: since the virtual update iterates (fracture.virtual_iterations) the strip
// breaks in two at onset (13 pieces with the single linearised step), but held, each half relaxes straight along
// its clamp's tangent and the two halves jam lip against lip in the sheet's plane: the collision stage meets
// ill-conditioned impact zones from the next step on and the run does not finish within 10 minutes.
// Measured again 2026-12-02 afternoon, with split far ends set apart and stress-free lips: the run finishes in
// 0.7 s and breaks in 2 at onset, but 16 more cracks open while it is held.
TEST(FractureBending, DISABLED_HeldAtTheOnsetCurvatureTheBrokenStripStopsCracking) {
  const double kappa_crit = critical_curvature(0.8);
  const BendingRun r = bend_until_crack(0.8, kappa_crit / 100, 2 * kappa_crit, 20);
  ASSERT_GT(r.onset, 0);
  std::printf("held: %d pieces at onset, %d cracks while held\n", r.pieces_at_onset, r.cracks_while_held);
  EXPECT_LE(r.pieces_at_onset, 3) << "the strip shattered instead of breaking";
  EXPECT_EQ(r.cracks_while_held, 0);
}

TEST(FractureBending, WithoutBendingFractureTheSameCurvatureDoesNotCrack) {
  const double kappa_crit = critical_curvature(0.8);
  EXPECT_LT(bend_until_crack(0, kappa_crit / 50, 2 * kappa_crit, 0).onset, 0);
}

// Most compressive and most tensile principal Green strains over the live faces.
std::pair<double, double> extreme_strains(const Mesh& mesh) {
  double lowest = 0, highest = 0;
  for (const Face& f : mesh.faces) {
    if (f.dead) continue;
    const Vec3 x0 = mesh.nodes[mesh.verts[f.v[0]].node].x;
    Mat32 Ds;
    Ds.col(0) = mesh.nodes[mesh.verts[f.v[1]].node].x - x0;
    Ds.col(1) = mesh.nodes[mesh.verts[f.v[2]].node].x - x0;
    const Mat32 F = Ds * f.Dm_inv;
    const Mat2 G = 0.5 * (F.transpose() * F - Mat2::Identity());
    const Vec2 e = Eigen::SelfAdjointEigenSolver<Mat2>(G).eigenvalues();
    lowest = std::min(lowest, e(0));
    highest = std::max(highest, e(1));
  }
  return {lowest, highest};
}

// Pushed to 85% of its length over 150 steps from a 1 mm (1% of its length) sine imperfection, the strip
// buckles into an arch and never cracks, although its compressive strain passes the critical tensile strain:
// sigma+ drops compression. The critical strain (toughness / E = 0.06%) sits between the largest tensile strain
// the run reaches with fracture off (0.045%, measured 2026-12-02; some tension is real: the strip's ends and
// the arch's dynamics) and its largest compressive strain (0.068%). With a 0.1 mm imperfection it stayed flat
// until 0.4% compression and then snapped out of plane within one step, and that rebound stretched it past
// 0.1% at the arch's inflection lines, a real dynamic tension this test is not about.
TEST(FractureCompression, BucklingStripNeverCracks) {
  StripSpec s;
  const double critical = 6e-4;
  s.material = tough_sheet(1e9, critical * 1e9, 1e-3);
  s.size_min = 0.004;
  s.size_max = 0.01;
  StripSim run;
  build(run, s);
  Simulation& sim = *run.sim;
  // The imperfection w = A sin(pi x / L), laid out by arc length so that it does not stretch the strip:
  // x' = x - integral of w'^2 / 2 (a plain z offset stretched it by up to (pi A / L)^2 / 2 = 0.05%).
  const double A = 1e-3, k = M_PI / s.length;
  for (Node& n : sim.cloths[0].mesh.nodes) {
    const double x = n.x.x();
    n.x.z() += A * std::sin(k * x);
    n.x.x() = x - 0.5 * A * A * k * k * (0.5 * x + std::sin(2 * k * x) / (4 * k));
  }
  int cracks = 0;
  double bulge = 0, compression = 0, tension = 0;
  for (int step = 1; step <= 150; ++step) {
    const double shift = 0.15 * s.length * step / 150;
    move_clamp(sim, 0, [&](const Vec3& u) { return u.x() < s.clamp + 1e-9; }, [](const Vec3& u) { return u; });
    move_clamp(sim, 1, [&](const Vec3& u) { return u.x() > s.length - s.clamp - 1e-9; },
               [&](const Vec3& u) { return Vec3(u.x() - shift, u.y(), 0); });
    sim.advance_step();
    cracks += cracks_of_last_step(sim);
    const auto strains = extreme_strains(sim.cloths[0].mesh);
    compression = std::min(compression, strains.first);
    tension = std::max(tension, strains.second);
  }
  for (const Node& n : sim.cloths[0].mesh.nodes) bulge = std::max(bulge, std::abs(n.x.z()));
  std::printf("compression: bulge %.3g mm, most compressive Green strain %.3g, most tensile %.3g (critical "
              "tensile %.3g)\n", 1e3 * bulge, compression, tension, critical);
  EXPECT_GT(bulge, 0.1 * s.length) << "the strip did not buckle";
  EXPECT_LT(compression, -critical) << "the compression never reached the critical strain: proves nothing";
  EXPECT_EQ(cracks, 0);
}

}  // namespace
}  // namespace arcsim
