#include "mesh/mesh.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>

namespace arcsim {

namespace {

// Removes `value` from `list` keeping the order of the rest (adjacency order must not depend on edit history
// in ways that break determinism, and stable order keeps it reproducible).
void erase_value(std::vector<int>& list, int value) {
  auto it = std::find(list.begin(), list.end(), value);
  if (it != list.end()) list.erase(it);
}

}  // namespace

double dihedral_angle(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3) {
  const Vec3 e = x1 - x0;
  const Vec3 nA = e.cross(x2 - x0);
  const Vec3 nB = (x3 - x0).cross(e);
  const double le = e.norm();
  if (le == 0 || nA.squaredNorm() == 0 || nB.squaredNorm() == 0) return 0;
  const Vec3 a = nA.normalized(), b = nB.normalized();
  return std::atan2(a.cross(b).dot(e / le), a.dot(b));
}

Mesh Mesh::from_triangles(const std::vector<Vec3>& node_x, const std::vector<Vec3>& vert_u,
                          const std::vector<int>& vert_node, const std::vector<std::array<int, 3>>& tris,
                          const std::vector<int>& tri_material) {
  Mesh m;
  m.nodes.reserve(node_x.size());
  for (const Vec3& x : node_x) {
    Node n;
    n.x = n.x0 = x;
    m.add_node(n);
  }
  m.verts.reserve(vert_u.size());
  for (size_t k = 0; k < vert_u.size(); ++k) {
    Vert v;
    v.u = vert_u[k];
    m.add_vert(v, vert_node[k]);
  }
  m.faces.reserve(tris.size());
  for (size_t t = 0; t < tris.size(); ++t) {
    Face proto;
    proto.material = tri_material.empty() ? 0 : tri_material[t];
    m.add_face(tris[t], proto);
  }
  m.update_rest_data();
  for (size_t e = 0; e < m.edges.size(); ++e) m.edges[e].rest_theta = m.rest_dihedral(static_cast<int>(e));
  return m;
}

int Mesh::add_node(const Node& n) {
  nodes.push_back(n);
  nodes.back().dead = false;  // the prototype may be a removed element
  nodes.back().verts.clear();
  nodes.back().edges.clear();
  return static_cast<int>(nodes.size()) - 1;
}

int Mesh::add_vert(const Vert& v, int node) {
  verts.push_back(v);
  Vert& nv = verts.back();
  nv.dead = false;
  nv.faces.clear();
  nv.node = node;
  const int index = static_cast<int>(verts.size()) - 1;
  nodes[node].verts.push_back(index);
  return index;
}

int Mesh::find_edge(int n0, int n1) const {
  for (int e : nodes[n0].edges) {
    const Edge& ed = edges[e];
    if ((ed.n[0] == n0 && ed.n[1] == n1) || (ed.n[0] == n1 && ed.n[1] == n0)) return e;
  }
  return kNone;
}

int Mesh::get_or_add_edge(int n0, int n1) {
  const int existing = find_edge(n0, n1);
  if (existing != kNone) return existing;
  Edge e;
  e.n = {n0, n1};
  edges.push_back(e);
  const int index = static_cast<int>(edges.size()) - 1;
  nodes[n0].edges.push_back(index);
  nodes[n1].edges.push_back(index);
  return index;
}

int Mesh::add_face(const std::array<int, 3>& v, const Face& prototype) {
  // Check everything before linking anything, so that a refused face leaves the mesh unchanged.
  for (int i = 0; i < 3; ++i) {
    const int a = verts[v[i]].node, b = verts[v[(i + 1) % 3]].node;
    if (a == b) throw std::logic_error("add_face: degenerate face (a node repeated)");
    const int e = find_edge(a, b);
    if (e != kNone && edges[e].f[edges[e].n[0] == a ? 0 : 1] != kNone)
      throw std::logic_error("add_face: edge side already taken (non-manifold or inconsistently oriented)");
  }
  Face f = prototype;
  f.dead = false;  // the prototype may be a removed face
  f.v = v;
  faces.push_back(f);
  const int index = static_cast<int>(faces.size()) - 1;
  for (int i = 0; i < 3; ++i) verts[v[i]].faces.push_back(index);
  for (int i = 0; i < 3; ++i) {
    const int a = verts[v[i]].node, b = verts[v[(i + 1) % 3]].node;
    const int e = get_or_add_edge(a, b);
    faces[index].e[i] = e;
    // The face runs a -> b; it is f[0] if the edge is stored as a -> b.
    edges[e].f[edges[e].n[0] == a ? 0 : 1] = index;
  }
  return index;
}

void Mesh::remove_face(int f) {
  assert(!faces[f].dead);
  for (int i = 0; i < 3; ++i) {
    erase_value(verts[faces[f].v[i]].faces, f);
    Edge& e = edges[faces[f].e[i]];
    for (int s = 0; s < 2; ++s)
      if (e.f[s] == f) e.f[s] = kNone;
  }
  faces[f].dead = true;
  ++dead_count_;
}

void Mesh::remove_edge(int e) {
  assert(!edges[e].dead && edges[e].f[0] == kNone && edges[e].f[1] == kNone);
  for (int s = 0; s < 2; ++s) erase_value(nodes[edges[e].n[s]].edges, e);
  edges[e].dead = true;
  ++dead_count_;
}

void Mesh::remove_vert(int v) {
  assert(!verts[v].dead && verts[v].faces.empty());
  erase_value(nodes[verts[v].node].verts, v);
  verts[v].dead = true;
  ++dead_count_;
}

void Mesh::remove_node(int n) {
  assert(!nodes[n].dead && nodes[n].verts.empty() && nodes[n].edges.empty());
  nodes[n].dead = true;
  ++dead_count_;
}

namespace {

// Keeps the live elements of `items` in order and returns the old -> new index map.
template <typename T>
std::vector<int> compact_vector(std::vector<T>& items) {
  std::vector<int> map(items.size(), kNone);
  size_t next = 0;
  for (size_t i = 0; i < items.size(); ++i) {
    if (items[i].dead) continue;
    map[i] = static_cast<int>(next);
    if (next != i) items[next] = std::move(items[i]);
    ++next;
  }
  items.resize(next);
  return map;
}

void remap(std::vector<int>& list, const std::vector<int>& map) {
  for (int& x : list) x = map[x];
}

int remap_one(int x, const std::vector<int>& map) { return x == kNone ? kNone : map[x]; }

}  // namespace

bool Mesh::is_compact() const { return dead_count_ == 0; }

Mesh::Compaction Mesh::compact() {
  Compaction c;
  c.node = compact_vector(nodes);
  c.vert = compact_vector(verts);
  c.edge = compact_vector(edges);
  c.face = compact_vector(faces);
  for (Node& n : nodes) {
    remap(n.verts, c.vert);
    remap(n.edges, c.edge);
  }
  for (Vert& v : verts) {
    v.node = c.node[v.node];
    remap(v.faces, c.face);
  }
  for (Edge& e : edges) {
    for (int s = 0; s < 2; ++s) {
      e.n[s] = c.node[e.n[s]];
      e.f[s] = remap_one(e.f[s], c.face);
    }
  }
  for (Face& f : faces) {
    for (int i = 0; i < 3; ++i) {
      f.v[i] = c.vert[f.v[i]];
      f.e[i] = c.edge[f.e[i]];
    }
  }
  dead_count_ = 0;
  return c;
}

std::vector<int> Mesh::node_faces(int n) const {
  std::vector<int> around;
  for (int v : nodes[n].verts) around.insert(around.end(), verts[v].faces.begin(), verts[v].faces.end());
  std::sort(around.begin(), around.end());
  around.erase(std::unique(around.begin(), around.end()), around.end());
  return around;
}

int Mesh::corner_of_node(int f, int node) const {
  for (int i = 0; i < 3; ++i)
    if (face_node(f, i) == node) return i;
  return kNone;
}

int Mesh::opposite_node(int e, int f) const {
  if (f == kNone) return kNone;
  for (int i = 0; i < 3; ++i) {
    const int n = face_node(f, i);
    if (n != edges[e].n[0] && n != edges[e].n[1]) return n;
  }
  return kNone;
}

bool Mesh::is_boundary_node(int n) const {
  for (int e : nodes[n].edges)
    if (edges[e].is_boundary()) return true;
  return false;
}

void Mesh::update_rest_data(int fi) {
  Face& f = faces[fi];
  const Vec3& u0 = verts[f.v[0]].u;
  const Vec3 d1 = verts[f.v[1]].u - u0, d2 = verts[f.v[2]].u - u0;
  const Vec3 c = d1.cross(d2);
  const double twice_area = c.norm();
  f.rest_area = 0.5 * twice_area;
  if (twice_area <= 0) {
    f.rest_normal = Vec3::UnitZ();
    f.rest_frame.setZero();
    f.Dm_inv.setZero();
    return;
  }
  f.rest_normal = c / twice_area;
  // Material frame: t1 is the rest-space x axis projected onto the face (the warp direction of a flat sheet
  // in the xy plane, as in ARCSim), or the y axis where the face is nearly perpendicular to x.
  Vec3 axis = Vec3::UnitX() - f.rest_normal.x() * f.rest_normal;
  if (axis.squaredNorm() < 1e-6) axis = Vec3::UnitY() - f.rest_normal.y() * f.rest_normal;
  const Vec3 t1 = axis.normalized();
  const Vec3 t2 = f.rest_normal.cross(t1);
  f.rest_frame.col(0) = t1;
  f.rest_frame.col(1) = t2;
  Mat2 Dm;
  Dm << t1.dot(d1), t1.dot(d2), t2.dot(d1), t2.dot(d2);
  f.Dm_inv = Dm.inverse();
}

void Mesh::update_rest_data() {
  for (size_t f = 0; f < faces.size(); ++f)
    if (!faces[f].dead) update_rest_data(static_cast<int>(f));
}

double Mesh::rest_dihedral(int ei) const {
  const Edge& e = edges[ei];
  if (e.is_boundary()) return 0;
  const Face& A = faces[e.f[0]];
  const Face& B = faces[e.f[1]];
  // Rest-space hinge: the edge's verts must be shared by both faces, otherwise the edge is a seam.
  int a0 = kNone, a1 = kNone, a2 = kNone, b0 = kNone, b1 = kNone, b3 = kNone;
  for (int i = 0; i < 3; ++i) {
    const int n = verts[A.v[i]].node;
    if (n == e.n[0]) a0 = A.v[i];
    else if (n == e.n[1]) a1 = A.v[i];
    else a2 = A.v[i];
  }
  for (int i = 0; i < 3; ++i) {
    const int n = verts[B.v[i]].node;
    if (n == e.n[0]) b0 = B.v[i];
    else if (n == e.n[1]) b1 = B.v[i];
    else b3 = B.v[i];
  }
  if (a0 != b0 || a1 != b1) return 0;
  return dihedral_angle(verts[a0].u, verts[a1].u, verts[a2].u, verts[b3].u);
}

double Mesh::world_dihedral(int ei) const {
  const Edge& e = edges[ei];
  if (e.is_boundary()) return 0;
  return dihedral_angle(nodes[e.n[0]].x, nodes[e.n[1]].x, nodes[opposite_node(ei, e.f[0])].x,
                        nodes[opposite_node(ei, e.f[1])].x);
}

Vec3 Mesh::world_normal(int f) const {
  const Vec3& x0 = nodes[face_node(f, 0)].x;
  const Vec3 c = (nodes[face_node(f, 1)].x - x0).cross(nodes[face_node(f, 2)].x - x0);
  const double n = c.norm();
  return n > 0 ? Vec3(c / n) : Vec3::UnitZ();
}

double Mesh::world_area(int f) const {
  const Vec3& x0 = nodes[face_node(f, 0)].x;
  return 0.5 * (nodes[face_node(f, 1)].x - x0).cross(nodes[face_node(f, 2)].x - x0).norm();
}

namespace {

std::vector<Vec3> normalized(std::vector<Vec3> sums) {
  for (Vec3& n : sums) {
    const double len = n.norm();
    n = len > 0 ? Vec3(n / len) : Vec3::Zero();
  }
  return sums;
}

}  // namespace

std::vector<Vec3> world_node_normals(const Mesh& mesh) {
  std::vector<Vec3> sums(mesh.nodes.size(), Vec3::Zero());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (mesh.faces[f].dead) continue;
    const int fi = static_cast<int>(f);
    const Vec3& x0 = mesh.nodes[mesh.face_node(fi, 0)].x;
    // Twice the area times the unit normal: area weighting for free.
    const Vec3 weighted = (mesh.nodes[mesh.face_node(fi, 1)].x - x0).cross(mesh.nodes[mesh.face_node(fi, 2)].x - x0);
    for (int i = 0; i < 3; ++i) sums[mesh.face_node(fi, i)] += weighted;
  }
  return normalized(std::move(sums));
}

std::vector<Vec3> rest_vert_normals(const Mesh& mesh) {
  std::vector<Vec3> sums(mesh.verts.size(), Vec3::Zero());
  for (const Face& face : mesh.faces) {
    if (face.dead) continue;
    const Vec3& u0 = mesh.verts[face.v[0]].u;
    const Vec3 weighted = (mesh.verts[face.v[1]].u - u0).cross(mesh.verts[face.v[2]].u - u0);
    for (int v : face.v) sums[v] += weighted;
  }
  return normalized(std::move(sums));
}

namespace {

Vec3 unit_or_zero(const Vec3& n) {
  const double len = n.norm();
  return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

}  // namespace

void update_world_node_normals(const Mesh& mesh, const std::vector<int>& nodes, std::vector<Vec3>& normals) {
  normals.resize(mesh.nodes.size(), Vec3::Zero());
  for (int n : nodes) {
    Vec3 sum = Vec3::Zero();
    for (int fi : mesh.node_faces(n)) {  // ascending
      if (mesh.faces[fi].dead) continue;
      const Vec3& x0 = mesh.nodes[mesh.face_node(fi, 0)].x;
      sum += (mesh.nodes[mesh.face_node(fi, 1)].x - x0).cross(mesh.nodes[mesh.face_node(fi, 2)].x - x0);
    }
    normals[n] = unit_or_zero(sum);
  }
}

void update_rest_vert_normals(const Mesh& mesh, const std::vector<int>& verts, std::vector<Vec3>& normals) {
  normals.resize(mesh.verts.size(), Vec3::Zero());
  std::vector<int> around;
  for (int v : verts) {
    around = mesh.verts[v].faces;
    std::sort(around.begin(), around.end());
    Vec3 sum = Vec3::Zero();
    for (int f : around) {
      const Face& face = mesh.faces[f];
      if (face.dead) continue;
      const Vec3& u0 = mesh.verts[face.v[0]].u;
      sum += (mesh.verts[face.v[1]].u - u0).cross(mesh.verts[face.v[2]].u - u0);
    }
    normals[v] = unit_or_zero(sum);
  }
}

}  // namespace arcsim
