// Proximity contacts (selection, gaps, stiffness, friction, floor proxy, crack-lip vertex-edge pairs, material
// neighbours), the
// penalty's derivatives, friction damping, the conversion into implicit-step terms, and the contact pattern.
#include <gtest/gtest.h>

#include <cmath>

#include "collision/proximity.hpp"
#include "mesh/edits.hpp"
#include "mesh/validate.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

constexpr double kT = 1e-3;  // repulsion thickness (m)

// A static 2 x 2 m plate of two triangles in z = 0 and a small sheet hovering `height` above it.
struct SheetOverPlate {
  Mesh sheet, plate;
  ContactGeometry g;
  explicit SheetOverPlate(double height, int cells = 2) {
    // Off the plate's diagonal (y = x), so that every sheet node has a unique nearest plate face.
    sheet = testing::make_grid(cells, cells, 0.2, 0.2, testing::Diagonal::kForward, 0.3, 0.35);
    for (Node& n : sheet.nodes) {
      n.x.z() = height;
      n.mass = 1e-3;
      n.v = Vec3(0.1, 0, -0.2);
    }
    plate = testing::make_grid(1, 1, 2, 2, testing::Diagonal::kForward, -1, -1);
    for (Node& n : plate.nodes) n.x0 = n.x;
    build();
  }
  void build() { build_contact_geometry({{&sheet, true}, {&plate, false}}, ContactStage::kBeforeStep, 1e-3, g); }
};

ProximityParams params() {
  ProximityParams p;
  p.thickness = kT;
  p.stiffness = 1e9;
  p.friction = 0.6;
  p.obstacle_friction = 0.3;
  return p;
}

TEST(Proximity, PenaltyIsTheDerivativeOfTheCubicEnergy) {
  const double k = 2e5;
  auto energy = [&](double g) { return g < kT ? k * std::pow(kT - g, 3) / (6 * kT) : 0.0; };
  for (double g : {-2e-4, 0.0, 3e-4, 9e-4}) {
    const Penalty p = repulsion_penalty(g, k, kT);
    const double h = 1e-9;
    EXPECT_NEAR(p.force, -(energy(g + h) - energy(g - h)) / (2 * h), 1e-6 * p.force + 1e-9);
    const Penalty q = repulsion_penalty(g + h, k, kT), r = repulsion_penalty(g - h, k, kT);
    EXPECT_NEAR(p.stiffness, -(q.force - r.force) / (2 * h), 1e-5 * p.stiffness);
  }
  EXPECT_EQ(repulsion_penalty(kT, k, kT).force, 0.0);
  EXPECT_EQ(repulsion_penalty(2 * kT, k, kT).stiffness, 0.0);
}

TEST(Proximity, ContactTermAtAGapChangeFollowsThePenaltyLaw) {
  const double k = 2e5;
  for (double gap : {-2e-4, 0.0, 3e-4, 9e-4}) {
    for (double change : {-3e-4, -1e-5, 0.0, 5e-5, 4e-4}) {
      const Penalty p = repulsion_penalty(gap, k, kT);
      ContactTerm term;
      term.force = p.force;
      term.stiffness = p.stiffness;
      term.outside_velocity = Vec3(0.1, 0.2, 0.3);
      const Penalty expected = repulsion_penalty(gap + change, k, kT);
      const bool touching = contact_term_at_gap_change(term, change);
      EXPECT_EQ(touching, expected.stiffness > 0) << gap << " " << change;
      if (!touching) continue;
      EXPECT_NEAR(term.force, expected.force, 1e-9 * expected.force + 1e-15) << gap << " " << change;
      EXPECT_NEAR(term.stiffness, expected.stiffness, 1e-9 * expected.stiffness) << gap << " " << change;
      EXPECT_EQ(term.outside_velocity, Vec3::Zero());  // the other side is at rest in the re-evaluated term
    }
  }
  ContactTerm none;  // a term without stiffness (no depth) never touches
  EXPECT_FALSE(contact_term_at_gap_change(none, -1e-4));
}

TEST(Proximity, FrictionDampingIsCoulombWhileSlidingAndCappedWhenSticking) {
  const double m = 1e-3, dt = 1e-3;
  // Sliding fast: the force c |u_t| is mu f_n.
  EXPECT_NEAR(friction_damping(0.5, 2.0, 0.4, m, dt) * 0.4, 0.5 * 2.0, 1e-12);
  // Sticking: capped at kStickFactor m / dt.
  EXPECT_DOUBLE_EQ(friction_damping(0.5, 2.0, 0.0, m, dt), kStickFactor * m / dt);
  EXPECT_DOUBLE_EQ(friction_damping(0.5, 2.0, 1e-12, m, dt), kStickFactor * m / dt);
  EXPECT_EQ(friction_damping(0.0, 2.0, 0.4, m, dt), 0.0);
}

TEST(Proximity, SheetNodesNearPlateGetOneContactEach) {
  SheetOverPlate s(0.4 * kT);
  BvhCache cache;
  const auto contacts = find_proximities(s.g, cache, params());
  // Every sheet node is above the plate's interior: one vertex-face contact per node (the plate's other face
  // is farther or on the same side), plus edge-edge contacts only with the plate's diagonal.
  int vertex_face = 0;
  for (const auto& c : contacts) {
    EXPECT_NEAR(c.gap, 0.4 * kT, 1e-12);
    EXPECT_NEAR(c.normal.z(), 1.0, 1e-9);
    EXPECT_DOUBLE_EQ(c.friction, 0.3);
    if (c.weights[0] == 1 && s.g.movable(c.nodes[0]) && !s.g.movable(c.nodes[1])) {
      ++vertex_face;
      // k = stiffness * min(node area, face area): the node's area is the smaller.
      EXPECT_NEAR(c.stiffness, 1e9 * s.g.area[c.nodes[0]], 1e-6);
    }
  }
  EXPECT_EQ(vertex_face, static_cast<int>(s.sheet.nodes.size()));
}

TEST(Proximity, NothingBeyondTheThickness) {
  SheetOverPlate s(1.5 * kT);
  BvhCache cache;
  EXPECT_TRUE(find_proximities(s.g, cache, params()).empty());
}

TEST(Proximity, FloorProxyActsOnNodesWithinTheThickness) {
  SheetOverPlate s(0.5);  // far above the plate (z); spans y in [0.35, 0.55] in rows 0.1 apart
  for (Node& n : s.sheet.nodes) n.x.y() += 0.2 * kT;
  s.build();
  ProximityParams p = params();
  p.floor = true;
  p.floor_height = 0.35;  // just under the bottom row
  BvhCache cache;
  const auto contacts = find_proximities(s.g, cache, p);
  int near = 0;
  for (const Node& n : s.sheet.nodes) near += n.x.y() - 0.35 < kT;
  ASSERT_EQ(static_cast<int>(contacts.size()), near);
  EXPECT_EQ(near, 3);  // the bottom row of the 2 x 2 grid
  for (const auto& c : contacts) {
    EXPECT_EQ(c.normal, Vec3::UnitY());
    EXPECT_NEAR(c.gap, 0.2 * kT, 1e-12);
    EXPECT_DOUBLE_EQ(c.friction, 0.3);
  }
}

TEST(Proximity, NearestFacePerSideIsKept) {
  // Two parallel static plates 0.3 T and 0.8 T below a single-triangle sheet, and none above: each sheet node
  // keeps only its nearest face (the upper plate) on that side, but each lower-plate face keeps its nearest
  // node, so the lower plate contributes at most one vertex-face contact per face.
  // The sheet lies entirely over one triangle of each plate (away from their diagonals y = x).
  Mesh sheet = testing::make_grid(1, 1, 0.1, 0.1, testing::Diagonal::kForward, 0.2, 0.0);
  for (Node& n : sheet.nodes) n.x.z() = 0.8 * kT, n.mass = 1e-3;
  Mesh upper = testing::make_grid(1, 1, 1, 1, testing::Diagonal::kForward, -0.45, -0.45);
  Mesh lower = upper;
  for (Node& n : upper.nodes) n.x.z() = n.x0.z() = 0.5 * kT;
  for (Node& n : lower.nodes) n.x0 = n.x;
  ContactGeometry g;
  build_contact_geometry({{&sheet, true}, {&upper, false}, {&lower, false}}, ContactStage::kBeforeStep, 1e-3, g);
  BvhCache cache;
  const auto contacts = find_proximities(g, cache, params());
  int with_upper = 0, with_lower = 0;
  const int lower_begin = g.meshes[2].node_begin;
  for (const auto& c : contacts) {
    if (!g.movable(c.nodes[0]) || g.movable(c.nodes[1])) continue;  // sheet vertex against plate face only
    (c.nodes[1] >= lower_begin ? with_lower : with_upper) += 1;
  }
  EXPECT_EQ(with_upper, 4);
  EXPECT_LE(with_lower, 2);
}

TEST(Proximity, CrackLipVertexEdgePairsOnTheOutwardSide) {
  // Two coplanar strips whose facing boundaries are 0.5 T apart: boundary nodes of one see boundary edges of
  // the other, on the outward side of those edges.
  Mesh a = testing::make_grid(4, 1, 0.4, 0.1);
  Mesh b = testing::make_grid(4, 1, 0.4, 0.1, testing::Diagonal::kForward, 0.0, 0.1 + 0.5 * kT);
  for (Node& n : a.nodes) n.mass = 1e-3;
  for (Node& n : b.nodes) n.mass = 1e-3;
  // Shift b along x so its nodes project inside a's edges.
  for (Node& n : b.nodes) n.x.x() += 0.05;
  ContactGeometry g;
  build_contact_geometry({{&a, true}, {&b, true}}, ContactStage::kBeforeStep, 1e-3, g);
  BvhCache cache;
  const auto contacts = find_proximities(g, cache, params());
  int lips = 0;
  for (const auto& c : contacts) {
    if (c.nodes[3] != kNone) continue;  // vertex-edge pairs use three nodes
    ++lips;
    EXPECT_NEAR(c.gap, 0.5 * kT, 1e-12);
    EXPECT_NEAR(std::abs(c.normal.y()), 1.0, 1e-9);  // in the sheets' plane, across the gap
    EXPECT_DOUBLE_EQ(c.friction, 0.6);               // deformable-deformable
  }
  // Inner nodes of each facing boundary (3 per strip) project inside an edge of the other.
  EXPECT_GE(lips, 6);
  // Overlapping instead (b pushed into a by 0.5 T): the nodes are behind the edges, no lip pair.
  for (Node& n : b.nodes) n.x.y() -= kT;
  build_contact_geometry({{&a, true}, {&b, true}}, ContactStage::kBeforeStep, 1e-3, g);
  for (const auto& c : find_proximities(g, cache, params())) EXPECT_NE(c.nodes[3], kNone);
}

TEST(Proximity, ContactTermsSplitPerCloth) {
  SheetOverPlate s(0.5 * kT);
  // The plate moves up at 0.05 m/s: its velocity enters the relative velocity of the sheet's terms.
  for (Node& n : s.plate.nodes) n.x = n.x0 + Vec3(0, 0, 0.05 * 1e-3);
  s.build();
  BvhCache cache;
  const auto contacts = find_proximities(s.g, cache, params());
  const auto terms = contact_terms(s.g, contacts, 0, 1e-3);
  ASSERT_FALSE(terms.empty());
  for (const ContactTerm& t : terms) {
    EXPECT_GT(t.force, 0);
    EXPECT_GT(t.stiffness, 0);
    EXPECT_GT(t.friction_damping, 0);  // sliding at 0.1 m/s
    for (int i = 0; i < 4; ++i) {
      if (t.nodes[i] != kNone) {
        EXPECT_LT(t.nodes[i], static_cast<int>(s.sheet.nodes.size()));
      }
    }
    // Plate nodes are outside this cloth: their weighted velocity (up, z) is carried along.
    if (t.weights[0] == 1 && t.nodes[1] == kNone) {
      EXPECT_NEAR(t.outside_velocity.z(), -0.05, 1e-9);
    }
  }
  // Nothing for the plate (immovable, no cloth of its own).
  EXPECT_TRUE(contact_terms(s.g, contacts, 1, 1e-3).empty());
}

TEST(Proximity, ContactPatternRebuiltOnlyForNewPairs) {
  Mesh sheet = testing::make_grid(3, 3, 0.3, 0.3);
  std::vector<Material> materials(1);
  materials[0].thickness = 1e-3;
  materials[0].density = 100;
  materials[0].youngs_modulus = 1e6;
  for (Face& f : sheet.faces) f.thickness = 1e-3;
  update_node_masses(sheet, materials);
  ElementCache cache;
  build_element_cache(sheet, materials, cache);
  const uint64_t base = cache.pattern.id();
  ContactTerm adjacent;  // nodes of one face: already in the pattern
  adjacent.nodes = {0, 1, 5, kNone};
  EXPECT_FALSE(update_contact_pattern(cache, {adjacent}));
  EXPECT_EQ(cache.pattern.id(), base);
  ContactTerm far;  // opposite corners: a new pair
  far.nodes = {0, 15, kNone, kNone};
  EXPECT_TRUE(update_contact_pattern(cache, {far}));
  EXPECT_GE(cache.pattern.block_index(15, 0), 0);
  const uint64_t with_far = cache.pattern.id();
  // Same pairs again, or fewer: kept.
  EXPECT_FALSE(update_contact_pattern(cache, {far}));
  EXPECT_FALSE(update_contact_pattern(cache, {}));
  EXPECT_EQ(cache.pattern.id(), with_far);
}

}  // namespace
}  // namespace arcsim

namespace arcsim {
namespace {

// A 0.4 x 0.2 m sheet (4 x 2 cells) cut in two along its middle row of edges, y = 0.1 (a crack run from border
// to border): the two halves' facing lips coincide in the rest shape. The upper half is then moved up by
// `gap` (m) in the world, so the lips are `gap` apart.
Mesh cracked_sheet(double gap) {
  Mesh m = testing::make_grid(4, 2, 0.4, 0.2);
  auto id = [](int i, int j) { return j * 5 + i; };
  for (int i = 0; i < 4; ++i) {
    const EditResult r = split_node(m, id(i, 1), {m.find_edge(id(i, 1), id(i + 1, 1))});
    EXPECT_TRUE(r.ok) << "split at node " << id(i, 1);
  }
  EXPECT_EQ(count_components(m), 2);
  for (Node& n : m.nodes) n.mass = 1e-3;
  // The upper half: nodes whose faces all lie above the cut.
  for (size_t k = 0; k < m.nodes.size(); ++k) {
    bool upper = true;
    for (int f : m.node_faces(static_cast<int>(k)))
      for (int i = 0; i < 3; ++i) upper = upper && m.verts[m.faces[f].v[i]].u.y() > 0.1 - 1e-12;
    if (upper) m.nodes[k].x.y() += gap;
  }
  for (Node& n : m.nodes) n.x0 = n.x;
  return m;
}

int contacts_across(const std::vector<ProximityContact>& contacts, double* thickness = nullptr) {
  int count = 0;
  for (const auto& c : contacts) {
    if (std::abs(c.normal.y()) < 0.99) continue;  // across the cut: in the sheet's plane, along y
    ++count;
    if (thickness) *thickness = c.thickness;
  }
  return count;
}

TEST(Proximity, CrackLipsAreMaterialNeighboursThatRepelOnlyWithinTheNeighbourThickness) {
  // Lips 0.5 T apart, twins coincident in the rest shape: with the full thickness between them they would be
  // pushed apart at once (a wedge at every crack tip); they repel only within the neighbour thickness.
  const Mesh m = cracked_sheet(0.5 * kT);
  ContactGeometry g;
  build_contact_geometry({{&m, true}}, ContactStage::kBeforeStep, 1e-3, g);
  BvhCache cache;
  ProximityParams p = params();
  EXPECT_EQ(contacts_across(find_proximities(g, cache, p)), 0);  // neighbour thickness 0: never
  p.neighbour_thickness = 0.25 * kT;                                // still closer than the lips are
  EXPECT_EQ(contacts_across(find_proximities(g, cache, p)), 0);
  p.neighbour_thickness = 0.75 * kT;                                // the lips came closer than that
  double thickness = 0;
  const auto contacts = find_proximities(g, cache, p);
  EXPECT_GE(contacts_across(contacts, &thickness), 3);
  EXPECT_DOUBLE_EQ(thickness, 0.75 * kT);
  // Their terms follow the contact's own thickness: the cubic penalty's force / stiffness is half the depth,
  // 0.5 (0.75 T - 0.5 T) (with the full thickness it would be 0.25 T).
  int terms = 0;
  for (const ContactTerm& t : contact_terms(g, contacts, 0, 1e-3)) {
    if (std::abs(t.normal.y()) < 0.99) continue;
    ++terms;
    EXPECT_NEAR(t.force / t.stiffness, 0.125 * kT, 1e-12);
  }
  EXPECT_GE(terms, 3);
}

TEST(Proximity, PartsOfOneSheetFarApartInTheRestShapeRepelAtTheFullThickness) {
  // The same sheet, its upper half laid back over its lower half 0.5 T above it (a fold): those points are
  // 0.1 m apart in the rest shape, so they are a collision, whatever the neighbour thickness.
  Mesh m = cracked_sheet(0);
  for (size_t k = 0; k < m.nodes.size(); ++k) {
    bool upper = true;
    for (int f : m.node_faces(static_cast<int>(k)))
      for (int i = 0; i < 3; ++i) upper = upper && m.verts[m.faces[f].v[i]].u.y() > 0.1 - 1e-12;
    Node& n = m.nodes[k];
    if (upper) n.x = Vec3(n.x.x(), 0.2 - n.x.y(), 0.5 * kT);
  }
  for (Node& n : m.nodes) n.x0 = n.x;
  ContactGeometry g;
  build_contact_geometry({{&m, true}}, ContactStage::kBeforeStep, 1e-3, g);
  BvhCache cache;
  int stacked = 0;
  for (const auto& c : find_proximities(g, cache, params())) {
    if (std::abs(c.normal.z()) < 0.99) continue;
    ++stacked;
    EXPECT_DOUBLE_EQ(c.thickness, kT);
    EXPECT_NEAR(c.gap, 0.5 * kT, 1e-7);
  }
  EXPECT_GE(stacked, 6);
}

}  // namespace
}  // namespace arcsim
