#include "mesh/validate.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <tuple>

#include "math/disjoint_sets.hpp"
#include "math/errors.hpp"

namespace arcsim {

bool rest_triangle_degenerate(const Vec3& u0, const Vec3& u1, const Vec3& u2) {
  const Vec3 d1 = u1 - u0, d2 = u2 - u0, d3 = u2 - u1;
  const double twice_area = d1.cross(d2).norm();
  const double longest_sq = std::max({d1.squaredNorm(), d2.squaredNorm(), d3.squaredNorm()});
  // Relative test: twice_area / longest^2 is about the sine of the smallest angle, so the threshold does not
  // depend on units. The negated comparison also catches NaN.
  return !(twice_area > kDegenerateRelativeArea * longest_sq) || !std::isfinite(twice_area);
}

namespace {

// ----------------------------------------------------------------------------------------------------------
// validate_triangles

class InputChecker {
 public:
  InputChecker(const TriangleInput& in, const std::string& file) : in_(in), file_(file) {}

  void run() {
    check_counts_and_ranges();
    check_degenerate();
    check_zero_area();
    check_duplicates();
    check_edges();
    check_fans_and_usage();
  }

 private:
  const TriangleInput& in_;
  const std::string& file_;

  // Half-edge a -> b of triangle t, keyed by the unordered node pair.
  struct HalfEdge {
    int lo, hi, tri;
    bool forward;  // runs lo -> hi
    bool operator<(const HalfEdge& o) const { return std::tie(lo, hi, tri) < std::tie(o.lo, o.hi, o.tri); }
  };

  [[noreturn]] void fail_face(size_t t, const std::string& problem) const {
    std::ostringstream s;
    s << file_;
    if (t < in_.tri_source_line.size() && in_.tri_source_line[t] > 0) s << ":" << in_.tri_source_line[t];
    s << ": face " << t + 1 << ": " << problem;
    throw InputError(s.str());
  }

  [[noreturn]] void fail_node(int node, const std::string& problem) const {
    throw InputError(file_ + ": " + problem + " (node " + std::to_string(node + 1) + ")");
  }

  int node_of(size_t t, int corner) const { return in_.vert_node[in_.tris[t][corner]]; }

  void check_counts_and_ranges() const {
    if (in_.vert_node.size() != in_.vert_u.size())
      throw InputError(file_ + ": " + std::to_string(in_.vert_u.size()) + " rest vertices but " +
                       std::to_string(in_.vert_node.size()) + " vertex->node indices");
    const long long node_count = static_cast<long long>(in_.node_count);
    for (size_t k = 0; k < in_.vert_node.size(); ++k) {
      if (in_.vert_node[k] < 0 || in_.vert_node[k] >= node_count)
        throw InputError(file_ + ": rest vertex " + std::to_string(k + 1) + " refers to node " +
                         std::to_string(in_.vert_node[k] + 1) + ", out of range (" + std::to_string(node_count) +
                         " nodes)");
      if (!in_.vert_u[k].allFinite())
        throw InputError(file_ + ": rest vertex " + std::to_string(k + 1) + " has a non-finite coordinate");
    }
    const long long vert_count = static_cast<long long>(in_.vert_u.size());
    for (size_t t = 0; t < in_.tris.size(); ++t)
      for (int c = 0; c < 3; ++c)
        if (in_.tris[t][c] < 0 || in_.tris[t][c] >= vert_count)
          fail_face(t, "vertex index " + std::to_string(in_.tris[t][c] + 1) + " out of range (" +
                           std::to_string(vert_count) + " rest vertices)");
  }

  void check_degenerate() const {
    for (size_t t = 0; t < in_.tris.size(); ++t)
      for (int c = 0; c < 3; ++c)
        if (node_of(t, c) == node_of(t, (c + 1) % 3))
          fail_face(t, "degenerate, node " + std::to_string(node_of(t, c) + 1) + " repeated");
  }

  void check_zero_area() const {
    for (size_t t = 0; t < in_.tris.size(); ++t) {
      const auto& v = in_.tris[t];
      if (rest_triangle_degenerate(in_.vert_u[v[0]], in_.vert_u[v[1]], in_.vert_u[v[2]]))
        fail_face(t, "zero area in rest space");
    }
  }

  void check_duplicates() const {
    // Sort node triples; equal neighbours are duplicates whatever their orientation.
    std::vector<std::pair<std::array<int, 3>, int>> keys(in_.tris.size());
    for (size_t t = 0; t < in_.tris.size(); ++t) {
      std::array<int, 3> k{node_of(t, 0), node_of(t, 1), node_of(t, 2)};
      std::sort(k.begin(), k.end());
      keys[t] = {k, static_cast<int>(t)};
    }
    std::sort(keys.begin(), keys.end());
    for (size_t i = 1; i < keys.size(); ++i)
      if (keys[i].first == keys[i - 1].first)
        fail_face(keys[i].second, "duplicates face " + std::to_string(keys[i - 1].second + 1));
  }

  std::vector<HalfEdge> sorted_half_edges() const {
    std::vector<HalfEdge> h;
    h.reserve(3 * in_.tris.size());
    for (size_t t = 0; t < in_.tris.size(); ++t)
      for (int c = 0; c < 3; ++c) {
        const int a = node_of(t, c), b = node_of(t, (c + 1) % 3);
        h.push_back({std::min(a, b), std::max(a, b), static_cast<int>(t), a < b});
      }
    std::sort(h.begin(), h.end());
    return h;
  }

  static std::string edge_name(const HalfEdge& h) {
    return "edge (node " + std::to_string(h.lo + 1) + ", node " + std::to_string(h.hi + 1) + ")";
  }

  void check_edges() {
    half_edges_ = sorted_half_edges();
    const auto& h = half_edges_;
    // Non-manifold edges first (all of them), then orientation, following the documented order.
    for (size_t i = 2; i < h.size(); ++i)
      if (h[i].lo == h[i - 2].lo && h[i].hi == h[i - 2].hi)
        fail_face(h[i].tri, "non-manifold " + edge_name(h[i]) + " has more than two faces");
    for (size_t i = 1; i < h.size(); ++i)
      if (h[i].lo == h[i - 1].lo && h[i].hi == h[i - 1].hi && h[i].forward == h[i - 1].forward)
        fail_face(h[i].tri, "inconsistent orientation: runs " + edge_name(h[i]) + " the same way as face " +
                                std::to_string(h[i - 1].tri + 1));
  }

  void check_fans_and_usage() const {
    // Corners (3t + c) at the same node are joined when their faces share an edge at that node; a manifold
    // node ends with one group.
    DisjointSets corners(3 * in_.tris.size());
    auto corner_at = [&](int tri, int node) {
      for (int c = 0; c < 3; ++c)
        if (node_of(tri, c) == node) return 3 * tri + c;
      return -1;  // unreachable: the half-edge came from this triangle
    };
    const auto& h = half_edges_;
    for (size_t i = 1; i < h.size(); ++i) {
      if (h[i].lo != h[i - 1].lo || h[i].hi != h[i - 1].hi) continue;
      for (int node : {h[i].lo, h[i].hi}) corners.unite(corner_at(h[i].tri, node), corner_at(h[i - 1].tri, node));
    }
    std::vector<int> first_root(in_.node_count, -1);
    std::vector<char> several_fans(in_.node_count, 0);
    for (size_t t = 0; t < in_.tris.size(); ++t)
      for (int c = 0; c < 3; ++c) {
        const int node = node_of(t, c);
        const int root = corners.find(static_cast<int>(3 * t + c));
        if (first_root[node] == -1) first_root[node] = root;
        else if (root != first_root[node]) several_fans[node] = 1;
      }
    // Lowest-numbered offender first, for a deterministic message.
    for (size_t n = 0; n < in_.node_count; ++n)
      if (several_fans[n]) fail_node(static_cast<int>(n), "non-manifold vertex: its faces form more than one fan");
    for (size_t n = 0; n < in_.node_count; ++n)
      if (first_root[n] == -1) fail_node(static_cast<int>(n), "node referenced by no face");
  }

  std::vector<HalfEdge> half_edges_;
};

// ----------------------------------------------------------------------------------------------------------
// check_mesh

class MeshChecker {
 public:
  MeshChecker(const Mesh& mesh, const MeshCheckOptions& options) : m_(mesh), opt_(options) {}

  std::string run() {
    if (!check_nodes() || !check_verts() || !check_face_corners() || !check_edges() || !check_face_edges())
      return problem_;
    if (!check_duplicate_edges() || !check_duplicate_faces() || !check_fans()) return problem_;
    if (opt_.require_positive_rest_area && !check_rest_areas()) return problem_;
    if (opt_.require_current_rest_data && !check_rest_data_current()) return problem_;
    if (opt_.require_finite_state && !check_finite_state()) return problem_;
    return "";
  }

 private:
  const Mesh& m_;
  const MeshCheckOptions& opt_;
  std::string problem_;

  bool fail(const std::string& what, int index, const std::string& text) {
    problem_ = what + " " + std::to_string(index) + ": " + text;
    return false;
  }

  static bool in_range(int i, size_t n) { return i >= 0 && static_cast<size_t>(i) < n; }
  bool live_node(int i) const { return in_range(i, m_.nodes.size()) && !m_.nodes[i].dead; }
  bool live_vert(int i) const { return in_range(i, m_.verts.size()) && !m_.verts[i].dead; }
  bool live_edge(int i) const { return in_range(i, m_.edges.size()) && !m_.edges[i].dead; }
  bool live_face(int i) const { return in_range(i, m_.faces.size()) && !m_.faces[i].dead; }

  static bool contains(const std::vector<int>& list, int x) {
    return std::find(list.begin(), list.end(), x) != list.end();
  }
  static bool has_repeats(std::vector<int> list) {
    std::sort(list.begin(), list.end());
    return std::adjacent_find(list.begin(), list.end()) != list.end();
  }

  bool check_nodes() {
    for (size_t i = 0; i < m_.nodes.size(); ++i) {
      const Node& n = m_.nodes[i];
      const int ni = static_cast<int>(i);
      if (n.dead) continue;
      if (n.verts.empty()) return fail("node", ni, "has no rest vertices");
      if (n.edges.empty()) return fail("node", ni, "has no edges");
      for (int v : n.verts) {
        if (!live_vert(v)) return fail("node", ni, "lists dead or invalid vert " + std::to_string(v));
        if (m_.verts[v].node != ni)
          return fail("node", ni, "lists vert " + std::to_string(v) + " which belongs to node " +
                                      std::to_string(m_.verts[v].node));
      }
      for (int e : n.edges) {
        if (!live_edge(e)) return fail("node", ni, "lists dead or invalid edge " + std::to_string(e));
        if (m_.edges[e].n[0] != ni && m_.edges[e].n[1] != ni)
          return fail("node", ni, "lists edge " + std::to_string(e) + " which does not touch it");
      }
      if (has_repeats(n.verts)) return fail("node", ni, "lists a vert twice");
      if (has_repeats(n.edges)) return fail("node", ni, "lists an edge twice");
    }
    return true;
  }

  bool check_verts() {
    for (size_t i = 0; i < m_.verts.size(); ++i) {
      const Vert& v = m_.verts[i];
      const int vi = static_cast<int>(i);
      if (v.dead) continue;
      if (!live_node(v.node)) return fail("vert", vi, "belongs to dead or invalid node " + std::to_string(v.node));
      if (!contains(m_.nodes[v.node].verts, vi))
        return fail("vert", vi, "missing from the vert list of its node " + std::to_string(v.node));
      if (v.faces.empty()) return fail("vert", vi, "has no faces");
      for (int f : v.faces) {
        if (!live_face(f)) return fail("vert", vi, "lists dead or invalid face " + std::to_string(f));
        const auto& corners = m_.faces[f].v;
        if (std::find(corners.begin(), corners.end(), vi) == corners.end())
          return fail("vert", vi, "lists face " + std::to_string(f) + " which does not use it");
      }
      if (has_repeats(v.faces)) return fail("vert", vi, "lists a face twice");
    }
    return true;
  }

  // The corner of face f at which an edge starting at node a and ending at node b runs CCW, or -1.
  int corner_running(int f, int a, int b) const {
    for (int c = 0; c < 3; ++c)
      if (m_.face_node(f, c) == a && m_.face_node(f, (c + 1) % 3) == b) return c;
    return -1;
  }

  bool check_edges() {
    for (size_t i = 0; i < m_.edges.size(); ++i) {
      const Edge& e = m_.edges[i];
      const int ei = static_cast<int>(i);
      if (e.dead) continue;
      for (int s = 0; s < 2; ++s) {
        if (!live_node(e.n[s])) return fail("edge", ei, "joins dead or invalid node " + std::to_string(e.n[s]));
        if (!contains(m_.nodes[e.n[s]].edges, ei))
          return fail("edge", ei, "missing from the edge list of its node " + std::to_string(e.n[s]));
      }
      if (e.n[0] == e.n[1]) return fail("edge", ei, "joins node " + std::to_string(e.n[0]) + " to itself");
      if (e.f[0] == kNone && e.f[1] == kNone) return fail("edge", ei, "has no faces");
      if (e.f[0] == e.f[1]) return fail("edge", ei, "has the same face on both sides");
      for (int s = 0; s < 2; ++s) {
        const int f = e.f[s];
        if (f == kNone) continue;
        if (!live_face(f)) return fail("edge", ei, "refers to dead or invalid face " + std::to_string(f));
        // f[0] runs n0 -> n1, f[1] runs n1 -> n0.
        const int c = corner_running(f, e.n[s], e.n[1 - s]);
        if (c < 0)
          return fail("edge", ei, "face " + std::to_string(f) + " on side " + std::to_string(s) +
                                      " does not run the edge in the required direction");
        if (m_.faces[f].e[c] != ei)
          return fail("edge", ei, "face " + std::to_string(f) + " does not list it at corner " + std::to_string(c));
      }
    }
    return true;
  }

  bool check_face_corners() {
    for (size_t i = 0; i < m_.faces.size(); ++i) {
      const Face& f = m_.faces[i];
      const int fi = static_cast<int>(i);
      if (f.dead) continue;
      for (int c = 0; c < 3; ++c) {
        const int v = f.v[c];
        if (!live_vert(v)) return fail("face", fi, "uses dead or invalid vert " + std::to_string(v));
        if (!contains(m_.verts[v].faces, fi))
          return fail("face", fi, "missing from the face list of its vert " + std::to_string(v));
      }
      for (int c = 0; c < 3; ++c)
        if (m_.face_node(fi, c) == m_.face_node(fi, (c + 1) % 3))
          return fail("face", fi, "is degenerate: node " + std::to_string(m_.face_node(fi, c)) + " repeated");
    }
    return true;
  }

  bool check_face_edges() {
    for (size_t i = 0; i < m_.faces.size(); ++i) {
      const Face& f = m_.faces[i];
      const int fi = static_cast<int>(i);
      if (f.dead) continue;
      for (int c = 0; c < 3; ++c) {
        const int e = f.e[c];
        if (!live_edge(e)) return fail("face", fi, "uses dead or invalid edge " + std::to_string(e));
        const int a = m_.face_node(fi, c), b = m_.face_node(fi, (c + 1) % 3);
        const Edge& ed = m_.edges[e];
        const bool forward = ed.n[0] == a && ed.n[1] == b;
        const bool backward = ed.n[0] == b && ed.n[1] == a;
        if (!forward && !backward)
          return fail("face", fi, "edge " + std::to_string(e) + " does not join corners " + std::to_string(c) +
                                      " and " + std::to_string((c + 1) % 3));
        if (ed.f[forward ? 0 : 1] != fi)
          return fail("face", fi, "not on the expected side of its edge " + std::to_string(e) +
                                      " (orientation mismatch)");
      }
    }
    return true;
  }

  bool check_duplicate_edges() {
    std::vector<std::tuple<int, int, int>> keys;
    for (size_t i = 0; i < m_.edges.size(); ++i) {
      const Edge& e = m_.edges[i];
      if (!e.dead) keys.emplace_back(std::min(e.n[0], e.n[1]), std::max(e.n[0], e.n[1]), static_cast<int>(i));
    }
    std::sort(keys.begin(), keys.end());
    for (size_t i = 1; i < keys.size(); ++i)
      if (std::get<0>(keys[i]) == std::get<0>(keys[i - 1]) && std::get<1>(keys[i]) == std::get<1>(keys[i - 1]))
        return fail("edge", std::get<2>(keys[i]),
                    "duplicates edge " + std::to_string(std::get<2>(keys[i - 1])) + " (non-manifold)");
    return true;
  }

  bool check_duplicate_faces() {
    std::vector<std::pair<std::array<int, 3>, int>> keys;
    for (size_t i = 0; i < m_.faces.size(); ++i) {
      if (m_.faces[i].dead) continue;
      const int fi = static_cast<int>(i);
      std::array<int, 3> k{m_.face_node(fi, 0), m_.face_node(fi, 1), m_.face_node(fi, 2)};
      std::sort(k.begin(), k.end());
      keys.emplace_back(k, fi);
    }
    std::sort(keys.begin(), keys.end());
    for (size_t i = 1; i < keys.size(); ++i)
      if (keys[i].first == keys[i - 1].first)
        return fail("face", keys[i].second, "duplicates face " + std::to_string(keys[i - 1].second));
    return true;
  }

  bool check_fans() {
    std::vector<int> fan;
    for (size_t i = 0; i < m_.nodes.size(); ++i) {
      const Node& n = m_.nodes[i];
      if (n.dead) continue;
      fan.clear();
      for (int v : n.verts) fan.insert(fan.end(), m_.verts[v].faces.begin(), m_.verts[v].faces.end());
      if (has_repeats(fan)) return fail("node", static_cast<int>(i), "a face uses two verts of the node");
      // Faces are joined across the node's edges; one group means one fan. Degrees are small, so linear
      // look-ups are fine.
      DisjointSets groups(fan.size());
      auto local = [&](int f) { return static_cast<int>(std::find(fan.begin(), fan.end(), f) - fan.begin()); };
      for (int e : n.edges) {
        const Edge& ed = m_.edges[e];
        if (ed.f[0] == kNone || ed.f[1] == kNone) continue;
        const int a = local(ed.f[0]), b = local(ed.f[1]);
        if (a == static_cast<int>(fan.size()) || b == static_cast<int>(fan.size()))
          return fail("node", static_cast<int>(i), "edge " + std::to_string(e) + " has a face not at the node");
        groups.unite(a, b);
      }
      for (size_t k = 1; k < fan.size(); ++k)
        if (groups.find(static_cast<int>(k)) != groups.find(0))
          return fail("node", static_cast<int>(i), "non-manifold: its faces form more than one fan");
      // Each face at the node must reach it through two of the node's edges (else the edge lists are wrong).
      for (int f : fan)
        for (int c = 0; c < 3; ++c)
          if ((m_.face_node(f, c) == static_cast<int>(i) || m_.face_node(f, (c + 1) % 3) == static_cast<int>(i)) &&
              !contains(n.edges, m_.faces[f].e[c]))
            return fail("node", static_cast<int>(i), "edge list misses edge " + std::to_string(m_.faces[f].e[c]));
    }
    return true;
  }

  bool check_rest_areas() {
    for (size_t i = 0; i < m_.faces.size(); ++i) {
      const Face& f = m_.faces[i];
      if (!f.dead && rest_triangle_degenerate(m_.verts[f.v[0]].u, m_.verts[f.v[1]].u, m_.verts[f.v[2]].u))
        return fail("face", static_cast<int>(i), "has zero or near-zero rest area");
    }
    return true;
  }

  // Stale derived data is how a forgotten update_rest_data after an edit shows.
  bool check_rest_data_current() {
    for (size_t i = 0; i < m_.faces.size(); ++i) {
      const Face& f = m_.faces[i];
      if (f.dead) continue;
      const Vec3 &u0 = m_.verts[f.v[0]].u, &u1 = m_.verts[f.v[1]].u, &u2 = m_.verts[f.v[2]].u;
      const Vec3 normal = (u1 - u0).cross(u2 - u0);
      const double area = 0.5 * normal.norm();
      if (area > 0 && !(f.rest_normal.dot(normal.normalized()) > 1 - 1e-9))
        return fail("face", static_cast<int>(i), "stale rest data (rest_normal does not match the rest vertices)");
      if (!(std::abs(f.rest_area - area) <= 1e-9 * area))
        return fail("face", static_cast<int>(i), "stale rest data (rest_area " + std::to_string(f.rest_area) +
                                                     ", geometry gives " + std::to_string(area) + ")");
    }
    return true;
  }

  bool check_finite_state() {
    problem_ = nonfinite_state(m_);
    return problem_.empty();
  }
};

}  // namespace

void validate_triangles(const TriangleInput& in, const std::string& file) { InputChecker(in, file).run(); }

std::string nonfinite_state(const Mesh& mesh) {
  auto problem = [](const char* what, size_t index, const char* text) {
    return std::string(what) + " " + std::to_string(index) + ": " + text;
  };
  for (size_t i = 0; i < mesh.nodes.size(); ++i) {
    const Node& n = mesh.nodes[i];
    if (n.dead) continue;
    if (!n.x.allFinite() || !n.x0.allFinite() || !n.v.allFinite() || !n.a.allFinite() || !std::isfinite(n.mass))
      return problem("node", i, "has non-finite x, x0, v, a or mass");
  }
  for (size_t i = 0; i < mesh.verts.size(); ++i) {
    const Vert& v = mesh.verts[i];
    if (!v.dead && (!v.u.allFinite() || !v.sizing.allFinite())) return problem("vert", i, "has non-finite u or sizing");
  }
  for (size_t i = 0; i < mesh.edges.size(); ++i) {
    const Edge& e = mesh.edges[i];
    if (!e.dead && (!std::isfinite(e.rest_theta) || !std::isfinite(e.damage)))
      return problem("edge", i, "has non-finite rest_theta or damage");
  }
  for (size_t i = 0; i < mesh.faces.size(); ++i) {
    const Face& f = mesh.faces[i];
    if (f.dead) continue;
    if (!std::isfinite(f.thickness) || !f.Fp.allFinite() || !f.Sp.allFinite() || !std::isfinite(f.damage))
      return problem("face", i, "has non-finite thickness, Fp, Sp or damage");
    if (!std::isfinite(f.rest_area) || !f.rest_normal.allFinite() || !f.rest_frame.allFinite() ||
        !f.Dm_inv.allFinite())
      return problem("face", i, "has non-finite derived rest data");
  }
  return "";
}

std::string check_mesh(const Mesh& mesh, const MeshCheckOptions& options) {
  return MeshChecker(mesh, options).run();
}

int count_components(const Mesh& mesh) {
  DisjointSets pieces(mesh.faces.size());
  for (const Edge& e : mesh.edges)
    if (!e.dead && e.f[0] != kNone && e.f[1] != kNone) pieces.unite(e.f[0], e.f[1]);
  int count = 0;
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    if (!mesh.faces[f].dead && pieces.find(static_cast<int>(f)) == static_cast<int>(f)) ++count;
  return count;
}

}  // namespace arcsim
