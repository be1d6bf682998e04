#include "collision/proximity.hpp"

#include <algorithm>
#include <cmath>

#include "collision/distance.hpp"

namespace arcsim {

Penalty repulsion_penalty(double gap, double k, double thickness) {
  const double depth = thickness - gap;
  if (!(depth > 0) || !(thickness > 0)) return {};
  return {k * depth * depth / (2 * thickness), k * depth / thickness};
}

double friction_damping(double mu, double normal_force, double tangential_speed, double effective_mass,
                        double dt) {
  if (!(mu > 0) || !(normal_force > 0) || !(dt > 0)) return 0;
  const double cap = kStickFactor * effective_mass / dt;
  if (!(tangential_speed > 0)) return cap;
  return std::min(mu * normal_force / tangential_speed, cap);
}

namespace {

// Which element slot a pair competes for: the nearest partner per (element, side) wins.
enum SlotKind { kNodeSlot, kEdgeSlot, kFaceSlot, kNodeLipSlot, kEdgeLipSlot, kSlotKinds };

struct Candidate {
  ProximityContact contact;
  double distance = kInfinity;
  std::array<std::pair<int, int>, 2> slots;  // (kind, 2 * element + side)
};

// What a candidate competes with: its distance (infinity if not within the thickness) and its two slots.
struct SlotClaim {
  double distance = kInfinity;
  std::array<std::pair<int, int>, 2> slots;
};

class ProximitySearch {
 public:
  ProximitySearch(const ContactGeometry& g, const ProximityParams& params)
      : g_(g), params_(params), face_normal_(face_normals(g, g.x0)) {
    node_normal_ = node_normals(g, face_normal_);
    edge_normal_ = edge_normals(g, face_normal_);
  }

  // The pair as a candidate contact, or distance = infinity if it is not within the thickness.
  Candidate evaluate(const PrimitivePair& p) const {
    Candidate c;
    const std::array<int, 4> nodes = pair_nodes(g_, p);
    const auto& x = g_.x0;
    ClosestPoints cp;
    double area_a = 0, area_b = 0;
    switch (p.kind) {
      case PairKind::kVertexFace:
        cp = vertex_face_closest(x[nodes[0]], x[nodes[1]], x[nodes[2]], x[nodes[3]]);
        area_a = g_.area[p.a];
        area_b = g_.face_area[p.b];
        c.slots = {{{kNodeSlot, side_slot(p.a, -cp.normal.dot(node_normal_[p.a]))},
                    {kFaceSlot, side_slot(p.b, cp.normal.dot(face_normal_[p.b]))}}};
        break;
      case PairKind::kEdgeEdge:
        cp = edge_edge_closest(x[nodes[0]], x[nodes[1]], x[nodes[2]], x[nodes[3]]);
        area_a = edge_area(p.a);
        area_b = edge_area(p.b);
        c.slots = {{{kEdgeSlot, side_slot(p.a, -cp.normal.dot(edge_normal_[p.a]))},
                    {kEdgeSlot, side_slot(p.b, cp.normal.dot(edge_normal_[p.b]))}}};
        break;
      case PairKind::kVertexEdge:
        cp = vertex_edge_closest(x[nodes[0]], x[nodes[1]], x[nodes[2]]);
        if (!outward_of_lip(p.b, nodes[0], cp)) return c;
        area_a = g_.area[p.a];
        area_b = edge_area(p.b);
        c.slots = {{{kNodeLipSlot, 2 * p.a}, {kEdgeLipSlot, 2 * p.b}}};
        break;
    }
    if (!(cp.distance < params_.thickness)) return c;
    const double thickness =
        material_neighbours(nodes, cp.weights) ? params_.neighbour_thickness : params_.thickness;
    if (!(cp.distance < thickness)) return c;
    c.distance = cp.distance;
    c.contact.nodes = nodes;
    c.contact.weights = cp.weights;
    c.contact.normal = cp.normal;
    c.contact.gap = cp.distance;
    c.contact.stiffness = params_.stiffness * std::min(area_a, area_b);
    c.contact.thickness = thickness;
    bool immovable = false;
    for (int n : nodes)
      if (n != kNone && !g_.movable(n)) immovable = true;
    c.contact.friction = immovable ? params_.obstacle_friction : params_.friction;
    return c;
  }

 private:
  static int side_slot(int element, double side) { return 2 * element + (side >= 0 ? 1 : 0); }

  // True if the pair's closest points are within the repulsion thickness of each other in the rest shape too:
  // then they are neighbours in the material (a crack's two lips: twins coincide in rest space, and the lips
  // meet at the tip), not two parts of the sheet that came together. Their penalty starts only at the
  // neighbour thickness (the gap new lips start with). WHY: with the full thickness and the penalty's
  // stiffness (ARCSim's glass: 1e13 N/m^3, 1e7 N/m on a 1 mm^2 node), a lip 2e-5 m from its twin was pushed
  // away with more than the membrane force at the critical stress (0.3-0.5 N against ~0.1 N). That wedged
  // every crack open at its tip, so it ran on, and each free shard of sphere-break.json held a
  // self-equilibrated strain of 1% (30 tau) that broke it again until the sphere was dust (4182 pieces by
  // step 90; 33 with this rule).
  bool material_neighbours(const std::array<int, 4>& nodes, const std::array<double, 4>& weights) const {
    return rest_distance(g_, nodes, weights) < params_.thickness;
  }

  double edge_area(int e) const {
    double a = 0;
    for (int f : g_.edge_faces[e])
      if (f != kNone) a += g_.face_area[f] / 3;
    return a;
  }

  // The vertex lies in the half-cylinder around boundary edge e on the side away from the edge's face, and
  // projects inside the edge (the lip of a crack facing the other lip).
  bool outward_of_lip(int e, int vertex, const ClosestPoints& cp) const {
    if (cp.weights[1] == 0 || cp.weights[2] == 0) return false;  // projects onto an end point
    const int f = g_.edge_faces[e][0] != kNone ? g_.edge_faces[e][0] : g_.edge_faces[e][1];
    if (f == kNone) return false;
    const auto& x = g_.x0;
    const int a = g_.edges[e][0], b = g_.edges[e][1];
    int opposite = kNone;
    for (int n : g_.faces[f])
      if (n != a && n != b) opposite = n;
    Vec3 outward = (x[b] - x[a]).cross(face_normal_[f]);
    if (outward.dot(x[opposite] - x[a]) > 0) outward = -outward;
    const Vec3 closest = x[vertex] - cp.distance * cp.normal;
    return outward.dot(x[vertex] - closest) > 0;
  }

  const ContactGeometry& g_;
  const ProximityParams& params_;
  std::vector<Vec3> face_normal_, node_normal_, edge_normal_;
};

}  // namespace

std::vector<ProximityContact> find_proximities(const ContactGeometry& g, BvhCache& cache,
                                               const ProximityParams& params) {
  CandidateOptions options;
  options.margin = params.thickness;
  options.swept = false;
  options.vertex_edge = true;
  const std::vector<PrimitivePair> pairs = find_candidates(g, cache, options);

  const ProximitySearch search(g, params);
  // First each pair's distance and slots only (most pairs are beyond the thickness); the kept pairs' contacts
  // are evaluated again afterwards, to the same values.
  std::vector<SlotClaim> claims(pairs.size());
#pragma omp parallel for schedule(dynamic, 64) if (pairs.size() > 2048)
  for (int k = 0; k < static_cast<int>(pairs.size()); ++k) {
    const Candidate c = search.evaluate(pairs[k]);
    claims[k] = {c.distance, c.slots};
  }

  // Nearest partner per slot; ties go to the earlier pair (deterministic). A slot is (kind, 2 * element + side),
  // its element a node, an edge or a face.
  const int elements = std::max({g.node_count(), static_cast<int>(g.edges.size()), static_cast<int>(g.faces.size())});
  std::vector<int> best(static_cast<size_t>(kSlotKinds) * 2 * elements, -1);
  const auto slot_index = [&](const std::pair<int, int>& slot) {
    return static_cast<size_t>(slot.first) * 2 * elements + slot.second;
  };
  for (int k = 0; k < static_cast<int>(claims.size()); ++k) {
    if (claims[k].distance == kInfinity) continue;
    for (const auto& slot : claims[k].slots) {
      int& holder = best[slot_index(slot)];
      if (holder < 0 || claims[k].distance < claims[holder].distance) holder = k;
    }
  }
  std::vector<char> kept(claims.size(), 0);
  for (const int holder : best)
    if (holder >= 0) kept[holder] = 1;

  std::vector<ProximityContact> contacts;
  for (size_t k = 0; k < claims.size(); ++k)
    if (kept[k]) contacts.push_back(search.evaluate(pairs[k]).contact);

  if (params.floor) {
    for (const auto& r : g.meshes) {
      if (!r.deformable) continue;
      for (int n = r.node_begin; n < r.node_end; ++n) {
        const double height = g.x0[n].y() - params.floor_height;
        if (!(height < params.thickness) || g.area[n] <= 0) continue;
        ProximityContact c;
        c.nodes = {n, kNone, kNone, kNone};
        c.weights = {1, 0, 0, 0};
        c.normal = Vec3::UnitY();
        c.gap = height;
        c.stiffness = params.stiffness * g.area[n];
        c.thickness = params.thickness;
        c.friction = params.obstacle_friction;
        contacts.push_back(c);
      }
    }
  }
  return contacts;
}

std::vector<ContactTerm> contact_terms(const ContactGeometry& g, const std::vector<ProximityContact>& contacts,
                                       int mesh, double dt) {
  const auto& r = g.meshes[mesh];
  std::vector<ContactTerm> terms;
  if (!r.deformable) return terms;  // immovable meshes have no implicit system
  for (const ProximityContact& c : contacts) {
    bool involved = false;
    for (int n : c.nodes)
      if (n != kNone && n >= r.node_begin && n < r.node_end) involved = true;
    if (!involved) continue;
    const Penalty p = repulsion_penalty(c.gap, c.stiffness, c.thickness);
    if (p.force <= 0 && p.stiffness <= 0) continue;

    ContactTerm t;
    t.normal = c.normal;
    t.force = p.force;
    t.stiffness = p.stiffness;
    Vec3 relative_velocity = Vec3::Zero();
    double inverse_mass = 0;
    for (int i = 0; i < 4; ++i) {
      const int n = c.nodes[i];
      if (n == kNone || c.weights[i] == 0) continue;
      relative_velocity += c.weights[i] * g.v[n];
      if (g.movable(n)) inverse_mass += c.weights[i] * c.weights[i] / g.mass[n];
      if (n >= r.node_begin && n < r.node_end) {
        t.nodes[i] = n - r.node_begin;
        t.weights[i] = c.weights[i];
      } else {
        t.outside_velocity += c.weights[i] * g.v[n];
      }
    }
    const Vec3 tangential = relative_velocity - c.normal * c.normal.dot(relative_velocity);
    if (inverse_mass > 0)
      t.friction_damping = friction_damping(c.friction, p.force, tangential.norm(), 1 / inverse_mass, dt);
    terms.push_back(t);
  }
  return terms;
}

bool contact_term_at_gap_change(ContactTerm& term, double gap_change) {
  if (!(term.stiffness > 0)) return false;
  // repulsion_penalty: force = k d^2 / (2T), stiffness = k d / T, so d = 2 force / stiffness, k/T = stiffness / d.
  const double depth = 2 * term.force / term.stiffness;
  const double moved = depth - gap_change;
  if (!(depth > 0) || !(moved > 0)) return false;
  const double k_over_thickness = term.stiffness / depth;
  term.force = 0.5 * k_over_thickness * moved * moved;
  term.stiffness = k_over_thickness * moved;
  term.outside_velocity = Vec3::Zero();
  return true;
}

}  // namespace arcsim
