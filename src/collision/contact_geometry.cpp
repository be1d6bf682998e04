#include "collision/contact_geometry.hpp"

namespace arcsim {

namespace {

uint64_t mix(uint64_t h, uint64_t value) {
  // FNV-1a style accumulation; only equality of whole topologies matters.
  h ^= value + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
  return h * 0x100000001b3ULL;
}

// Appends the per-face lists of owned items: item i (global index first + i) belongs to local face owner[i]
// (kNone: to none). Each face's list holds its items in ascending order; begin gets one offset per face.
void append_owned(const std::vector<int>& owner, int first, int face_count, std::vector<int>& begin,
                  std::vector<int>& items) {
  std::vector<int> next(face_count + 1, 0);
  for (int f : owner)
    if (f != kNone) ++next[f + 1];
  for (int f = 0; f < face_count; ++f) next[f + 1] += next[f];
  const int base = static_cast<int>(items.size());
  for (int f = 0; f < face_count; ++f) begin.push_back(base + next[f]);
  items.resize(base + next[face_count]);
  for (size_t i = 0; i < owner.size(); ++i)
    if (owner[i] != kNone) items[base + next[owner[i]]++] = first + static_cast<int>(i);
}

void append_mesh(const ContactBody& body, ContactStage stage, double dt, ContactGeometry& g) {
  const Mesh& mesh = *body.mesh;
  ContactGeometry::Range r;
  r.deformable = body.deformable;
  r.node_begin = g.node_count();
  r.edge_begin = static_cast<int>(g.edges.size());
  r.face_begin = static_cast<int>(g.faces.size());
  const int mesh_index = static_cast<int>(g.meshes.size());

  // Sized once, then written in place (these run twice a step).
  const int node_end = r.node_begin + static_cast<int>(mesh.nodes.size());
  for (auto* v : {&g.x0, &g.x1, &g.v, &g.rest}) v->resize(node_end);
  g.mass.resize(node_end);
  g.area.resize(node_end);
  g.node_mesh.resize(node_end);
  for (size_t i = 0; i < mesh.nodes.size(); ++i) {
    const Node& n = mesh.nodes[i];
    const int k = r.node_begin + static_cast<int>(i);
    g.x0[k] = n.x0;
    g.x1[k] = n.x;
    g.v[k] = n.v;
    if (!body.deformable) {
      g.v[k] = dt > 0 ? Vec3((n.x - n.x0) / dt) : Vec3::Zero();
    } else if (stage == ContactStage::kBeforeStep) {
      g.x0[k] = n.x;
      g.x1[k] = n.x + dt * n.v;
    }
    g.mass[k] = body.deformable && n.mass > 0 ? n.mass : kInfinity;
    g.area[k] = 0;
    g.node_mesh[k] = mesh_index;
    g.rest[k] = body.deformable && !n.verts.empty() ? mesh.verts[n.verts[0]].u : Vec3::Zero();
  }
  uint64_t topology = mix(mesh.nodes.size(), mesh.faces.size());
  g.faces.resize(r.face_begin + mesh.faces.size());
  g.face_area.resize(g.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Face& face = mesh.faces[f];
    std::array<int, 3>& nodes = g.faces[r.face_begin + f];
    nodes = {kNone, kNone, kNone};
    if (!face.dead)
      for (int i = 0; i < 3; ++i) nodes[i] = r.node_begin + mesh.verts[face.v[i]].node;
    for (int i = 0; i < 3; ++i) topology = mix(topology, static_cast<uint64_t>(nodes[i] - r.node_begin));
    double area = 0;
    if (!face.dead) {
      area = body.deformable ? face.rest_area
                             : 0.5 * (g.x0[nodes[1]] - g.x0[nodes[0]]).cross(g.x0[nodes[2]] - g.x0[nodes[0]]).norm();
      for (int i = 0; i < 3; ++i) g.area[nodes[i]] += area / 3;
    }
    g.face_area[r.face_begin + f] = area;
  }
  g.edges.resize(r.edge_begin + mesh.edges.size());
  g.edge_faces.resize(g.edges.size());
  for (size_t i = 0; i < mesh.edges.size(); ++i) {
    const Edge& e = mesh.edges[i];
    const size_t k = r.edge_begin + i;
    if (e.dead) {
      g.edges[k] = {kNone, kNone};
      g.edge_faces[k] = {kNone, kNone};
      continue;
    }
    g.edges[k] = {r.node_begin + e.n[0], r.node_begin + e.n[1]};
    g.edge_faces[k] = {e.f[0] == kNone ? kNone : r.face_begin + e.f[0], e.f[1] == kNone ? kNone : r.face_begin + e.f[1]};
  }
  r.node_end = g.node_count();
  r.edge_end = static_cast<int>(g.edges.size());
  r.face_end = static_cast<int>(g.faces.size());
  r.topology = topology;
  g.meshes.push_back(r);

  // Ownership: the first live face incident to each node and edge, listed per face in ascending order
  // (counting sort into the flat lists: one pass, no list per face).
  const int face_count = r.face_end - r.face_begin;
  std::vector<int> node_owner(mesh.nodes.size(), kNone);
  for (int f = r.face_begin; f < r.face_end; ++f)
    for (int n : g.faces[f])
      if (n != kNone && node_owner[n - r.node_begin] == kNone) node_owner[n - r.node_begin] = f - r.face_begin;
  std::vector<int> edge_owner(r.edge_end - r.edge_begin, kNone);
  for (int e = r.edge_begin; e < r.edge_end; ++e) {
    int owner = kNone;
    for (int f : g.edge_faces[e])
      if (f != kNone && (owner == kNone || f < owner)) owner = f;
    if (owner != kNone) edge_owner[e - r.edge_begin] = owner - r.face_begin;
  }
  append_owned(node_owner, r.node_begin, face_count, g.owned_node_begin, g.owned_nodes);
  append_owned(edge_owner, r.edge_begin, face_count, g.owned_edge_begin, g.owned_edges);
}

}  // namespace

void build_contact_geometry(const std::vector<ContactBody>& bodies, ContactStage stage, double dt,
                            ContactGeometry& g) {
  // Cleared, not replaced: the vectors keep their capacity from the last build (two builds a step).
  g.meshes.clear();
  for (auto* v : {&g.x0, &g.x1, &g.v, &g.rest}) v->clear();
  for (auto* v : {&g.mass, &g.area, &g.face_area}) v->clear();
  for (auto* v : {&g.node_mesh, &g.owned_node_begin, &g.owned_nodes, &g.owned_edge_begin, &g.owned_edges})
    v->clear();
  g.edges.clear();
  g.edge_faces.clear();
  g.faces.clear();
  for (const ContactBody& body : bodies) append_mesh(body, stage, dt, g);
  g.owned_node_begin.push_back(static_cast<int>(g.owned_nodes.size()));
  g.owned_edge_begin.push_back(static_cast<int>(g.owned_edges.size()));
}

double rest_distance(const ContactGeometry& g, const std::array<int, 4>& nodes, const std::array<double, 4>& weights) {
  const int mesh = g.node_mesh[nodes[0]];
  if (!g.meshes[mesh].deformable) return kInfinity;
  Vec3 gap = Vec3::Zero();
  for (int k = 0; k < 4; ++k) {
    if (nodes[k] == kNone) continue;
    if (g.node_mesh[nodes[k]] != mesh) return kInfinity;
    gap += weights[k] * g.rest[nodes[k]];
  }
  return gap.norm();
}

std::vector<Vec3> face_normals(const ContactGeometry& g, const std::vector<Vec3>& x) {
  std::vector<Vec3> n(g.faces.size(), Vec3::Zero());
  for (size_t f = 0; f < g.faces.size(); ++f) {
    const auto& v = g.faces[f];
    if (v[0] == kNone) continue;
    const Vec3 c = (x[v[1]] - x[v[0]]).cross(x[v[2]] - x[v[0]]);
    if (c.squaredNorm() > 0) n[f] = c.normalized();
  }
  return n;
}

std::vector<Vec3> node_normals(const ContactGeometry& g, const std::vector<Vec3>& face_normal) {
  std::vector<Vec3> n(g.node_count(), Vec3::Zero());
  for (size_t f = 0; f < g.faces.size(); ++f)
    if (g.faces[f][0] != kNone)
      for (int v : g.faces[f]) n[v] += face_normal[f];
  for (Vec3& d : n)
    if (d.squaredNorm() > 0) d.normalize();
  return n;
}

std::vector<Vec3> edge_normals(const ContactGeometry& g, const std::vector<Vec3>& face_normal) {
  std::vector<Vec3> n(g.edges.size(), Vec3::Zero());
  for (size_t e = 0; e < g.edges.size(); ++e) {
    for (int f : g.edge_faces[e])
      if (f != kNone) n[e] += face_normal[f];
    if (n[e].squaredNorm() > 0) n[e].normalize();
  }
  return n;
}

}  // namespace arcsim
