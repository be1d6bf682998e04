#include "fracture/crack_opening.hpp"

#include <algorithm>
#include <array>

#include "remesh/world_guard.hpp"

namespace arcsim {
namespace {

// The node's corner of one face in rest space: the node at u, the far end of edge_out at u_out, the far end of
// edge_in at u_in (CCW from out to in about the rest normal), and the opposite edge joining node_out -> node_in.
struct Wedge {
  int face = kNone;
  int edge_out = kNone, edge_in = kNone, opposite = kNone;
  int node_out = kNone, node_in = kNone;
  Vec3 u = Vec3::Zero(), u_out = Vec3::Zero(), u_in = Vec3::Zero(), normal = Vec3::UnitZ();
};

Wedge wedge_at(const Mesh& m, int face, int corner) {
  const Face& f = m.faces[face];
  Wedge w;
  w.face = face;
  w.edge_out = f.e[corner];
  w.opposite = f.e[(corner + 1) % 3];
  w.edge_in = f.e[(corner + 2) % 3];
  w.node_out = m.face_node(face, (corner + 1) % 3);
  w.node_in = m.face_node(face, (corner + 2) % 3);
  w.u = m.verts[f.v[corner]].u;
  w.u_out = m.verts[f.v[(corner + 1) % 3]].u;
  w.u_in = m.verts[f.v[(corner + 2) % 3]].u;
  w.normal = f.rest_normal;
  return w;
}

// How far inside the wedge the direction points: the smaller sine of its angle to either side (negative
// outside), less its tilt out of the face's plane.
double inside_score(const Wedge& w, const Vec3& d) {
  const Vec3 out = (w.u_out - w.u).normalized(), in = (w.u_in - w.u).normalized();
  return std::min(out.cross(d).dot(w.normal), d.cross(in).dot(w.normal)) - std::abs(d.dot(w.normal));
}

// The wedge of `node` the ray leaves through: its own face when that face is live, holds the node and contains
// the direction (up to round-off); otherwise the node's face that contains the direction best. The fallback
// follows the ray into the children of a face that an earlier split of this opening replaced.
bool locate_wedge(const Mesh& m, int node, const CutRay& ray, Wedge& found) {
  constexpr double kInsideTolerance = 1e-9;
  const int given = ray.face;
  if (given >= 0 && given < static_cast<int>(m.faces.size()) && !m.faces[given].dead) {
    const int corner = m.corner_of_node(given, node);
    if (corner != kNone) {
      found = wedge_at(m, given, corner);
      if (inside_score(found, ray.direction) >= -kInsideTolerance) return true;
    }
  }
  double best = -kInfinity;
  for (int f : m.node_faces(node)) {
    const Wedge w = wedge_at(m, f, m.corner_of_node(f, node));
    const double score = inside_score(w, ray.direction);
    if (score > best) best = score, found = w;
  }
  return best >= -kInsideTolerance;
}

double angle_between(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// Where one ray takes the crack: along an existing edge at the node (follow), or across the opposite edge,
// split at `t` (the edge's own parameter, from edges[edge].n[0]).
struct RayPlan {
  bool split = false;
  int edge = kNone;  // follow: the crack edge; split: the opposite edge
  double t = 0;
  int face = kNone;  // the wedge the ray leaves through
};

// Parameter along node_out -> node_in where the ray crosses the opposite edge (in the face's rest plane).
double crossing_parameter(const Wedge& w, const Vec3& d) {
  const Vec3 across = w.normal.cross(d);  // in-plane normal of the ray's line
  const Vec3 side = w.u_in - w.u_out;
  return std::clamp(-(w.u_out - w.u).dot(across) / side.dot(across), 0.0, 1.0);
}

// The rest edges and child faces a split at t (along a -> b, a = `from`) would create in one face of the edge,
// against the sliver limits. Empty if fine, else what is too small.
std::string sliver_problem(const Mesh& m, int face, int from, int to, double t, const CrackOpeningOptions& o) {
  const double min_length = o.sliver * o.size_min, min_area = min_length * min_length;
  const Face& f = m.faces[face];
  const int ca = m.corner_of_node(face, from), cb = m.corner_of_node(face, to), cx = 3 - ca - cb;
  const Vec3 &a = m.verts[f.v[ca]].u, &b = m.verts[f.v[cb]].u, &x = m.verts[f.v[cx]].u;
  const Vec3 p = (1 - t) * a + t * b;
  const std::array<double, 3> lengths{(p - a).norm(), (b - p).norm(), (x - p).norm()};
  for (double length : lengths)
    if (length < min_length) return "an edge of the split would be a sliver (shorter than sliver * size_min)";
  const double area_a = 0.5 * (p - a).cross(x - a).norm(), area_b = 0.5 * (b - p).cross(x - p).norm();
  if (std::min(area_a, area_b) < min_area) return "a face of the split would be a sliver (area below (sliver * size_min)^2)";
  return "";
}

bool plan_ray(const Mesh& m, int node, const CutRay& ray, const CrackOpeningOptions& o, RayPlan& plan,
              std::string& why) {
  Wedge w;
  if (ray.direction.norm() < 0.5 || !locate_wedge(m, node, ray, w)) {
    why = "the ray does not point into a face of the node";
    return false;
  }
  plan = RayPlan{};
  plan.face = w.face;
  const Vec3 d = ray.direction.normalized();
  const double angle_out = angle_between(d, w.u_out - w.u), angle_in = angle_between(d, w.u_in - w.u);
  if (std::min(angle_out, angle_in) <= o.snap_angle) {
    plan.edge = angle_out <= angle_in ? w.edge_out : w.edge_in;
    return true;
  }
  const double t = crossing_parameter(w, d);
  if (!std::isfinite(t)) {
    why = "the ray runs parallel to the opposite edge";
    return false;
  }
  const double length = (w.u_in - w.u_out).norm(), reach = o.snap_distance * o.size_min;
  const bool near_out = t < o.snap_fraction && t * length < reach;
  const bool near_in = 1 - t < o.snap_fraction && (1 - t) * length < reach;
  if (near_out || near_in) {
    plan.edge = near_out && (!near_in || t <= 1 - t) ? w.edge_out : w.edge_in;
    return true;
  }
  const Edge& opposite = m.edges[w.opposite];
  for (int f : opposite.f) {
    if (f == kNone) continue;
    why = sliver_problem(m, f, w.node_out, w.node_in, t, o);
    if (!why.empty()) return false;
  }
  plan.split = true;
  plan.edge = w.opposite;
  plan.t = opposite.n[0] == w.node_out ? t : 1 - t;
  if (!(plan.t > 0 && plan.t < 1)) {
    why = "the ray crosses the opposite edge at an end";
    return false;
  }
  return true;
}

// Checks between the plans that need no edit: a followed edge must be interior, two rays need two edges.
bool plans_compatible(const Mesh& m, const std::vector<RayPlan>& plans, std::string& why) {
  for (const RayPlan& p : plans)
    if (!p.split && m.edges[p.edge].is_boundary()) {
      why = "the crack would follow an edge that already is a border";
      return false;
    }
  if (plans.size() == 2 && plans[0].edge == plans[1].edge) {
    why = "both rays end up on the same edge";
    return false;
  }
  return true;
}

int far_end(const Mesh& m, int edge, int node) { return m.edges[edge].n[0] == node ? m.edges[edge].n[1] : m.edges[edge].n[0]; }

CrackOpening refuse(CrackOpening out, const std::string& why) {
  out.ok = false;
  out.refused = why;
  if (out.mesh_changed) out.refused += " (after an edge split of this opening, which stays: the mesh changed)";
  return out;
}

// Carries out one ray's plan; the crack edge goes into out.crack_edges.
bool apply_plan(EditSession& session, int node, const RayPlan& plan, CrackOpening& out, std::string& why) {
  if (!plan.split) {
    out.crack_edges.push_back(plan.edge);
    ++out.snaps;
    return true;
  }
  const EditResult r = session.split_edge(plan.edge, plan.t);
  if (!r.ok) {
    why = "the edit session refused the edge split";
    return false;
  }
  out.mesh_changed = true;
  ++out.edge_splits;
  const int crack = session.mesh().find_edge(node, r.added_nodes[0]);
  if (crack == kNone) {
    why = "the edge split made no edge from the node to the crossing";
    return false;
  }
  out.crack_edges.push_back(crack);
  return true;
}

// The faces reachable from face `start` without crossing a border or one of `cut` edges, counted up to
// `limit` (the count stops there): the size of the piece the cut would leave `start` in, if it is small.
int piece_faces(const Mesh& m, int start, const std::vector<int>& cut, int limit) {
  std::vector<int> seen{start}, stack{start};
  while (!stack.empty() && static_cast<int>(seen.size()) < limit) {
    const int f = stack.back();
    stack.pop_back();
    for (int e : m.faces[f].e) {
      if (m.edges[e].is_boundary() || std::find(cut.begin(), cut.end(), e) != cut.end()) continue;
      const int g = m.other_face(e, f);
      if (g == kNone || std::find(seen.begin(), seen.end(), g) != seen.end()) continue;
      seen.push_back(g);
      stack.push_back(g);
    }
  }
  return static_cast<int>(seen.size());
}

// The world direction (unit) in which the lip made of faces `own` moves away from the crack: their centroid minus
// the centroid of `all` (the faces of every side of the split node), within their mean world plane. Zero if it
// has none.
Vec3 lip_direction(const Mesh& m, const std::vector<int>& own, const std::vector<int>& all) {
  if (own.empty() || all.empty()) return Vec3::Zero();
  auto centroid_of = [&](const std::vector<int>& faces) {
    Vec3 c = Vec3::Zero();
    for (int f : faces)
      for (int i = 0; i < 3; ++i) c += m.nodes[m.face_node(f, i)].x / 3;
    return Vec3(c / static_cast<double>(faces.size()));
  };
  Vec3 normal = Vec3::Zero();
  for (int f : own) normal += m.world_normal(f);
  Vec3 d = centroid_of(own) - centroid_of(all);
  if (normal.norm() > 0) d -= d.dot(normal.normalized()) * normal.normalized();
  return d.norm() > 0 ? Vec3(d.normalized()) : Vec3::Zero();
}

// The faces of `from` not in `own`.
std::vector<int> faces_besides(const std::vector<int>& from, const std::vector<int>& own) {
  std::vector<int> out;
  for (int f : from)
    if (std::find(own.begin(), own.end(), f) == own.end()) out.push_back(f);
  return out;
}

// Moves a node of a new crack by `distance` (m) away from the other side(s) of the split, `twins` (the split
// node and its copies): along lip_direction of its own faces. The guard does not check the move against the
// faces of `split` (every node the opening split, and their copies), which it touches by construction: they
// start coincident with its own. True if the move was kept.
bool set_lip_apart(EditSession& session, int node, double distance, const std::vector<int>& twins,
                   const std::vector<int>& split) {
  const Mesh& m = session.mesh();
  const std::vector<int> own = m.node_faces(node);
  std::vector<int> all, around;
  for (int t : twins) {
    const std::vector<int> faces = m.node_faces(t);
    all.insert(all.end(), faces.begin(), faces.end());
  }
  for (int t : split) {
    const std::vector<int> faces = m.node_faces(t);
    around.insert(around.end(), faces.begin(), faces.end());
  }
  const Vec3 d = lip_direction(m, own, all);
  if (!(d.norm() > 0)) return false;
  // The guard's clearance first. A lip next to the lip of an earlier crack (the same node split twice in a
  // step, paper-tearing.json step 1128) cannot keep it: those lips are only a lip gap apart. Coincident twins
  // are worse than lips closer than the clearance, so then only sweeping through a surface is ruled out.
  // The gap is taken up plastically by the lip's faces (NodeMoveOptions::stress_free): it is room for the
  // collision stage, not a strain of the material.
  const Vec3 move = distance * d;
  NodeMoveOptions options;
  options.exempt_faces = faces_besides(around, own);
  options.stress_free = true;
  if (session.move_node(node, move, options)) return true;
  options.require_clearance = false;
  return session.move_node(node, move, options);
}

// The faces around `node` in the groups a split along the `cut` edges makes (its sides: the lips of the crack),
// joined across the node's interior edges that are not cut.
std::vector<std::vector<int>> sides_of(const Mesh& m, int node, const std::vector<int>& cut) {
  const std::vector<int> faces = m.node_faces(node);
  std::vector<int> group(faces.size(), -1);
  std::vector<std::vector<int>> sides;
  for (size_t start = 0; start < faces.size(); ++start) {
    if (group[start] >= 0) continue;
    const int g = static_cast<int>(sides.size());
    sides.emplace_back();
    std::vector<size_t> stack{start};
    group[start] = g;
    while (!stack.empty()) {
      const size_t i = stack.back();
      stack.pop_back();
      sides[g].push_back(faces[i]);
      for (int e : m.faces[faces[i]].e) {
        const Edge& edge = m.edges[e];
        if ((edge.n[0] != node && edge.n[1] != node) || edge.is_boundary() ||
            std::find(cut.begin(), cut.end(), e) != cut.end())
          continue;
        const int other = m.other_face(e, faces[i]);
        for (size_t j = 0; j < faces.size(); ++j)
          if (faces[j] == other && group[j] < 0) group[j] = g, stack.push_back(j);
      }
    }
  }
  return sides;
}

// Whether every lip of the split open_crack is about to make (`node` along `crack_edges`, with the far ends in
// `split_far_ends`) can be set `distance` apart from its twin, checked before the split as set_lip_apart's
// weaker try checks it after. WHY: a lip whose move the guard refuses (its sweep meets the lips of an earlier
// crack of the same pass, often coincident twins themselves) stays coincident with its twin; once a later edit
// removes the node they share, their faces cross, and collision handling has no normal to separate them
// (docs/repro/glass-plate-shards-coincident-lips.json: 66 such lips in one step, 191 crossing pairs).
// Empty if they can, else why not.
std::string lips_can_part(const EditSession& session, int node, const std::vector<int>& crack_edges,
                          const std::vector<int>& split_far_ends, double distance) {
  const std::string guard_refuses = "the lips could not be set apart (the world guard refuses their move)";
  const Mesh& m = session.mesh();
  std::vector<int> around = m.node_faces(node);
  for (int far : split_far_ends) {
    const std::vector<int> faces = m.node_faces(far);
    around.insert(around.end(), faces.begin(), faces.end());
  }
  std::sort(around.begin(), around.end());
  around.erase(std::unique(around.begin(), around.end()), around.end());
  std::vector<int> splitting{node};
  splitting.insert(splitting.end(), split_far_ends.begin(), split_far_ends.end());
  // Each face of `around` now and as it will be once the lips are set apart: its corners' positions and the nodes
  // they will be (a split node's corner becomes the copy of its side, numbered below every real node and kNone).
  std::vector<GuardTriangle> before(around.size());
  for (size_t i = 0; i < around.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      before[i].x[c] = m.nodes[m.face_node(around[i], c)].x;
      before[i].nodes[c] = m.face_node(around[i], c);
    }
  std::vector<GuardTriangle> after = before;
  int next_copy = kNone - 1;  // ids of the split nodes' copies, one per side, counted down from below kNone
  for (const int n : splitting) {
    const std::vector<int> all = m.node_faces(n);
    for (const std::vector<int>& own : sides_of(m, n, crack_edges)) {
      const Vec3 d = lip_direction(m, own, all);
      if (!(d.norm() > 0)) return guard_refuses;
      NodeMoveOptions options;
      options.exempt_faces = faces_besides(around, own);
      options.require_clearance = false;
      if (!session.move_allowed(n, own, distance * d, options)) return guard_refuses;
      for (int f : own) {
        const size_t i = std::lower_bound(around.begin(), around.end(), f) - around.begin();
        const int c = m.corner_of_node(f, n);
        after[i].x[c] += distance * d;
        after[i].nodes[c] = next_copy;
      }
      --next_copy;
    }
  }
  // The guard does not check the lips against each other (they touch at the split nodes until the split), and
  // moves that part each twin pair well can still leave the new lips crossing: where the crack reaches a
  // border, the lip directions of the two ends can run mostly along the crack edge, in opposite senses, and the
  // two lips' edges then cross in an X (f15 static ornament, step 4: 20 um apart along the edge, one lip over
  // the other's face 0.1 um out of the surface), which no contact normal can part.
  if (edit_makes_crossing(before, after))
    return "the lips would cross once set apart (faces of the split meet where they share no node)";
  return "";
}

}  // namespace

CrackOpening open_crack(EditSession& session, int node, const std::vector<CutRay>& rays,
                        const CrackOpeningOptions& options) {
  const Mesh& m = session.mesh();
  CrackOpening out;
  if (node < 0 || node >= static_cast<int>(m.nodes.size()) || m.nodes[node].dead || m.node_faces(node).empty())
    return refuse(out, "no such live node with faces");
  const bool boundary = m.is_boundary_node(node);
  if (rays.empty() || rays.size() > 2 || (!boundary && rays.size() != 2))
    return refuse(out, "an interior node needs two rays, a border node one or two");

  // Everything that can be checked before an edit is checked on all rays first.
  std::vector<RayPlan> plans(rays.size());
  std::string why;
  for (size_t k = 0; k < rays.size(); ++k)
    if (!plan_ray(m, node, rays[k], options, plans[k], why)) return refuse(out, why);
  if (!plans_compatible(m, plans, why)) return refuse(out, why);

  for (size_t k = 0; k < plans.size(); ++k) {
    // A split for an earlier ray may have replaced this ray's face or the far side of its opposite edge.
    if (k > 0 && out.mesh_changed && !plan_ray(m, node, rays[k], options, plans[k], why)) return refuse(out, why);
    if (!apply_plan(session, node, plans[k], out, why)) return refuse(out, why);
  }
  if (out.crack_edges.size() == 2 && out.crack_edges[0] == out.crack_edges[1])
    return refuse(out, "both rays end up on the same edge");
  for (int e : out.crack_edges)
    if (m.edges[e].is_boundary()) return refuse(out, "the crack would follow an edge that already is a border");

  // A far end already on a border is split with the node (the crack reached it); the others are the new tips.
  std::vector<int> tips, split_far_ends;
  for (int e : out.crack_edges) {
    const int far = far_end(m, e, node);
    (m.is_boundary_node(far) ? split_far_ends : tips).push_back(far);
  }
  if (options.min_piece_faces > 1)
    for (int f : m.node_faces(node))
      if (piece_faces(m, f, out.crack_edges, options.min_piece_faces) < options.min_piece_faces)
        return refuse(out, "the crack would cut off a piece of fewer than min_piece_faces faces");
  if (options.lip_gap > 0) {
    why = lips_can_part(session, node, out.crack_edges, split_far_ends, 0.5 * options.lip_gap);
    if (!why.empty()) return refuse(out, why);
  }
  const EditResult r = session.split_node(node, out.crack_edges);
  if (!r.ok) return refuse(out, "the edit session refused the node split");
  out.mesh_changed = true;
  // split_node lists the node's copies first: two for two cuts at a border node, else one.
  const size_t copies = boundary && out.crack_edges.size() == 2 ? 2 : 1;
  out.nodes.push_back(node);
  for (size_t k = 0; k < copies && k < r.added_nodes.size(); ++k) out.nodes.push_back(r.added_nodes[k]);
  // The far ends' copies follow (split_node copies x exactly: each copy is matched to its far end by position).
  for (size_t k = copies; k < r.added_nodes.size(); ++k) {
    const int copy = r.added_nodes[k];
    for (int far : split_far_ends)
      if (m.nodes[far].x == m.nodes[copy].x) {
        out.far_ends.push_back({far, copy});
        break;
      }
  }
  out.tips = tips;
  out.ok = true;
  if (options.lip_gap > 0) {
    // A far end the crack reached on a border is split too, and its halves start just as coincident.
    const std::vector<int> split = out.split_nodes();
    for (int n : out.nodes) set_lip_apart(session, n, 0.5 * options.lip_gap, out.nodes, split);
    for (const std::array<int, 2>& twins : out.far_ends) {
      const std::vector<int> pair(twins.begin(), twins.end());
      for (int n : pair) set_lip_apart(session, n, 0.5 * options.lip_gap, pair, split);
    }
  }
  return out;
}

}  // namespace arcsim
