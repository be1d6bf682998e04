#include "collision/candidates.hpp"

#include <algorithm>

namespace arcsim {

std::array<int, 4> pair_nodes(const ContactGeometry& g, const PrimitivePair& p) {
  switch (p.kind) {
    case PairKind::kVertexFace: {
      const auto& f = g.faces[p.b];
      return {p.a, f[0], f[1], f[2]};
    }
    case PairKind::kEdgeEdge:
      return {g.edges[p.a][0], g.edges[p.a][1], g.edges[p.b][0], g.edges[p.b][1]};
    case PairKind::kVertexEdge:
      break;
  }
  return {p.a, g.edges[p.b][0], g.edges[p.b][1], kNone};
}

void BvhCache::update(const ContactGeometry& g, const std::vector<Aabb>& face_boxes) {
  trees_.resize(g.meshes.size());
  topology_.resize(g.meshes.size(), 0);
  for (size_t m = 0; m < g.meshes.size(); ++m) {
    const auto& r = g.meshes[m];
    const std::vector<Aabb> boxes(face_boxes.begin() + r.face_begin, face_boxes.begin() + r.face_end);
    if (topology_[m] != r.topology || trees_[m].primitive_count() != static_cast<int>(boxes.size()) ||
        trees_[m].empty()) {
      trees_[m].build(boxes);
      topology_[m] = r.topology;
      ++builds_;
    } else {
      trees_[m].refit(boxes);
    }
  }
}

namespace {

bool contains(const std::array<int, 3>& face, int node) {
  return face[0] == node || face[1] == node || face[2] == node;
}
bool share_node(const std::array<int, 2>& a, const std::array<int, 2>& b) {
  return a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1];
}

class CandidateFinder {
 public:
  CandidateFinder(const ContactGeometry& g, const CandidateOptions& options) : g_(g), options_(options) {
    node_box_.resize(g.node_count());
    for (int n = 0; n < g.node_count(); ++n) {
      Aabb b;
      b.extend(g.x0[n]);
      if (options.swept) b.extend(g.x1[n]);
      b.inflate(0.5 * options.margin);
      node_box_[n] = b;
    }
    // Each face's and edge's box once: a face pair's tests ask for them again and again.
    face_box_.resize(g.faces.size());
    for (size_t f = 0; f < g.faces.size(); ++f)
      if (g.faces[f][0] != kNone)
        for (int n : g.faces[f]) face_box_[f].extend(node_box_[n]);
    edge_box_.resize(g.edges.size());
    for (size_t e = 0; e < g.edges.size(); ++e)
      if (g.edges[e][0] != kNone) {
        edge_box_[e] = node_box_[g.edges[e][0]];
        edge_box_[e].extend(node_box_[g.edges[e][1]]);
      }
    if (options.vertex_edge) {
      on_boundary_.assign(g.node_count(), 0);
      for (size_t e = 0; e < g.edges.size(); ++e)
        if (g.edges[e][0] != kNone && g.is_boundary_edge(static_cast<int>(e)))
          on_boundary_[g.edges[e][0]] = on_boundary_[g.edges[e][1]] = 1;
    }
  }

  const std::vector<Aabb>& face_boxes() const { return face_box_; }

  // Per face of mesh range r: has a moved node (only with options.moved).
  std::vector<char> moved_faces(const ContactGeometry::Range& r) const {
    std::vector<char> flags(r.face_end - r.face_begin, 0);
    for (int f = r.face_begin; f < r.face_end; ++f)
      if (g_.faces[f][0] != kNone)
        for (int n : g_.faces[f]) flags[f - r.face_begin] |= (*options_.moved)[n];
    return flags;
  }

  // Primitive pairs of the face pair (fa, fb), fa != fb.
  void face_pair(int fa, int fb, std::vector<PrimitivePair>& out) const {
    vertices_against_face(fa, fb, out);
    vertices_against_face(fb, fa, out);
    for (int k = g_.owned_edge_begin[fa]; k < g_.owned_edge_begin[fa + 1]; ++k) {
      const int ea = g_.owned_edges[k];
      const Aabb& box_a = edge_box_[ea];
      for (int l = g_.owned_edge_begin[fb]; l < g_.owned_edge_begin[fb + 1]; ++l) {
        const int eb = g_.owned_edges[l];
        if (!any_moved(g_.edges[ea]) && !any_moved(g_.edges[eb])) continue;
        if (share_node(g_.edges[ea], g_.edges[eb]) || !box_a.overlaps(edge_box_[eb])) continue;
        out.push_back({PairKind::kEdgeEdge, std::min(ea, eb), std::max(ea, eb)});
      }
    }
    if (options_.vertex_edge && g_.meshes[mesh_of_face(fa)].deformable && g_.meshes[mesh_of_face(fb)].deformable) {
      boundary_vertices_against_edges(fa, fb, out);
      boundary_vertices_against_edges(fb, fa, out);
    }
  }

 private:
  int mesh_of_face(int f) const { return g_.node_mesh[g_.faces[f][0]]; }

  bool moved(int n) const { return !options_.moved || (*options_.moved)[n]; }
  bool any_moved(const std::array<int, 2>& e) const { return moved(e[0]) || moved(e[1]); }
  bool any_moved(const std::array<int, 3>& f) const { return moved(f[0]) || moved(f[1]) || moved(f[2]); }

  void vertices_against_face(int owner, int face, std::vector<PrimitivePair>& out) const {
    const Aabb& box = face_box_[face];
    const bool face_moved = any_moved(g_.faces[face]);
    for (int k = g_.owned_node_begin[owner]; k < g_.owned_node_begin[owner + 1]; ++k) {
      const int n = g_.owned_nodes[k];
      if (!face_moved && !moved(n)) continue;
      if (contains(g_.faces[face], n) || !node_box_[n].overlaps(box)) continue;
      out.push_back({PairKind::kVertexFace, n, face});
    }
  }

  void boundary_vertices_against_edges(int owner, int face, std::vector<PrimitivePair>& out) const {
    for (int k = g_.owned_node_begin[owner]; k < g_.owned_node_begin[owner + 1]; ++k) {
      const int n = g_.owned_nodes[k];
      if (!on_boundary_[n]) continue;
      for (int l = g_.owned_edge_begin[face]; l < g_.owned_edge_begin[face + 1]; ++l) {
        const int e = g_.owned_edges[l];
        if (!moved(n) && !any_moved(g_.edges[e])) continue;
        if (!g_.is_boundary_edge(e) || g_.edges[e][0] == n || g_.edges[e][1] == n) continue;
        if (!node_box_[n].overlaps(edge_box_[e])) continue;
        out.push_back({PairKind::kVertexEdge, n, e});
      }
    }
  }

  const ContactGeometry& g_;
  const CandidateOptions& options_;
  std::vector<Aabb> node_box_;
  std::vector<Aabb> face_box_, edge_box_;
  std::vector<char> on_boundary_;
};

}  // namespace

std::vector<PrimitivePair> find_candidates(const ContactGeometry& g, BvhCache& cache,
                                           const CandidateOptions& options) {
  const CandidateFinder finder(g, options);
  cache.update(g, finder.face_boxes());

  // Face pairs as global indices, mesh pair by mesh pair.
  std::vector<std::pair<int, int>> face_pairs;
  const int meshes = static_cast<int>(g.meshes.size());
  std::vector<std::vector<char>> moved(meshes);
  std::vector<char> any_moved(meshes, 1);
  if (options.moved) {
    for (int i = 0; i < meshes; ++i) {
      moved[i] = finder.moved_faces(g.meshes[i]);
      any_moved[i] = std::find(moved[i].begin(), moved[i].end(), 1) != moved[i].end();
    }
  }
  auto flags = [&](int i) { return options.moved ? &moved[i] : nullptr; };
  for (int i = 0; i < meshes; ++i) {
    const auto& ri = g.meshes[i];
    if (ri.deformable && any_moved[i])
      for (const auto& p : cache.tree(i).self_overlaps(flags(i)))
        face_pairs.emplace_back(ri.face_begin + p.first, ri.face_begin + p.second);
    for (int j = i + 1; j < meshes; ++j) {
      const auto& rj = g.meshes[j];
      if ((!ri.deformable && !rj.deformable) || (!any_moved[i] && !any_moved[j])) continue;
      for (const auto& p : cache.tree(i).overlaps(cache.tree(j), flags(i), flags(j)))
        face_pairs.emplace_back(ri.face_begin + p.first, rj.face_begin + p.second);
    }
  }

  const int count = static_cast<int>(face_pairs.size());
  std::vector<PrimitivePair> pairs;
#pragma omp parallel if (count > 4096)
  {
    std::vector<PrimitivePair> local;
#pragma omp for schedule(static) nowait
    for (int k = 0; k < count; ++k) finder.face_pair(face_pairs[k].first, face_pairs[k].second, local);
#pragma omp critical(arcsim_collision_candidates)
    pairs.insert(pairs.end(), local.begin(), local.end());
  }
  std::sort(pairs.begin(), pairs.end());
  // Ownership makes each pair appear once; the unique guards against degenerate meshes (a face listing a
  // node twice).
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

}  // namespace arcsim
