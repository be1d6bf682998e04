#include "mesh/edits.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "mesh/validate.hpp"

namespace arcsim {

namespace {

bool live_node(const Mesh& m, int n) { return n >= 0 && n < static_cast<int>(m.nodes.size()) && !m.nodes[n].dead; }
bool live_edge(const Mesh& m, int e) { return e >= 0 && e < static_cast<int>(m.edges.size()) && !m.edges[e].dead; }

bool contains(const std::vector<int>& list, int x) { return std::find(list.begin(), list.end(), x) != list.end(); }

// The vert of face f at node n (kNone if n is not a corner).
int vert_at(const Mesh& m, int f, int n) {
  const int c = m.corner_of_node(f, n);
  return c == kNone ? kNone : m.faces[f].v[c];
}

// Every face touching node n, through all of its verts.
std::vector<int> node_faces(const Mesh& m, int n) {
  std::vector<int> faces;
  for (int v : m.nodes[n].verts) faces.insert(faces.end(), m.verts[v].faces.begin(), m.verts[v].faces.end());
  return faces;
}

std::vector<int> neighbours(const Mesh& m, int n) {
  std::vector<int> result;
  for (int e : m.nodes[n].edges) result.push_back(m.edges[e].n[0] == n ? m.edges[e].n[1] : m.edges[e].n[0]);
  return result;
}

// A new face may turn its rest normal by at most this angle from the face(s) it replaces (cos 60 deg). Beyond
// it the rest surface folds: on flat sheets that is an inversion, on curved ones a face standing across the
// surface (a flip of three nearly collinear points on a curved edge path would create one).
constexpr double kMinNormalCosine = 0.5;

// Rest-space triangle check for a face about to be created: not degenerate and, if a reference normal is given,
// not turned away from it (see kMinNormalCosine).
bool rest_triangle_ok(const Mesh& m, const std::array<int, 3>& v, const Vec3* reference_normal = nullptr) {
  const Vec3 &u0 = m.verts[v[0]].u, &u1 = m.verts[v[1]].u, &u2 = m.verts[v[2]].u;
  if (rest_triangle_degenerate(u0, u1, u2)) return false;
  if (reference_normal == nullptr) return true;
  const Vec3 normal = (u1 - u0).cross(u2 - u0);
  return normal.dot(*reference_normal) > kMinNormalCosine * normal.norm() * reference_normal->norm();
}

// Unnormalised rest normal (twice the area) of an existing face, computed from the verts.
Vec3 rest_cross(const Mesh& m, int f) {
  const Vec3& u0 = m.verts[m.faces[f].v[0]].u;
  return (m.verts[m.faces[f].v[1]].u - u0).cross(m.verts[m.faces[f].v[2]].u - u0);
}

// rest_theta minus the geometric rest dihedral: the plastic part of the rest angle, which an edit carries over
// while the geometric part follows the new faces.
double plastic_offset(const Mesh& m, int e) { return m.edges[e].rest_theta - m.rest_dihedral(e); }

void append_range(std::vector<int>& list, size_t begin, size_t end) {
  for (size_t i = begin; i < end; ++i) list.push_back(static_cast<int>(i));
}

// A prototype for add_face: the state of an existing (possibly just removed) face, alive again.
Face prototype_of(const Face& f) {
  Face p = f;
  p.dead = false;
  return p;
}

// Removes the edges among `candidates` that are live and have lost all their faces.
void remove_faceless_edges(Mesh& m, const std::vector<int>& candidates, EditResult& r) {
  for (int e : candidates) {
    if (m.edges[e].dead || m.edges[e].f[0] != kNone || m.edges[e].f[1] != kNone) continue;
    m.remove_edge(e);
    r.removed_edges.push_back(e);
  }
}

void remove_faceless_verts(Mesh& m, int n, EditResult& r) {
  const std::vector<int> verts = m.nodes[n].verts;
  for (int v : verts)
    if (m.verts[v].faces.empty()) {
      m.remove_vert(v);
      r.removed_verts.push_back(v);
    }
}

}  // namespace

bool node_fan(const Mesh& m, int node, NodeFan& fan) {
  fan.corners.clear();
  fan.closed = false;
  if (!live_node(m, node)) return false;
  const std::vector<int> faces = node_faces(m, node);
  if (faces.empty()) return false;
  auto corner_of = [&](int f) {
    FanCorner c;
    c.face = f;
    c.corner = m.corner_of_node(f, node);
    if (c.corner == kNone) return c;
    c.edge_out = m.faces[f].e[c.corner];
    c.edge_in = m.faces[f].e[(c.corner + 2) % 3];
    return c;
  };
  // An open fan starts where edge_out is on the boundary; there must be at most one such place.
  int start = kNone;
  for (int f : faces) {
    const FanCorner c = corner_of(f);
    if (c.corner == kNone) return false;
    if (m.edges[c.edge_out].is_boundary()) {
      if (start != kNone) return false;
      start = f;
    }
  }
  fan.closed = start == kNone;
  if (fan.closed) start = faces.front();
  int f = start;
  while (true) {
    const FanCorner c = corner_of(f);
    if (c.corner == kNone || fan.corners.size() >= faces.size()) return false;
    fan.corners.push_back(c);
    const int next = m.other_face(c.edge_in, f);
    if (next == kNone) {
      if (fan.closed) return false;
      break;
    }
    if (next == start) {
      if (!fan.closed) return false;
      break;
    }
    f = next;
  }
  return fan.corners.size() == faces.size();
}

// ------------------------------------------------------------------------------------------------------------
// split_edge

EditResult split_edge(Mesh& m, int edge, double t) {
  EditResult r;
  if (!live_edge(m, edge) || !(t > 0 && t < 1)) return r;
  const Edge old = m.edges[edge];
  const int n0 = old.n[0], n1 = old.n[1];

  struct Side {
    int face = kNone;
    int corner = kNone;  // corner of the face where the edge starts (it runs corner -> corner + 1)
    int v0 = kNone, v1 = kNone;
    Vec3 u = Vec3::Zero();  // rest position of the new vert on this side
    Mat3 sizing = Mat3::Zero();
  };
  std::vector<Side> sides;
  for (int s = 0; s < 2; ++s) {
    if (old.f[s] == kNone) continue;
    Side side;
    side.face = old.f[s];
    const Face& f = m.faces[side.face];
    for (int c = 0; c < 3; ++c)
      if (f.e[c] == edge) side.corner = c;
    if (side.corner == kNone) return r;
    side.v0 = vert_at(m, side.face, n0);
    side.v1 = vert_at(m, side.face, n1);
    side.u = (1 - t) * m.verts[side.v0].u + t * m.verts[side.v1].u;
    side.sizing = (1 - t) * m.verts[side.v0].sizing + t * m.verts[side.v1].sizing;
    sides.push_back(side);
  }
  if (sides.empty()) return r;
  // Two faces with the same third node would produce the same new edge twice.
  if (sides.size() == 2 && m.opposite_node(edge, sides[0].face) == m.opposite_node(edge, sides[1].face)) return r;

  // Child faces of a side: the parent's corners with the new vert in place of one end of the edge. Checked on a
  // scratch vert before anything changes.
  auto children = [](const Face& parent, int corner, int new_vert) {
    std::array<int, 3> a = parent.v, b = parent.v;
    a[(corner + 1) % 3] = new_vert;
    b[corner] = new_vert;
    return std::make_pair(a, b);
  };
  for (const Side& side : sides) {
    const Face& f = m.faces[side.face];
    const std::array<Vec3, 3> u{m.verts[f.v[0]].u, m.verts[f.v[1]].u, m.verts[f.v[2]].u};
    const int c = side.corner;
    std::array<Vec3, 3> a = u, b = u;
    a[(c + 1) % 3] = side.u;
    b[c] = side.u;
    if (rest_triangle_degenerate(a[0], a[1], a[2]) || rest_triangle_degenerate(b[0], b[1], b[2])) return r;
  }

  // New node, interpolated.
  const Node& a = m.nodes[n0];
  const Node& b = m.nodes[n1];
  Node node;
  node.x = (1 - t) * a.x + t * b.x;
  node.x0 = (1 - t) * a.x0 + t * b.x0;
  node.v = (1 - t) * a.v + t * b.v;
  node.a = (1 - t) * a.a + t * b.a;
  node.mass = (1 - t) * a.mass + t * b.mass;
  node.label = a.label == b.label ? a.label : 0;
  const int new_node = m.add_node(node);
  r.added_nodes.push_back(new_node);

  // One vert per distinct pair of side verts.
  std::vector<int> new_verts;
  for (size_t s = 0; s < sides.size(); ++s) {
    if (s == 1 && sides[1].v0 == sides[0].v0 && sides[1].v1 == sides[0].v1) {
      new_verts.push_back(new_verts[0]);
      continue;
    }
    Vert v;
    v.u = sides[s].u;
    v.sizing = sides[s].sizing;
    new_verts.push_back(m.add_vert(v, new_node));
    r.added_verts.push_back(new_verts.back());
  }

  std::vector<Face> parents;
  for (const Side& side : sides) {
    parents.push_back(prototype_of(m.faces[side.face]));
    m.remove_face(side.face);
    r.removed_faces.push_back(side.face);
  }
  m.remove_edge(edge);
  r.removed_edges.push_back(edge);

  const size_t first_edge = m.edges.size(), first_face = m.faces.size();
  for (size_t s = 0; s < sides.size(); ++s) {
    const auto [first, second] = children(parents[s], sides[s].corner, new_verts[s]);
    m.add_face(first, parents[s]);
    m.add_face(second, parents[s]);
  }
  append_range(r.added_edges, first_edge, m.edges.size());
  append_range(r.added_faces, first_face, m.faces.size());
  for (int f : r.added_faces) m.update_rest_data(f);

  for (int e : r.added_edges) {
    Edge& ed = m.edges[e];
    const int other = ed.n[0] == new_node ? ed.n[1] : ed.n[0];
    if (other == n0 || other == n1) {
      ed.rest_theta = old.rest_theta;
      ed.damage = old.damage;
      ed.preserve = old.preserve;
    } else {
      // Inside a former face: flat within that face, so the rest angle is purely geometric.
      ed.rest_theta = m.rest_dihedral(e);
      ed.damage = m.faces[ed.f[0] != kNone ? ed.f[0] : ed.f[1]].damage;
    }
  }
  r.ok = true;
  return r;
}

// ------------------------------------------------------------------------------------------------------------
// flip_edge

EditResult flip_edge(Mesh& m, int edge) {
  EditResult r;
  if (!live_edge(m, edge)) return r;
  const Edge& e = m.edges[edge];
  if (e.is_boundary() || e.preserve) return r;
  const int f0 = e.f[0], f1 = e.f[1];
  const int n0 = e.n[0], n1 = e.n[1];
  const int v0 = vert_at(m, f0, n0), v1 = vert_at(m, f0, n1);
  if (v0 != vert_at(m, f1, n0) || v1 != vert_at(m, f1, n1)) return r;  // seam
  if (m.faces[f0].material != m.faces[f1].material) return r;
  const int na = m.opposite_node(edge, f0), nb = m.opposite_node(edge, f1);
  if (na == nb || m.find_edge(na, nb) != kNone) return r;
  const int va = vert_at(m, f0, na), vb = vert_at(m, f1, nb);

  // f0 runs n0 -> n1 -> a, f1 runs n1 -> n0 -> b, so the quad is n0, b, n1, a counter-clockwise.
  const std::array<int, 3> A{va, v0, vb}, B{vb, v1, va};
  const Vec3 normal0 = rest_cross(m, f0), normal1 = rest_cross(m, f1);
  for (const auto& tri : {A, B})
    if (!rest_triangle_ok(m, tri, &normal0) || !rest_triangle_ok(m, tri, &normal1)) return r;

  // Plastic offsets of the outer edges, measured with the old wings.
  std::vector<std::pair<int, double>> outer;
  for (int f : {f0, f1})
    for (int k = 0; k < 3; ++k)
      if (m.faces[f].e[k] != edge) outer.emplace_back(m.faces[f].e[k], plastic_offset(m, m.faces[f].e[k]));

  // Area-weighted state of the two old faces.
  const Face& F0 = m.faces[f0];
  const Face& F1 = m.faces[f1];
  const double w0 = 0.5 * normal0.norm(), w1 = 0.5 * normal1.norm();
  const double s0 = w0 / (w0 + w1), s1 = w1 / (w0 + w1);
  Face proto = prototype_of(F0);
  // Equal states stay exact (s0 + s1 rounds off 1): an elastic face's Fp = I and Sp = 0 must not drift.
  proto.thickness = F0.thickness == F1.thickness ? F0.thickness : s0 * F0.thickness + s1 * F1.thickness;
  proto.Fp = F0.Fp == F1.Fp ? F0.Fp : Mat3(s0 * F0.Fp + s1 * F1.Fp);
  proto.Sp = F0.Sp == F1.Sp ? F0.Sp : Mat3(s0 * F0.Sp + s1 * F1.Sp);
  proto.damage = F0.damage == F1.damage ? F0.damage : s0 * F0.damage + s1 * F1.damage;

  m.remove_face(f0);
  m.remove_face(f1);
  m.remove_edge(edge);
  r.removed_faces = {f0, f1};
  r.removed_edges = {edge};
  const size_t first_edge = m.edges.size();
  r.added_faces = {m.add_face(A, proto), m.add_face(B, proto)};
  append_range(r.added_edges, first_edge, m.edges.size());
  for (int f : r.added_faces) m.update_rest_data(f);
  for (int ne : r.added_edges) {
    m.edges[ne].rest_theta = m.rest_dihedral(ne);
    m.edges[ne].damage = proto.damage;
  }
  for (const auto& [oe, offset] : outer) m.edges[oe].rest_theta = offset + m.rest_dihedral(oe);
  r.ok = true;
  return r;
}

// ------------------------------------------------------------------------------------------------------------
// collapse_edge

bool collapse_edge_precheck(const Mesh& m, int edge, int remove_side) {
  if (!live_edge(m, edge) || (remove_side != 0 && remove_side != 1)) return false;
  const Edge& e = m.edges[edge];
  const int gone = e.n[remove_side];
  if (e.preserve || m.nodes[gone].preserve) return false;
  for (int ge : m.nodes[gone].edges)
    if (m.edges[ge].preserve) return false;
  return !(m.is_boundary_node(gone) && !e.is_boundary());
}

EditResult collapse_edge(Mesh& m, int edge, int remove_side) {
  EditResult r;
  if (!collapse_edge_precheck(m, edge, remove_side)) return r;
  const Edge& e = m.edges[edge];
  const int gone = e.n[remove_side], keep = e.n[1 - remove_side];
  NodeFan fan_gone, fan_keep;
  if (!node_fan(m, gone, fan_gone) || !node_fan(m, keep, fan_keep)) return r;

  // Link condition: the only common neighbours are the opposite corners of the collapsing faces.
  std::vector<int> collapsing, opposite;
  for (int s = 0; s < 2; ++s)
    if (e.f[s] != kNone) {
      collapsing.push_back(e.f[s]);
      opposite.push_back(m.opposite_node(edge, e.f[s]));
    }
  const std::vector<int> keep_ring = neighbours(m, keep);
  for (int x : neighbours(m, gone))
    if (x != keep && contains(keep_ring, x) && !contains(opposite, x)) return r;

  // Rest verts of the removed node map onto the kept node's verts through the collapsing faces.
  std::map<int, int> vert_map;
  for (int f : collapsing) {
    const int vg = vert_at(m, f, gone), vk = vert_at(m, f, keep);
    const auto it = vert_map.find(vg);
    if (it != vert_map.end() && it->second != vk) return r;
    for (const auto& [from, to] : vert_map)
      if (to == vk && from != vg) return r;
    vert_map[vg] = vk;
  }

  const std::vector<int> gone_faces = node_faces(m, gone);
  const std::vector<int> keep_faces = node_faces(m, keep);
  struct Moved {
    int face;
    std::array<int, 3> v;
  };
  std::vector<Moved> moved;
  for (int f : gone_faces) {
    if (contains(collapsing, f)) continue;
    const int c = m.corner_of_node(f, gone);
    const auto it = vert_map.find(m.faces[f].v[c]);
    if (it == vert_map.end()) return r;  // a seam crosses the removed node away from the edge
    Moved mv{f, m.faces[f].v};
    mv.v[c] = it->second;
    const Vec3 old_normal = rest_cross(m, f);
    if (!rest_triangle_ok(m, mv.v, &old_normal)) return r;
    // The moved face must not duplicate a face the kept node already has.
    std::array<int, 3> nodes{keep, m.face_node(f, (c + 1) % 3), m.face_node(f, (c + 2) % 3)};
    std::sort(nodes.begin(), nodes.end());
    for (int kf : keep_faces) {
      if (contains(collapsing, kf)) continue;
      std::array<int, 3> other{m.face_node(kf, 0), m.face_node(kf, 1), m.face_node(kf, 2)};
      std::sort(other.begin(), other.end());
      if (other == nodes) return r;
    }
    moved.push_back(mv);
  }
  // Nodes that lose faces must keep at least one.
  if (moved.empty() && keep_faces.size() <= collapsing.size()) return r;
  for (int x : opposite) {
    size_t remaining = 0;
    for (int f : node_faces(m, x))
      if (!contains(collapsing, f)) ++remaining;
    if (remaining == 0) return r;
  }

  // --- checks done: apply ---
  // Edges whose wings change, with their plastic offsets taken before the change.
  std::map<int, double> offsets;
  for (int f : gone_faces)
    for (int k = 0; k < 3; ++k) offsets.emplace(m.faces[f].e[k], plastic_offset(m, m.faces[f].e[k]));
  // Index of each edge gone -> x, whose state goes over to keep -> x (a tombstone keeps its data).
  std::map<int, int> gone_edge_to;
  for (int ge : m.nodes[gone].edges) {
    const Edge& ed = m.edges[ge];
    gone_edge_to[ed.n[0] == gone ? ed.n[1] : ed.n[0]] = ge;
  }
  std::vector<Face> protos;
  for (const Moved& mv : moved) protos.push_back(prototype_of(m.faces[mv.face]));

  for (int f : gone_faces) {
    m.remove_face(f);
    r.removed_faces.push_back(f);
  }
  std::vector<int> touched_edges;
  for (int f : collapsing)
    for (int k = 0; k < 3; ++k) touched_edges.push_back(m.faces[f].e[k]);
  remove_faceless_edges(m, std::vector<int>(m.nodes[gone].edges), r);
  remove_faceless_verts(m, gone, r);
  m.remove_node(gone);
  r.removed_nodes.push_back(gone);

  const size_t first_edge = m.edges.size();
  for (size_t i = 0; i < moved.size(); ++i) r.added_faces.push_back(m.add_face(moved[i].v, protos[i]));
  append_range(r.added_edges, first_edge, m.edges.size());
  remove_faceless_edges(m, touched_edges, r);  // defensive: the checks above leave none
  for (int f : r.added_faces) m.update_rest_data(f);

  // New edges keep -> x take over the state of gone -> x.
  for (int ne : r.added_edges) {
    Edge& ed = m.edges[ne];
    const int from = gone_edge_to.at(ed.n[0] == keep ? ed.n[1] : ed.n[0]);
    ed.damage = m.edges[from].damage;
    ed.preserve = m.edges[from].preserve;
    offsets[ne] = offsets.at(from);
  }
  // Merged edges keep -> c (c opposite) absorb gone -> c: the worse damage survives.
  for (int c : opposite) {
    const int merged = m.find_edge(keep, c);
    if (merged != kNone) m.edges[merged].damage = std::max(m.edges[merged].damage, m.edges[gone_edge_to.at(c)].damage);
  }
  for (const auto& [ei, offset] : offsets)
    if (!m.edges[ei].dead) m.edges[ei].rest_theta = offset + m.rest_dihedral(ei);
  r.ok = true;
  return r;
}

// ------------------------------------------------------------------------------------------------------------
// split_node

namespace {

// A node to be split: which of its faces go to which new copy (index into the copies, -1 = stays).
struct NodeSplitPlan {
  int node = kNone;
  std::map<int, int> face_copy;  // face -> copy index (faces absent from the map stay)
  int copies = 0;
};

// Splits the open fan of boundary node `far` at interior edge `cut`: the part holding `moving_face` moves.
bool plan_far_split(const Mesh& m, int far, int cut, int moving_face, NodeSplitPlan& plan) {
  NodeFan fan;
  if (!node_fan(m, far, fan) || fan.closed) return false;
  size_t cut_after = fan.corners.size();  // the cut is the edge_in of this corner
  for (size_t k = 0; k < fan.corners.size(); ++k)
    if (fan.corners[k].edge_in == cut) cut_after = k;
  if (cut_after + 1 >= fan.corners.size()) return false;
  bool moving_first = false;
  for (size_t k = 0; k <= cut_after; ++k)
    if (fan.corners[k].face == moving_face) moving_first = true;
  plan.node = far;
  plan.copies = 1;
  for (size_t k = 0; k < fan.corners.size(); ++k)
    if ((k <= cut_after) == moving_first) plan.face_copy[fan.corners[k].face] = 0;
  return true;
}

}  // namespace

EditResult split_node(Mesh& m, int node, const std::vector<int>& cut_edges) {
  EditResult r;
  if (!live_node(m, node) || cut_edges.empty() || cut_edges.size() > 2) return r;
  if (cut_edges.size() == 2 && cut_edges[0] == cut_edges[1]) return r;
  for (int c : cut_edges)
    if (!live_edge(m, c) || m.edges[c].is_boundary() || (m.edges[c].n[0] != node && m.edges[c].n[1] != node))
      return r;
  NodeFan fan;
  if (!node_fan(m, node, fan)) return r;
  if (fan.closed && cut_edges.size() == 1) return r;

  // Sectors: walk CCW, starting (closed fan) just after cut_edges[1] so that sector 1 runs from cut_edges[0]
  // to cut_edges[1]; crossing a cut edge starts the next sector. Sector 0 stays.
  auto& corners = fan.corners;
  if (fan.closed) {
    const auto start = std::find_if(corners.begin(), corners.end(),
                                    [&](const FanCorner& c) { return c.edge_out == cut_edges[1]; });
    std::rotate(corners.begin(), start, corners.end());
  }
  NodeSplitPlan main_plan;
  main_plan.node = node;
  std::map<int, int> sector_of;  // face -> sector
  int sector = 0;
  for (const FanCorner& c : corners) {
    sector_of[c.face] = sector;
    if (sector > 0) main_plan.face_copy[c.face] = sector - 1;
    if (contains(cut_edges, c.edge_in)) ++sector;
  }
  main_plan.copies = sector_of[corners.back().face];

  // Far ends already on the boundary would become bow-ties: split their fans at the cut edge as well, moving the
  // part on the side of the higher sector.
  std::vector<NodeSplitPlan> plans{main_plan};
  for (int c : cut_edges) {
    const Edge& ed = m.edges[c];
    const int far = ed.n[0] == node ? ed.n[1] : ed.n[0];
    if (!m.is_boundary_node(far)) continue;
    const int moving_face = sector_of.at(ed.f[0]) > sector_of.at(ed.f[1]) ? ed.f[0] : ed.f[1];
    NodeSplitPlan far_plan;
    if (!plan_far_split(m, far, c, moving_face, far_plan)) return r;
    plans.push_back(far_plan);
  }

  // --- checks done: apply ---
  // Edge state by node pair, for the edges that are rebuilt around a copy.
  std::map<std::pair<int, int>, int> edge_by_nodes;
  for (const NodeSplitPlan& plan : plans)
    for (int e : m.nodes[plan.node].edges)
      edge_by_nodes[std::minmax(m.edges[e].n[0], m.edges[e].n[1])] = e;

  std::map<int, int> original_of;  // copy node -> original node
  std::vector<std::vector<int>> copy_nodes(plans.size());
  for (size_t p = 0; p < plans.size(); ++p) {
    m.nodes[plans[p].node].preserve = true;
    for (int k = 0; k < plans[p].copies; ++k) {
      Node copy = m.nodes[plans[p].node];  // add_node drops the adjacency lists
      copy.dead = false;
      const int index = m.add_node(copy);
      copy_nodes[p].push_back(index);
      original_of[index] = plans[p].node;
      r.added_nodes.push_back(index);
    }
  }

  // New corner verts of every face that moves (to one copy or, at the far ends, two).
  std::map<int, std::array<int, 3>> new_corners;
  std::map<std::pair<int, int>, int> vert_copy;  // (old vert, copy node) -> new vert
  for (size_t p = 0; p < plans.size(); ++p)
    for (const auto& [f, copy] : plans[p].face_copy) {
      auto it = new_corners.emplace(f, m.faces[f].v).first;
      const int c = m.corner_of_node(f, plans[p].node);
      const int old_vert = m.faces[f].v[c];
      const int target = copy_nodes[p][copy];
      auto vit = vert_copy.find({old_vert, target});
      if (vit == vert_copy.end()) {
        Vert v = m.verts[old_vert];
        v.dead = false;
        vit = vert_copy.emplace(std::make_pair(old_vert, target), m.add_vert(v, target)).first;
        r.added_verts.push_back(vit->second);
      }
      it->second[c] = vit->second;
    }

  std::vector<Face> protos;
  for (const auto& [f, v] : new_corners) {
    protos.push_back(prototype_of(m.faces[f]));
    m.remove_face(f);
    r.removed_faces.push_back(f);
  }
  const size_t first_edge = m.edges.size();
  size_t i = 0;
  for (const auto& [f, v] : new_corners) r.added_faces.push_back(m.add_face(v, protos[i++]));
  append_range(r.added_edges, first_edge, m.edges.size());
  // Orphans only now: a face that keeps a split node's old vert (it moved for the other node) is back.
  for (const NodeSplitPlan& plan : plans) {
    remove_faceless_edges(m, std::vector<int>(m.nodes[plan.node].edges), r);
    remove_faceless_verts(m, plan.node, r);
  }
  for (int f : r.added_faces) m.update_rest_data(f);

  auto original = [&](int n) {
    const auto it = original_of.find(n);
    return it == original_of.end() ? n : it->second;
  };
  for (int ne : r.added_edges) {
    Edge& ed = m.edges[ne];
    const int from = edge_by_nodes.at(std::minmax(original(ed.n[0]), original(ed.n[1])));
    ed.rest_theta = m.edges[from].rest_theta;
    ed.damage = m.edges[from].damage;
    ed.preserve = m.edges[from].preserve;
  }
  r.ok = true;
  return r;
}

}  // namespace arcsim
