#include "collision/candidates.hpp"

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <type_traits>

#include "math/counting_sort.hpp"

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

// A candidate list's slack, as a fraction of the mean edge length (list_slack).
constexpr double kListSlackFraction = 0.2;
// Lists longer than this are filtered in parallel.
constexpr int kParallelFilterPairs = 1 << 16;
// A list that served fewer searches than this did not pay for itself; searches then go without one for
// backoff searches (doubling after each such list, up to kMaxListBackoff).
constexpr int kMinListServes = 2;
constexpr int kMaxListBackoff = 16;

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

  const std::vector<Aabb>& node_boxes() const { return node_box_; }

  // The candidates of the face pair (fa, fb), fa != fb, that pass the tests of topology alone: vertices of one
  // against the other face, edges against edges, boundary vertices against boundary edges (with
  // options.vertex_edge, between deformable meshes), never two primitives that share a node.
  void static_pairs(int fa, int fb, std::vector<PrimitivePair>& out) const {
    vertices_against_face(fa, fb, out);
    vertices_against_face(fb, fa, out);
    for (int k = g_.owned_edge_begin[fa]; k < g_.owned_edge_begin[fa + 1]; ++k) {
      const int ea = g_.owned_edges[k];
      for (int l = g_.owned_edge_begin[fb]; l < g_.owned_edge_begin[fb + 1]; ++l) {
        const int eb = g_.owned_edges[l];
        if (!share_node(g_.edges[ea], g_.edges[eb]))
          out.push_back({PairKind::kEdgeEdge, std::min(ea, eb), std::max(ea, eb)});
      }
    }
    if (options_.vertex_edge && g_.meshes[mesh_of_face(fa)].deformable && g_.meshes[mesh_of_face(fb)].deformable) {
      boundary_vertices_against_edges(fa, fb, out);
      boundary_vertices_against_edges(fb, fa, out);
    }
  }

  // A candidate of static_pairs is found if one of its nodes moved (options.moved) and its primitives' boxes
  // overlap.
  bool passes(const PrimitivePair& p) const {
    switch (p.kind) {
      case PairKind::kVertexFace:
        return passes_vertex_face<true>(p);
      case PairKind::kEdgeEdge:
        return passes_edge_edge<true>(p);
      case PairKind::kVertexEdge:
        break;
    }
    return passes_vertex_edge<true>(p);
  }
  // passes() for one kind of pair; without `check_moved` the moved flags are not consulted.
  template <bool check_moved>
  bool passes_vertex_face(const PrimitivePair& p) const {
    return (!check_moved || moved(p.a) || any_moved(g_.faces[p.b])) && node_box_[p.a].overlaps(face_box_[p.b]);
  }
  template <bool check_moved>
  bool passes_edge_edge(const PrimitivePair& p) const {
    return (!check_moved || any_moved(g_.edges[p.a]) || any_moved(g_.edges[p.b])) &&
           edge_box_[p.a].overlaps(edge_box_[p.b]);
  }
  template <bool check_moved>
  bool passes_vertex_edge(const PrimitivePair& p) const {
    return (!check_moved || moved(p.a) || any_moved(g_.edges[p.b])) && node_box_[p.a].overlaps(edge_box_[p.b]);
  }
  bool checks_moved() const { return options_.moved != nullptr; }
  // Bounds the first index of every pair: a node or an edge.
  int index_bound() const { return std::max(g_.node_count(), static_cast<int>(g_.edges.size())); }

 private:
  int mesh_of_face(int f) const { return g_.node_mesh[g_.faces[f][0]]; }

  bool moved(int n) const { return !options_.moved || (*options_.moved)[n]; }
  bool any_moved(const std::array<int, 2>& e) const { return moved(e[0]) || moved(e[1]); }
  bool any_moved(const std::array<int, 3>& f) const { return moved(f[0]) || moved(f[1]) || moved(f[2]); }

  void vertices_against_face(int owner, int face, std::vector<PrimitivePair>& out) const {
    for (int k = g_.owned_node_begin[owner]; k < g_.owned_node_begin[owner + 1]; ++k) {
      const int n = g_.owned_nodes[k];
      if (!contains(g_.faces[face], n)) out.push_back({PairKind::kVertexFace, n, face});
    }
  }

  void boundary_vertices_against_edges(int owner, int face, std::vector<PrimitivePair>& out) const {
    for (int k = g_.owned_node_begin[owner]; k < g_.owned_node_begin[owner + 1]; ++k) {
      const int n = g_.owned_nodes[k];
      if (!on_boundary_[n]) continue;
      for (int l = g_.owned_edge_begin[face]; l < g_.owned_edge_begin[face + 1]; ++l) {
        const int e = g_.owned_edges[l];
        if (g_.is_boundary_edge(e) && g_.edges[e][0] != n && g_.edges[e][1] != n)
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

// The face pairs whose boxes (as the trees hold them) overlap, as global indices, mesh pair by mesh pair;
// with options.moved only pairs with a moved face.
std::vector<std::pair<int, int>> overlapping_faces(const ContactGeometry& g, const BvhCache& cache,
                                                   const CandidateFinder& finder, const std::vector<char>* moved_nodes) {
  std::vector<std::pair<int, int>> face_pairs;
  const int meshes = static_cast<int>(g.meshes.size());
  std::vector<std::vector<char>> moved(meshes);
  std::vector<char> any_moved(meshes, 1);
  if (moved_nodes) {
    for (int i = 0; i < meshes; ++i) {
      moved[i] = finder.moved_faces(g.meshes[i]);
      any_moved[i] = std::find(moved[i].begin(), moved[i].end(), 1) != moved[i].end();
    }
  }
  auto flags = [&](int i) { return moved_nodes ? &moved[i] : nullptr; };
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
  return face_pairs;
}

// Sorts pairs[first, end) as std::sort does (by kind, a, b) and drops duplicates, by counting on (kind, a), every
// a in [0, a_count): a proximity search sorts ~10^5-10^6 pairs, and std::sort took 4% of flag.json's wall.
void sort_unique(std::vector<PrimitivePair>& pairs, size_t first, int a_count) {
  const size_t a_keys = static_cast<size_t>(std::max(a_count, 0));
  counting_sort_unique(
      pairs, first, 3 * a_keys,
      [&](const PrimitivePair& p) {
        // An a out of range has no key (-1): the whole range then goes to std::sort.
        if (p.a < 0 || static_cast<size_t>(p.a) >= a_keys) return -1L;
        return static_cast<long>(p.kind) * static_cast<long>(a_keys) + p.a;
      },
      4096);
}

// The static candidates of the face pairs (passing `passes` when given), sorted and unique. Ownership makes
// each pair appear once; the unique guards against degenerate meshes (a face listing a node twice).
template <typename Keep>
std::vector<PrimitivePair> expand_face_pairs(const CandidateFinder& finder,
                                             const std::vector<std::pair<int, int>>& face_pairs, Keep keep) {
  const int count = static_cast<int>(face_pairs.size());
  std::vector<PrimitivePair> pairs;
#pragma omp parallel if (count > 4096)
  {
    std::vector<PrimitivePair> local, scratch;
#pragma omp for schedule(static) nowait
    for (int k = 0; k < count; ++k) {
      scratch.clear();
      finder.static_pairs(face_pairs[k].first, face_pairs[k].second, scratch);
      for (const PrimitivePair& p : scratch)
        if (keep(p)) local.push_back(p);
    }
#pragma omp critical(arcsim_collision_candidates)
    pairs.insert(pairs.end(), local.begin(), local.end());
  }
  sort_unique(pairs, 0, finder.index_bound());
  return pairs;
}

// Equal contents of two vectors of plain integers (one comparison of their bytes).
template <typename T>
bool same_values(const std::vector<T>& a, const std::vector<T>& b) {
  static_assert(std::is_trivially_copyable_v<T>, "compared as bytes");
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool same_range(const ContactGeometry::Range& a, const ContactGeometry::Range& b) {
  return a.node_begin == b.node_begin && a.node_end == b.node_end && a.edge_begin == b.edge_begin &&
         a.edge_end == b.edge_end && a.face_begin == b.face_begin && a.face_end == b.face_end &&
         a.deformable == b.deformable && a.topology == b.topology;
}

bool inside(const Aabb& box, const Aabb& bound) {
  return (box.lo.array() >= bound.lo.array()).all() && (box.hi.array() <= bound.hi.array()).all();
}

// The list was made for this connectivity and these options, and every node's box is inside its grown box.
bool list_fits(const CandidateList& list, const ContactGeometry& g, const CandidateOptions& options,
               const std::vector<Aabb>& node_boxes) {
  if (!list.ready || list.margin != options.margin || list.vertex_edge != options.vertex_edge ||
      list.grown.size() != node_boxes.size() || !list.connectivity.matches(g))
    return false;
  for (size_t n = 0; n < node_boxes.size(); ++n)
    if (!inside(node_boxes[n], list.grown[n])) return false;
  return true;
}

// The slack (m) each node's box grows by for a new list: a fifth of the mean edge length. Any slack gives the
// same candidates; a larger one lists more pairs that fail their box test, a smaller one lasts fewer steps.
double list_slack(const ContactGeometry& g) {
  double length = 0;
  int count = 0;
  for (const auto& e : g.edges)
    if (e[0] != kNone) {
      length += (g.x0[e[1]] - g.x0[e[0]]).norm();
      ++count;
    }
  return count > 0 ? kListSlackFraction * length / count : 0.0;
}

int kind_index(PairKind kind) { return static_cast<int>(kind); }

void make_list(const ContactGeometry& g, BvhCache& cache, const CandidateOptions& options,
               const CandidateFinder& finder, CandidateList& list) {
  cache.count_list_build();
  const double slack = list_slack(g);
  list.grown = finder.node_boxes();
  for (Aabb& b : list.grown) b.inflate(slack);
  std::vector<Aabb> face_boxes(g.faces.size());
  for (size_t f = 0; f < g.faces.size(); ++f)
    if (g.faces[f][0] != kNone)
      for (int n : g.faces[f]) face_boxes[f].extend(list.grown[n]);
  cache.update(g, face_boxes);
  const std::vector<std::pair<int, int>> face_pairs = overlapping_faces(g, cache, finder, nullptr);
  const int count = static_cast<int>(face_pairs.size());
  for (auto& pairs : list.by_kind) pairs.clear();
  // In no particular order (threads append as they finish): searches sort what passes.
#pragma omp parallel if (count > 4096)
  {
    std::array<std::vector<PrimitivePair>, 3> local;
    std::vector<PrimitivePair> scratch;
#pragma omp for schedule(static) nowait
    for (int k = 0; k < count; ++k) {
      scratch.clear();
      finder.static_pairs(face_pairs[k].first, face_pairs[k].second, scratch);
      for (const PrimitivePair& p : scratch) local[kind_index(p.kind)].push_back(p);
    }
#pragma omp critical(arcsim_collision_candidates)
    for (int kind = 0; kind < 3; ++kind)
      list.by_kind[kind].insert(list.by_kind[kind].end(), local[kind].begin(), local[kind].end());
  }
  list.connectivity.capture(g);
  list.margin = options.margin;
  list.vertex_edge = options.vertex_edge;
  list.ready = true;
  list.served = 0;
}

// Appends the pairs of list[begin, end), all of kind `kind`, that pass the search's tests.
template <PairKind kind, bool check_moved>
void filter_range(const CandidateFinder& finder, const std::vector<PrimitivePair>& list, int begin, int end,
                  std::vector<PrimitivePair>& out) {
  for (int k = begin; k < end; ++k) {
    const PrimitivePair& p = list[k];
    bool pass;
    if constexpr (kind == PairKind::kVertexFace)
      pass = finder.passes_vertex_face<check_moved>(p);
    else if constexpr (kind == PairKind::kEdgeEdge)
      pass = finder.passes_edge_edge<check_moved>(p);
    else
      pass = finder.passes_vertex_edge<check_moved>(p);
    if (pass) out.push_back(p);
  }
}

template <PairKind kind>
void filter_chunk(const CandidateFinder& finder, const std::vector<PrimitivePair>& list, int begin, int end,
                  std::vector<PrimitivePair>& out) {
  if (finder.checks_moved())
    filter_range<kind, true>(finder, list, begin, end, out);
  else
    filter_range<kind, false>(finder, list, begin, end, out);
}

// Appends the pairs of `list`, all of kind `kind`, that pass the search's tests, sorted and unique.
template <PairKind kind>
void filter_kind(const CandidateFinder& finder, const std::vector<PrimitivePair>& list,
                 std::vector<PrimitivePair>& out) {
  const int count = static_cast<int>(list.size());
  const size_t first = out.size();
  if (count <= kParallelFilterPairs) {
    filter_chunk<kind>(finder, list, 0, count, out);
  } else {
    const int chunks = 64;
    std::vector<std::vector<PrimitivePair>> found(chunks);
#pragma omp parallel for schedule(dynamic, 1)
    for (int c = 0; c < chunks; ++c) {
      const int begin = static_cast<int>(static_cast<long long>(count) * c / chunks);
      const int end = static_cast<int>(static_cast<long long>(count) * (c + 1) / chunks);
      filter_chunk<kind>(finder, list, begin, end, found[c]);
    }
    for (const auto& f : found) out.insert(out.end(), f.begin(), f.end());
  }
  // Ownership makes each pair appear once; the unique guards against degenerate meshes (a face listing a node
  // twice).
  sort_unique(out, first, finder.index_bound());
}

// The list's pairs that pass the search's tests, sorted: kinds in PairKind's order, each kind sorted.
std::vector<PrimitivePair> filter_list(const CandidateFinder& finder, const CandidateList& list) {
  std::vector<PrimitivePair> pairs;
  filter_kind<PairKind::kVertexFace>(finder, list.by_kind[kind_index(PairKind::kVertexFace)], pairs);
  filter_kind<PairKind::kEdgeEdge>(finder, list.by_kind[kind_index(PairKind::kEdgeEdge)], pairs);
  filter_kind<PairKind::kVertexEdge>(finder, list.by_kind[kind_index(PairKind::kVertexEdge)], pairs);
  return pairs;
}

// Without a list: the face pairs of the current boxes (pruned by the moved flags), their candidates tested.
std::vector<PrimitivePair> search_directly(const ContactGeometry& g, BvhCache& cache, const CandidateOptions& options,
                                           const CandidateFinder& finder) {
  cache.update(g, finder.face_boxes());
  return expand_face_pairs(finder, overlapping_faces(g, cache, finder, options.moved),
                           [&](const PrimitivePair& p) { return finder.passes(p); });
}

}  // namespace

void CandidateConnectivity::capture(const ContactGeometry& g) {
  meshes = g.meshes;
  faces = g.faces;
  edges = g.edges;
  edge_faces = g.edge_faces;
  owned_node_begin = g.owned_node_begin;
  owned_nodes = g.owned_nodes;
  owned_edge_begin = g.owned_edge_begin;
  owned_edges = g.owned_edges;
}

bool CandidateConnectivity::matches(const ContactGeometry& g) const {
  if (meshes.size() != g.meshes.size()) return false;
  for (size_t m = 0; m < g.meshes.size(); ++m)
    if (!same_range(meshes[m], g.meshes[m])) return false;
  return same_values(faces, g.faces) && same_values(edges, g.edges) && same_values(edge_faces, g.edge_faces) &&
         same_values(owned_node_begin, g.owned_node_begin) && same_values(owned_nodes, g.owned_nodes) &&
         same_values(owned_edge_begin, g.owned_edge_begin) && same_values(owned_edges, g.owned_edges);
}

std::vector<PrimitivePair> find_candidates(const ContactGeometry& g, BvhCache& cache,
                                           const CandidateOptions& options) {
  const CandidateFinder finder(g, options);
  CandidateList& list = cache.list(options.swept);
  if (list_fits(list, g, options, finder.node_boxes())) {
    ++list.served;
    return filter_list(finder, list);
  }
  // A re-search after impact zones moved some nodes is pruned by the moved flags; a list made for it would
  // list every pair, moved or not. It leaves the list for the next full search.
  if (options.moved) return search_directly(g, cache, options, finder);
  // A list costs about a search and a half to make: when the last one served fewer than two searches (the
  // nodes move by more than the slack per step), search without one for a while, longer after each failure.
  if (list.ready && list.served < kMinListServes) {
    list.ready = false;
    list.backoff = std::min(2 * list.backoff, kMaxListBackoff);
    list.skip = list.backoff;
  } else if (list.ready) {
    list.backoff = 1;
  }
  if (list.skip > 0) {
    --list.skip;
    return search_directly(g, cache, options, finder);
  }
  make_list(g, cache, options, finder, list);
  ++list.served;
  return filter_list(finder, list);
}

}  // namespace arcsim
