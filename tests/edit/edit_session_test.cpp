// The edit session: cracks opened through it keep the plastic state, rest angles and plastic world shape of a
// plastically bent, curved-rest sheet; its stages run in the documented order for every kind of edit.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "collision/triangle_intersection.hpp"
#include "physics/plate_bending.hpp"
#include "physics/cloth_physics.hpp"
#include "edit/edit_fixtures.hpp"
#include "edit/edit_session.hpp"
#include "mesh/validate.hpp"
#include "physics/cloth_physics.hpp"
#include "remesh/remesh_fixtures.hpp"
#include "remesh/reprojection.hpp"
#include "restshape/reference_surface.hpp"

namespace arcsim {
namespace {

using test::BentSheet;
using test::distance_from_axis;
using test::make_plastically_bent_sheet;

double total_mass(Mesh& m, const std::vector<Material>& materials) {
  update_node_masses(m, materials);
  double mass = 0;
  for (const Node& n : m.nodes)
    if (!n.dead) mass += n.mass;
  return mass;
}

// An edge's identity through vertex splits: the rest positions of its ends (copies keep them exactly).
using EdgeKey = std::array<double, 6>;
EdgeKey edge_key(const Mesh& m, int e) {
  const Edge& edge = m.edges[e];
  const int f = edge.f[0] != kNone ? edge.f[0] : edge.f[1];
  std::array<Vec3, 2> u;
  for (int s = 0; s < 2; ++s) u[s] = m.verts[m.faces[f].v[m.corner_of_node(f, edge.n[s])]].u;
  if (std::lexicographical_compare(u[1].data(), u[1].data() + 3, u[0].data(), u[0].data() + 3)) std::swap(u[0], u[1]);
  return {u[0].x(), u[0].y(), u[0].z(), u[1].x(), u[1].y(), u[1].z()};
}

// The interior edge at `tip` that runs most nearly along `direction` in rest space (kNone if none): the
// farthest reach along it, less half the sideways offset, so that a crack follows a grid line.
int crack_edge(const Mesh& m, int tip, const Vec3& direction) {
  int best = kNone;
  double best_reach = -kInfinity;
  const Vec3& from = m.verts[m.nodes[tip].verts[0]].u;
  for (int e : m.nodes[tip].edges) {
    if (m.edges[e].is_boundary()) continue;
    const int far = m.edges[e].n[0] == tip ? m.edges[e].n[1] : m.edges[e].n[0];
    const Vec3 step = m.verts[m.nodes[far].verts[0]].u - from;
    const double along = step.dot(direction);
    const double reach = along - 0.5 * (step - along * direction).norm();
    if (reach > best_reach) best = e, best_reach = reach;
  }
  return best;
}

int far_end(const Mesh& m, int e, int tip) { return m.edges[e].n[0] == tip ? m.edges[e].n[1] : m.edges[e].n[0]; }

// Opens a crack from `tip` along `direction` for at most `steps` node splits, stopping where it reaches the
// border or another crack. Checks the mesh after every edit. Returns the number of splits.
int open_crack(EditSession& session, Mesh& m, int tip, const Vec3& direction, int steps,
               std::map<int, int>& origin) {
  int splits = 0;
  for (; splits < steps; ++splits) {
    const int cut = crack_edge(m, tip, direction);
    if (cut == kNone) break;
    const int next = far_end(m, cut, tip);
    const bool reaches_boundary = m.is_boundary_node(next);
    const EditResult r = session.split_node(tip, {cut});
    EXPECT_TRUE(r.ok);
    if (!r.ok) break;
    const std::string problem = check_mesh(m);
    EXPECT_EQ(problem, "") << "after node split " << splits;
    if (!problem.empty()) break;
    for (size_t i = 0; i < r.added_faces.size(); ++i) origin[r.added_faces[i]] = origin.at(r.removed_faces[i]);
    tip = next;
    if (reaches_boundary) return splits + 1;
  }
  return splits;
}

int node_near(const Mesh& m, const Vec3& u) {
  int best = kNone;
  for (size_t n = 0; n < m.nodes.size(); ++n) {
    if (m.nodes[n].dead) continue;
    const double d = (m.verts[m.nodes[n].verts[0]].u - u).norm();
    if (best == kNone || d < (m.verts[m.nodes[best].verts[0]].u - u).norm()) best = static_cast<int>(n);
  }
  return best;
}

TEST(EditSessionCrack, KeepsPlasticStateRestAnglesAndPlasticShape) {
  BentSheet s = make_plastically_bent_sheet(12, 8);
  Mesh& m = s.mesh;
  ASSERT_EQ(check_mesh(m), "");
  const double mass = total_mass(m, s.materials);
  std::vector<Mat3> Fp, Sp;
  std::map<int, int> origin;  // live face -> the face of the original sheet it is
  for (size_t f = 0; f < m.faces.size(); ++f) {
    Fp.push_back(m.faces[f].Fp);
    Sp.push_back(m.faces[f].Sp);
    origin[static_cast<int>(f)] = static_cast<int>(f);
  }
  std::map<EdgeKey, double> rest_theta;
  for (size_t e = 0; e < m.edges.size(); ++e) rest_theta[edge_key(m, static_cast<int>(e))] = m.edges[e].rest_theta;
  // The sheet holds plastic state worth keeping: Fp off the identity and a plastic curvature.
  ASSERT_GT((Fp[0] - Mat3::Identity()).norm(), 1e-3);
  ASSERT_GT(Sp[0].norm(), 0.1);

  EditSessionOptions options;
  EditSession session(m, s.materials, options);
  // Rest space: x = sin(phi), y along the axis. A crack from the middle of the phi = 0 border towards +phi,
  // stopped inside the sheet; a second one from the y = 0 border upwards until it meets the first; a third from
  // an interior node (two cuts) to the far border.
  const int first = open_crack(session, m, node_near(m, Vec3(0, 0.4, 1)), Vec3(1, 0, 0), 6, origin);
  EXPECT_EQ(first, 6);
  const int second = open_crack(session, m, node_near(m, Vec3(std::sin(0.5), 0, std::cos(0.5))), Vec3(0, 1, 0),
                                20, origin);
  EXPECT_GE(second, 2);
  const int middle = node_near(m, Vec3(std::sin(0.9), 0.2, std::cos(0.9)));
  ASSERT_FALSE(m.is_boundary_node(middle));
  const int cut_a = crack_edge(m, middle, Vec3(1, 0, 0)), cut_b = crack_edge(m, middle, Vec3(-1, 0, 0));
  const int tip = far_end(m, cut_a, middle);
  const EditResult r = session.split_node(middle, {cut_a, cut_b});
  ASSERT_TRUE(r.ok);
  ASSERT_EQ(check_mesh(m), "");
  for (size_t i = 0; i < r.added_faces.size(); ++i) origin[r.added_faces[i]] = origin.at(r.removed_faces[i]);
  const int third = open_crack(session, m, tip, Vec3(1, 0, 0), 20, origin);
  EXPECT_GE(third, 1);
  EXPECT_EQ(session.counts().node_splits, first + second + third + 1);
  EXPECT_TRUE(session.edited());

  // Faces on both sides of every crack keep Fp and Sp; every edge keeps its rest angle.
  int faces = 0, moved_faces = 0;
  for (size_t f = 0; f < m.faces.size(); ++f) {
    if (m.faces[f].dead) continue;
    ++faces;
    const int o = origin.at(static_cast<int>(f));
    moved_faces += o != static_cast<int>(f);
    EXPECT_LE((m.faces[f].Fp - Fp[o]).cwiseAbs().maxCoeff(), 1e-12) << "face " << f;
    EXPECT_LE((m.faces[f].Sp - Sp[o]).cwiseAbs().maxCoeff(), 1e-12) << "face " << f;
  }
  EXPECT_GT(moved_faces, 10);
  int lips = 0;
  for (size_t e = 0; e < m.edges.size(); ++e) {
    if (m.edges[e].dead) continue;
    const auto it = rest_theta.find(edge_key(m, static_cast<int>(e)));
    ASSERT_NE(it, rest_theta.end()) << "edge " << e << " is not an edge of the original sheet";
    EXPECT_LE(std::abs(m.edges[e].rest_theta - it->second), 1e-12) << "edge " << e;
    lips += m.edges[e].is_boundary();
  }
  EXPECT_GT(lips, 2 * (first + second + third + 2));
  // The world stays on the plastic shape: on the world cylinder, every interior dihedral at its rest angle.
  for (const Node& n : m.nodes) {
    if (!n.dead) {
      EXPECT_NEAR(distance_from_axis(n.x), s.world_radius, 1e-9);
    }
  }
  for (size_t e = 0; e < m.edges.size(); ++e) {
    if (!m.edges[e].dead && !m.edges[e].is_boundary()) {
      EXPECT_NEAR(m.world_dihedral(static_cast<int>(e)), m.edges[e].rest_theta, 1e-9);
    }
  }
  // Masses are conserved.
  EXPECT_NEAR(total_mass(m, s.materials), mass, 1e-12 * mass);
  EXPECT_EQ(faces, static_cast<int>(Fp.size()));
}

// The session reprojects the nodes a vertex split makes: a crack node pushed off the plastic shape returns to
// it, with each lip on its own side; without reprojection it stays off.
TEST(EditSessionCrack, ReprojectsSplitNodesOntoThePlasticShape) {
  for (bool reproject : {true, false}) {
    BentSheet s = make_plastically_bent_sheet(12, 8);
    Mesh& m = s.mesh;
    const int node = node_near(m, Vec3(std::sin(0.6), 0.4, std::cos(0.6)));
    const Vec3 on_shape = m.nodes[node].x;
    m.nodes[node].x += 2e-3 * on_shape.normalized();
    EditSessionOptions options;
    options.reproject = reproject;
    EditSession session(m, s.materials, options);
    const EditResult r = session.split_node(
        node, {crack_edge(m, node, Vec3(1, 0, 0)), crack_edge(m, node, Vec3(-1, 0, 0))});
    ASSERT_TRUE(r.ok);
    ASSERT_EQ(r.added_nodes.size(), 1u);
    ASSERT_EQ(check_mesh(m), "");
    for (int n : {node, r.added_nodes[0]}) {
      const double off = (m.nodes[n].x - on_shape).norm();
      if (reproject) {
        // Reprojection's Newton steps (a positive semi-definite Hessian) converge linearly across the sheet.
        EXPECT_LT(off, 0.2 * 2e-3) << "node " << n;
      } else {
        EXPECT_NEAR(off, 2e-3, 1e-15) << "node " << n;
      }
    }
    EXPECT_EQ(session.counts().reprojections, reproject ? 2 : 0);
  }
}

// --- hook order -------------------------------------------------------------------------------------------

struct StageRecorder : EditObserver {
  std::vector<std::string> stages;
  void stage_done(EditKind kind, EditStage stage, const EditResult& result) override {
    stages.push_back(std::string(edit_kind_name(kind)) + ":" + edit_stage_name(stage) + (result.ok ? "" : "-"));
  }
};

// The documented order (edit/edit_session.hpp); "-" marks stages reported before the edit succeeded.
std::vector<std::string> documented(const std::string& kind) {
  std::vector<std::string> order;
  for (const char* stage : {"guard_check-", "capture-", "topology", "track", "rest_positions", "rest_angles",
                            "plastic", "guard_moves", "reprojection", "done"})
    order.push_back(kind + ":" + stage);
  return order;
}

// A collapse that flags and boundaries rule out (a boundary node along an interior edge) is refused at the
// topology stage alone, before the world guard, exactly where the raw edit refuses it.
TEST(EditSessionHooks, ACollapseRuledOutByTheBoundaryIsRefusedBeforeTheGuard) {
  BentSheet s = make_plastically_bent_sheet(6, 4);
  Mesh& m = s.mesh;
  int edge = kNone, side = 0;
  for (size_t e = 0; e < m.edges.size() && edge == kNone; ++e) {
    if (m.edges[e].dead || m.edges[e].is_boundary()) continue;
    for (int k = 0; k < 2 && edge == kNone; ++k)
      if (m.is_boundary_node(m.edges[e].n[k]) && !m.nodes[m.edges[e].n[k]].preserve) edge = static_cast<int>(e), side = k;
  }
  ASSERT_NE(edge, kNone);
  EXPECT_FALSE(collapse_edge_precheck(m, edge, side));
  Mesh raw = m;
  EXPECT_FALSE(collapse_edge(raw, edge, side).ok);

  EditSession session(m, s.materials, EditSessionOptions());
  StageRecorder recorder;
  session.add_observer(&recorder);
  const size_t faces = m.faces.size();
  EXPECT_FALSE(session.collapse_edge(edge, side).ok);
  EXPECT_EQ(recorder.stages, std::vector<std::string>{"collapse_edge:topology-"});
  EXPECT_EQ(session.counts().guarded, 0);
  EXPECT_EQ(m.faces.size(), faces);
  EXPECT_FALSE(m.edges[edge].dead);
}

TEST(EditSessionHooks, RunInTheDocumentedOrderForEveryEdit) {
  BentSheet s = make_plastically_bent_sheet(6, 4);
  Mesh& m = s.mesh;
  EditSessionOptions options;
  EditSession session(m, s.materials, options);
  StageRecorder recorder;
  session.add_observer(&recorder);

  // Split of an interior edge.
  int interior = kNone;
  for (size_t e = 0; e < m.edges.size() && interior == kNone; ++e)
    if (!m.edges[e].is_boundary() && !m.is_boundary_node(m.edges[e].n[0]) && !m.is_boundary_node(m.edges[e].n[1]))
      interior = static_cast<int>(e);
  ASSERT_NE(interior, kNone);
  const EditResult split = session.split_edge(interior, 0.5);
  ASSERT_TRUE(split.ok);
  EXPECT_EQ(recorder.stages, documented("split_edge"));

  bool flipped = false;
  for (size_t e = 0; e < m.edges.size() && !flipped; ++e) {
    if (m.edges[e].dead || m.edges[e].is_boundary()) continue;
    recorder.stages.clear();
    flipped = session.flip_edge(static_cast<int>(e)).ok;
  }
  ASSERT_TRUE(flipped);
  EXPECT_EQ(recorder.stages, documented("flip_edge"));

  recorder.stages.clear();
  const int new_edge = m.nodes[split.added_nodes[0]].edges[0];
  const int side = m.edges[new_edge].n[0] == split.added_nodes[0] ? 0 : 1;
  ASSERT_TRUE(session.collapse_edge(new_edge, side).ok);
  EXPECT_EQ(recorder.stages, documented("collapse_edge"));

  recorder.stages.clear();
  int middle = kNone;
  for (size_t n = 0; n < m.nodes.size() && middle == kNone; ++n)
    if (!m.nodes[n].dead && !m.is_boundary_node(static_cast<int>(n))) middle = static_cast<int>(n);
  std::vector<int> cuts;
  for (int e : m.nodes[middle].edges)
    if (cuts.size() < 2 && !m.edges[e].is_boundary())
      cuts.push_back(e);
  ASSERT_TRUE(session.split_node(middle, cuts).ok);
  EXPECT_EQ(recorder.stages, documented("split_node"));

  // A refused edit stops at the stage that refused it: a boundary edge cannot be flipped.
  recorder.stages.clear();
  int boundary = kNone;
  for (size_t e = 0; e < m.edges.size() && boundary == kNone; ++e)
    if (!m.edges[e].dead && m.edges[e].is_boundary()) boundary = static_cast<int>(e);
  EXPECT_FALSE(session.flip_edge(boundary).ok);
  EXPECT_EQ(recorder.stages, (std::vector<std::string>{"flip_edge:guard_check-", "flip_edge:capture-",
                                                       "flip_edge:topology-"}));
  EXPECT_EQ(session.counts().splits, 1);
  EXPECT_EQ(session.counts().flips, 1);
  EXPECT_EQ(session.counts().collapses, 1);
  EXPECT_EQ(session.counts().node_splits, 1);
}

// Stages see the mesh in the state the order promises: nothing is edited before kCapture has run, the new faces
// exist from kTopology on, the new rest vert reaches the reference surface at kRestPositions and the node's
// world position follows it there.
struct StateProbe : EditObserver {
  Mesh* mesh = nullptr;
  const ReferenceSurface* reference = nullptr;
  size_t faces_before = 0;
  double radius = 0;
  std::vector<std::string> problems;
  std::map<EditStage, double> world_off, rest_off;  // node's distance off the world shape, vert's off the reference
  void stage_done(EditKind kind, EditStage stage, const EditResult& r) override {
    if (stage == EditStage::kCapture && mesh->faces.size() != faces_before) problems.push_back("edited before capture");
    if (stage == EditStage::kTopology && r.ok && mesh->faces.size() == faces_before)
      problems.push_back("no new faces after topology");
    if (!r.ok || r.added_nodes.empty()) return;
    world_off[stage] = std::abs(radius - distance_from_axis(mesh->nodes[r.added_nodes[0]].x));
    const Vec3& u = mesh->verts[r.added_verts[0]].u;
    rest_off[stage] = (reference->closest_point(u) - u).norm();
  }
};

TEST(EditSessionHooks, StagesSeeTheMeshInTheDocumentedState) {
  BentSheet s = make_plastically_bent_sheet(6, 4);
  Mesh& m = s.mesh;
  const std::unique_ptr<ReferenceSurface> reference = make_mesh_reference(test::make_cylinder_patch(60, 4, 1.0, 1.2, 0.8));
  EditSessionOptions options;
  options.reference = reference.get();
  EditSession session(m, s.materials, options);
  StateProbe probe;
  probe.mesh = &m;
  probe.reference = reference.get();
  probe.faces_before = m.faces.size();
  probe.radius = s.world_radius;
  session.add_observer(&probe);
  // A circumferential interior edge: its midpoint lies on the chord, inside both cylinders.
  int edge = kNone;
  for (size_t e = 0; e < m.edges.size() && edge == kNone; ++e) {
    const Edge& ed = m.edges[e];
    if (!ed.is_boundary() && std::abs(m.nodes[ed.n[0]].x.y() - m.nodes[ed.n[1]].x.y()) < 1e-12)
      edge = static_cast<int>(e);
  }
  ASSERT_NE(edge, kNone);
  ASSERT_TRUE(session.split_edge(edge, 0.5).ok);
  EXPECT_TRUE(probe.problems.empty()) << probe.problems.front();
  // The fine reference differs from the coarse chords by their sagitta (~5 mm) at most.
  EXPECT_GT(probe.rest_off[EditStage::kTrack], 1e-3);
  EXPECT_LT(probe.rest_off[EditStage::kRestPositions], 1e-4);
  EXPECT_GT(probe.world_off[EditStage::kTrack], 1e-3);
  EXPECT_LT(probe.world_off[EditStage::kRestPositions], 0.5 * probe.world_off[EditStage::kTrack]);
}

namespace arcsim {
namespace {

// Bending energy (J) of the mesh's plate bending elements.
double bending_energy_of(const Mesh& m, const std::vector<Material>& materials) {
  ElementCache cache;
  build_element_cache(m, materials, cache);
  double e = 0;
  for (const auto& b : cache.bending) {
    std::array<Vec3, 6> x;
    for (int i = 0; i < 6; ++i) x[i] = m.nodes[b.nodes[i]].x;
    e += plate_bending_terms(x, b.has_wing, b.rest_theta, b.Q, HessianKind::kNone).energy;
  }
  return e;
}

// A stress-free move (a crack's lip gap) on a bent sheet leaves its bending energy as it was: the hinges it
// kinks turn their rest angles with it. Before, a 0.2 mm gap over small faces of a bent steel sheet added
// joules per step (docs/stability.md, 2026-12-05).
TEST(EditSessionStressFreeMove, KeepsTheBendingEnergyOfABentSheet) {
  BentSheet s = make_plastically_bent_sheet(12, 8);
  Mesh& m = s.mesh;
  int node = -1;
  for (size_t n = 0; n < m.nodes.size() && node < 0; ++n)
    if (!m.is_boundary_node(static_cast<int>(n))) node = static_cast<int>(n);
  ASSERT_GE(node, 0);
  const double before = bending_energy_of(m, s.materials);
  EditSessionOptions options;
  EditSession session(m, s.materials, options);
  NodeMoveOptions move;
  move.stress_free = true;
  // Along a world axis, not the sheet's tangent plane: the move kinks the hinges round the node.
  ASSERT_TRUE(session.move_node(node, Vec3(0.3, 0.3, 0.3).normalized() * 2e-3, move));
  const double after = bending_energy_of(m, s.materials);
  EXPECT_NEAR(after, before, 1e-9 + 1e-6 * before) << "bending energy before " << before << " J";
}

}  // namespace
}  // namespace arcsim

namespace fold_test {

// Pairs of faces sharing exactly one node that meet elsewhere too (each shrunk by 1e-6 towards its centroid, so
// that the shared node itself no longer counts): a fold of the surface through itself, which `arcsim inspect`
// does not see while the two faces share the node, and sees once an edit splits one of them.
int folded_pairs(const Mesh& m) {
  auto shrunk = [&](int f) {
    std::array<Vec3, 3> t;
    Vec3 c = Vec3::Zero();
    for (int i = 0; i < 3; ++i) c += m.nodes[m.face_node(f, i)].x / 3;
    for (int i = 0; i < 3; ++i) t[i] = c + (1 - 1e-6) * (m.nodes[m.face_node(f, i)].x - c);
    return t;
  };
  int count = 0;
  for (size_t f = 0; f < m.faces.size(); ++f)
    for (size_t g = f + 1; g < m.faces.size(); ++g) {
      if (m.faces[f].dead || m.faces[g].dead) continue;
      int shared = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) shared += m.face_node(int(f), i) == m.face_node(int(g), j);
      if (shared == 1 && triangles_intersect(shrunk(int(f)), shrunk(int(g)))) ++count;
    }
  return count;
}

// A crumpled hexagonal fan: centre node 0, ring nodes 1-6 (unit radius) alternately 0.3 up and down.
Mesh crumpled_fan() {
  std::vector<Vec3> p{Vec3::Zero()};
  for (int k = 0; k < 6; ++k)
    p.emplace_back(std::cos(k * M_PI / 3), std::sin(k * M_PI / 3), k % 2 ? 0.3 : -0.3);
  std::vector<std::array<int, 3>> tris;
  for (int k = 0; k < 6; ++k) tris.push_back({0, 1 + k, 1 + (k + 1) % 6});
  return remesh_test::mesh_from(p, tris);
}

}  // namespace fold_test

// A node moved across its own fan (here past the ring node it heads for) folds faces of the fan through each
// other. The world guard skipped every face the moving faces touch, so it kept such moves: an edge split's
// reprojection next to a crack tip moved its node 2 mm through a 3 mm fan, and the local remesh that refined the
// two faces afterwards left 146 crossing pairs (docs/repro/glass-plate-shards-coincident-lips.json, step 21).
TEST(EditSessionGuard, RefusesANodeMoveThatFoldsItsFanThroughItself) {
  const std::vector<Material> materials{remesh_test::glass()};
  const Vec3 across(1.6, 0.05, 0.0);  // m: the centre to beyond ring node 1 at (1, 0, -0.3)
  {
    // The premise: unguarded, the move is kept and folds the fan.
    Mesh m = fold_test::crumpled_fan();
    ASSERT_EQ(fold_test::folded_pairs(m), 0);
    EditSession session(m, materials, EditSessionOptions{});
    ASSERT_TRUE(session.move_node(0, across));
    ASSERT_GT(fold_test::folded_pairs(m), 0);
  }
  Mesh m = fold_test::crumpled_fan();
  EditSessionOptions options;
  options.world_clearance = 1e-4;
  EditSession session(m, materials, options);
  const std::vector<int> fan = m.node_faces(0);
  EXPECT_FALSE(session.move_allowed(0, fan, across));
  EXPECT_FALSE(session.move_node(0, across));
  EXPECT_EQ(m.nodes[0].x, Vec3::Zero());
  EXPECT_EQ(fold_test::folded_pairs(m), 0);
  // A short move within the fan stays allowed.
  EXPECT_TRUE(session.move_allowed(0, fan, Vec3(0.2, 0.05, 0)));
  EXPECT_TRUE(session.move_node(0, Vec3(0.2, 0.05, 0)));
  EXPECT_EQ(fold_test::folded_pairs(m), 0);
}

}  // namespace
}  // namespace arcsim
