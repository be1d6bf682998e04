#include "remesh/remesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_set>
#include <utility>

#include "collision/distance.hpp"
#include "edit/edit_session.hpp"
#include "plasticity/plastic_embedding.hpp"

namespace arcsim {

namespace {

// Flips are refused across folds sharper than this (rad): flipping a bent quad's diagonal changes its shape.
constexpr double kMaxFlipBend = 40.0 * M_PI / 180.0;
// ARCSim refuses a split whose child would be this thin (mean-ratio aspect).
constexpr double kMinSplitAspect = 1e-3;
// A collapse must keep new edges this far below the target length, so that a split does not undo it at once.
constexpr double kCollapseMetricLimit = 0.9;
// Collapses keep surviving faces at least this well shaped when the scene gives no aspect_min (ARCSim requires
// it; without any bound a collapse may leave slivers that a curved rest shape cannot follow).
constexpr double kDefaultAspectMin = 0.1;
// A boundary node counts as lying on the straight line of its neighbours within this fraction of their distance.
constexpr double kStraightBoundary = 1e-6;

bool positive_finite(double x) { return std::isfinite(x) && x > 0; }

int vert_at(const Mesh& m, int f, int n) {
  const int c = m.corner_of_node(f, n);
  return c == kNone ? kNone : m.faces[f].v[c];
}

Vec3 world_cross(const Vec3& a, const Vec3& b, const Vec3& c) { return (b - a).cross(c - a); }

// Rest-side positions of a neighbourhood against which max_surface_change measures the world's change: the
// nodes' rest positions u, or, where the faces (and their flaps) hold plastic state, their local plastic
// embedding (only distances are compared, so its arbitrary placement does not matter).
class RestSidePositions {
 public:
  RestSidePositions(const Mesh& m, const std::vector<Material>* materials, const std::vector<int>& faces)
      : m_(m) {
    if (materials != nullptr && neighbourhood_has_plasticity(m, *materials, faces)) {
      embedding_ = build_plastic_embedding(m, faces);
      plastic_ = true;
    }
  }
  bool plastic() const { return plastic_; }
  // Position of node n, seen from face f (the vert of n in f gives u).
  Vec3 at(int n, int f) const {
    if (plastic_ && embedding_.has(n)) return embedding_.at(n);
    return m_.verts[vert_at(m_, f, n)].u;
  }

 private:
  const Mesh& m_;
  PlasticEmbedding embedding_;
  bool plastic_ = false;
};

}  // namespace

double triangle_aspect(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double area = 0.5 * (b - a).cross(c - a).norm();
  const double perimeter = (b - a).norm() + (c - b).norm() + (a - c).norm();
  if (!(perimeter > 0)) return 0;
  return 12 * std::sqrt(3.0) * area / (perimeter * perimeter);
}

bool should_flip(const Mesh& m, int e, double threshold, double max_surface_change,
                 const std::vector<Material>* materials) {
  const Edge& edge = m.edges[e];
  if (edge.dead || edge.is_boundary() || edge.preserve) return false;
  const int f0 = edge.f[0], f1 = edge.f[1];
  const int i = edge.n[0], j = edge.n[1];
  const int vi = vert_at(m, f0, i), vj = vert_at(m, f0, j);
  if (vi != vert_at(m, f1, i) || vj != vert_at(m, f1, j)) return false;  // seam
  if (m.faces[f0].material != m.faces[f1].material) return false;
  const int k = m.opposite_node(e, f0), l = m.opposite_node(e, f1);
  if (k == l || m.find_edge(k, l) != kNone) return false;
  const int vk = vert_at(m, f0, k), vl = vert_at(m, f1, l);
  if (std::abs(m.world_dihedral(e)) >= kMaxFlipBend) return false;

  // Opposite angles in the mean metric, in the plane of the mean rest normal.
  const Vec3 normal = m.faces[f0].rest_normal + m.faces[f1].rest_normal;
  if (!(normal.norm() > 0)) return false;
  const Vec3 n = normal.normalized();
  Vec3 t1 = n.unitOrthogonal();
  const Vec3 t2 = n.cross(t1);
  Eigen::Matrix<double, 3, 2> B;
  B << t1, t2;
  const Mat3 M3 = 0.25 * (m.verts[vi].sizing + m.verts[vj].sizing + m.verts[vk].sizing + m.verts[vl].sizing);
  const Mat2 M = B.transpose() * M3 * B;
  const double det = M.determinant();
  if (!(det > 0)) return false;
  const double sqrt_det = std::sqrt(det);
  auto p = [&](int v) -> Vec2 { return B.transpose() * m.verts[v].u; };
  const Vec2 ui = p(vi), uj = p(vj), uk = p(vk), ul = p(vl);
  auto cross = [](const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); };
  auto norm = [&](const Vec2& a) { return std::sqrt(std::max(a.dot(M * a), 0.0)); };
  // Angle at k in triangle (i, j, k) and at l in (j, i, l); both triangles are counter-clockwise about n.
  const Vec2 ki = ui - uk, kj = uj - uk, lj = uj - ul, li = ui - ul;
  const double sin_k = sqrt_det * cross(ki, kj), cos_k = ki.dot(M * kj);
  const double sin_l = sqrt_det * cross(lj, li), cos_l = lj.dot(M * li);
  const double scale = norm(ki) * norm(kj) * norm(lj) * norm(li);
  if (!(scale > 0)) return false;
  // sin(alpha_k + alpha_l) < 0: the opposite angles sum to more than pi (both triangles valid in the plane).
  if (!(sin_k > 0 && sin_l > 0)) return false;
  if ((sin_k * cos_l + cos_k * sin_l) / scale >= -threshold) return false;

  // The flipped quad must not fold sharply (rest or world) nor invert in world space. New faces (k, i, l) and
  // (l, j, k): the new edge runs k -> l in the second, with wings j (second face) and i (first face).
  const Vec3 &Ui = m.verts[vi].u, &Uj = m.verts[vj].u, &Uk = m.verts[vk].u, &Ul = m.verts[vl].u;
  if (std::abs(dihedral_angle(Uk, Ul, Uj, Ui)) >= kMaxFlipBend) return false;
  const Vec3 &xi = m.nodes[i].x, &xj = m.nodes[j].x, &xk = m.nodes[k].x, &xl = m.nodes[l].x;
  if (std::abs(dihedral_angle(xk, xl, xj, xi)) >= kMaxFlipBend) return false;
  const Vec3 old_normal = world_cross(xi, xj, xk) + world_cross(xj, xi, xl);
  if (world_cross(xk, xi, xl).dot(old_normal) <= 0 || world_cross(xl, xj, xk).dot(old_normal) <= 0) return false;
  if (max_surface_change > 0) {
    // The flip replaces one diagonal of the quad by the other: the surface moves by their distance. The part
    // of it that the rest shape has too (a curved rest surface) is no elastic change.
    auto gap = [](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
      const Vec3 across = (b - a).cross(d - c);
      return across.norm() > 0 ? std::abs((c - a).dot(across)) / across.norm() : 0.0;
    };
    const RestSidePositions rest(m, materials, {f0, f1});
    const double rest_gap = rest.plastic() ? gap(rest.at(i, f0), rest.at(j, f0), rest.at(k, f0), rest.at(l, f1))
                                           : gap(Ui, Uj, Uk, Ul);
    const double change = std::abs(gap(xi, xj, xk, xl) - rest_gap);
    if (change > max_surface_change * (Uj - Ui).norm()) return false;
  }
  return true;
}

namespace {

// Counts the session's edits and stamps each node with the count at the last edit that touched its neighbourhood:
// the nodes of every face an edit removed or added, and every node sharing a live face with one of them. An
// answer that depends only on a node's faces and their nodes (their positions, rest positions, sizing and
// plastic state, which only the nodes of an edit's faces see change) is still valid while the stamp is not newer
// than the answer. Edits move only nodes of the faces they add (a split's new node, a collapse's kept node).
class NeighbourhoodClock : public EditObserver {
 public:
  explicit NeighbourhoodClock(const Mesh& mesh) : m_(mesh) {}

  void stage_done(EditKind, EditStage stage, const EditResult& result) override {
    if (stage != EditStage::kDone || !result.ok) return;
    ++edits_;
    if (stamp_.size() < m_.nodes.size()) stamp_.resize(m_.nodes.size(), 0);
    touched_.clear();
    for (const std::vector<int>* faces : {&result.removed_faces, &result.added_faces})
      for (int f : *faces)
        for (int i = 0; i < 3; ++i) touched_.push_back(m_.face_node(f, i));
    for (int n : touched_) {
      stamp_[n] = edits_;
      if (m_.nodes[n].dead) continue;
      for (int f : m_.node_faces(n))
        for (int i = 0; i < 3; ++i) stamp_[m_.face_node(f, i)] = edits_;
    }
  }

  long edits() const { return edits_; }
  // The count at the last edit around node n (0: none since the clock started).
  long stamp(int n) const { return n < static_cast<int>(stamp_.size()) ? stamp_[n] : 0; }

 private:
  const Mesh& m_;
  long edits_ = 0;
  std::vector<long> stamp_;
  std::vector<int> touched_;
};

// The remesher is a client of the edit session (edit/edit_session.hpp): it sizes the mesh and chooses which
// edge to split, flip or collapse, and in which order; everything an edit needs beyond that (rest positions and
// angles, plastic transfer, reprojection, the world guard, the subset's bookkeeping) is the session's.
class Remesher {
 public:
  Remesher(Mesh& mesh, const std::vector<Material>& materials, const RemeshOptions& options,
           const std::vector<int>* subset)
      : m_(mesh), materials_(materials), o_(options), subset_(subset),
        clock_(mesh), session_(mesh, materials, edit_session_options(options), subset) {
    for (EditObserver* observer : o_.observers) session_.add_observer(observer);
    session_.add_observer(&clock_);
    const RemeshingParams& r = o_.sizing.remeshing;
    aspect_min_ = positive_finite(r.aspect_min) ? std::min(r.aspect_min, 1.0) : kDefaultAspectMin;
    min_area_ = positive_finite(r.size_min) ? 0.1 * r.size_min * r.size_min : 0.0;
  }

  RemeshStats run() {
    // A subset's edits read only the sizing of its faces' verts (splits of its edges, flips and collapses inside
    // it, and the verts new edits make interpolate it).
    if (subset_ != nullptr)
      compute_vertex_sizing(m_, o_.sizing, o_.extras, *subset_);
    else
      compute_vertex_sizing(m_, o_.sizing, o_.extras);
    flip_edges(active_edges());
    split_rounds();
    collapse_rounds();
    RemeshStats stats;
    static_cast<EditCounts&>(stats) = session_.counts();
    stats.active_faces = session_.zone_faces();
    return stats;
  }

 private:

  bool is_active(int f) const { return session_.in_zone(f); }

  // An edge may be split when one of its faces is active (a border edge of a subset too, so that the refined
  // region stays conforming), but flipped only when all its faces are: flips and collapses stay inside the
  // subset, and only the children of active faces become active, so the region cannot creep outwards.
  bool is_active_edge(int e) const {
    const Edge& edge = m_.edges[e];
    if (edge.dead) return false;
    for (int s = 0; s < 2; ++s)
      if (edge.f[s] != kNone && is_active(edge.f[s])) return true;
    return false;
  }

  bool is_inner_edge(int e) const {
    const Edge& edge = m_.edges[e];
    if (edge.dead) return false;
    for (int s = 0; s < 2; ++s)
      if (edge.f[s] != kNone && !is_active(edge.f[s])) return false;
    return true;
  }

  std::vector<int> active_edges() const {
    std::vector<int> edges;
    for (size_t e = 0; e < m_.edges.size(); ++e)
      if (is_active_edge(static_cast<int>(e))) edges.push_back(static_cast<int>(e));
    return edges;
  }

  // --- flips ------------------------------------------------------------------------------------------------

  // Flips on independent sets: within a pass no two flipped edges share a face (an edge whose face was
  // already changed waits for the next pass), and the edges of flipped faces are examined again next pass.
  void flip_edges(std::vector<int> queue) {
    const size_t budget = 3 * queue.size() + 16;
    size_t done = 0;
    for (int pass = 0; pass < 50 && !queue.empty() && done < budget; ++pass) {
      std::unordered_set<int> used;
      std::vector<int> next;
      for (int e : queue) {
        if (done >= budget) break;
        if (!is_inner_edge(e) || m_.edges[e].is_boundary()) continue;
        const int f0 = m_.edges[e].f[0], f1 = m_.edges[e].f[1];
        if (used.count(f0) || used.count(f1)) {
          next.push_back(e);
          continue;
        }
        if (!should_flip(m_, e, o_.edge_flip_threshold, o_.max_surface_change, &materials_)) continue;
        const EditResult r = session_.flip_edge(e);
        if (!r.ok) continue;
        ++done;
        used.insert(r.added_faces.begin(), r.added_faces.end());
        for (int ne : edges_of_faces(m_, r.added_faces)) next.push_back(ne);
      }
      std::sort(next.begin(), next.end());
      next.erase(std::unique(next.begin(), next.end()), next.end());
      queue = std::move(next);
    }
  }

  void flip_around(int node) { flip_edges(edges_of_faces(m_, m_.node_faces(node))); }

  // --- splits -----------------------------------------------------------------------------------------------

  bool split_children_ok(int e) const {
    const Edge& edge = m_.edges[e];
    for (int s = 0; s < 2; ++s) {
      const int f = edge.f[s];
      if (f == kNone) continue;
      const int a = vert_at(m_, f, edge.n[0]), b = vert_at(m_, f, edge.n[1]);
      const int c = vert_at(m_, f, m_.opposite_node(e, f));
      const Vec3 mid = 0.5 * (m_.verts[a].u + m_.verts[b].u);
      const Vec3& uc = m_.verts[c].u;
      if (triangle_aspect(m_.verts[a].u, mid, uc) < kMinSplitAspect ||
          triangle_aspect(mid, m_.verts[b].u, uc) < kMinSplitAspect)
        return false;
    }
    return true;
  }

  bool split(int e) {
    if (!split_children_ok(e)) return false;
    const EditResult r = session_.split_edge(e, 0.5);
    if (!r.ok) return false;
    flip_around(r.added_nodes[0]);
    return true;
  }

  void split_rounds() {
    for (int round = 0; round < o_.max_rounds; ++round) {
      std::vector<std::pair<double, int>> long_edges;
      for (int e : active_edges()) {
        const double l = edge_metric_length(m_, e);
        if (l > 1) long_edges.emplace_back(l, e);
      }
      if (long_edges.empty()) return;
      std::sort(long_edges.begin(), long_edges.end(),
                [](const auto& a, const auto& b) {
                  return a.first > b.first || (a.first == b.first && a.second < b.second);
                });
      int count = 0;
      for (const auto& [length, e] : long_edges) {
        if (session_.live_faces() >= static_cast<long>(o_.max_faces)) return;
        if (!m_.edges[e].dead && split(e)) ++count;
      }
      if (count == 0) return;
    }
  }

  // --- collapses --------------------------------------------------------------------------------------------

  // ARCSim's collapse rules (facts §5.3) on the faces that survive around the removed node, checked before the
  // edit: mean-ratio aspect at least aspect_min (or, for a face already below it, no worse than before), rest
  // area at least 0.1 size_min^2 (or no smaller than before), rest normal not reversed, world normal not
  // reversed, every new edge's metric length <= 0.9; and the world surface change limit (max_surface_change).
  // The removed node must be unpreserved, unlabelled, inside the subset and, on the boundary, on a straight
  // piece of it (boundary_node_on_chord). Topology (boundary, preserved edges, link condition, seams) is checked
  // by collapse_edge itself.
  bool can_collapse(int e, int remove_side) const {
    const Edge& edge = m_.edges[e];
    const int gone = edge.n[remove_side], keep = edge.n[1 - remove_side];
    const Node& g = m_.nodes[gone];
    if (g.preserve || g.label != 0) return false;
    const std::vector<int> fan = m_.node_faces(gone);
    for (int f : fan)
      if (!is_active(f)) return false;
    // The removed node's vert in each face of the edge, and the kept node's vert that replaces it.
    std::array<std::pair<int, int>, 2> vert_map{{{kNone, kNone}, {kNone, kNone}}};
    for (int s = 0; s < 2; ++s)
      if (edge.f[s] != kNone) vert_map[s] = {vert_at(m_, edge.f[s], gone), vert_at(m_, edge.f[s], keep)};
    const auto replacement = [&](int vert) {  // the second face's pair first, as a map written in order
      for (int s = 1; s >= 0; --s)
        if (vert_map[s].first == vert && vert != kNone) return vert_map[s].second;
      return kNone;
    };
    // The new edges' metric lengths first: in a mesh that meets its sizing nearly every edge is shorter than 1
    // and so a candidate, and this is the test that turns most of them down (the checks are independent, so
    // their order does not change the answer).
    for (int f : fan) {
      if (f == edge.f[0] || f == edge.f[1]) continue;
      const Face& face = m_.faces[f];
      const int c = m_.corner_of_node(f, gone);
      const int kept_vert = replacement(face.v[c]);
      if (kept_vert == kNone) return false;
      for (int k = 1; k <= 2; ++k)
        if (vert_pair_metric_length(m_, kept_vert, face.v[(c + k) % 3]) > kCollapseMetricLimit) return false;
    }
    if (m_.is_boundary_node(gone) && !boundary_node_on_chord(gone)) return false;
    const Vec3& x_keep = m_.nodes[keep].x;
    double gone_to_surface = kInfinity, gone_to_rest_surface = kInfinity;  // m
    const RestSidePositions rest(m_, o_.max_surface_change > 0 ? &materials_ : nullptr, fan);
    for (int f : fan) {
      if (f == edge.f[0] || f == edge.f[1]) continue;
      const Face& face = m_.faces[f];
      const int c = m_.corner_of_node(f, gone);
      std::array<int, 3> nv = face.v;
      nv[c] = replacement(face.v[c]);
      const Vec3 &u0 = m_.verts[nv[0]].u, &u1 = m_.verts[nv[1]].u, &u2 = m_.verts[nv[2]].u;
      const Vec3 &o0 = m_.verts[face.v[0]].u, &o1 = m_.verts[face.v[1]].u, &o2 = m_.verts[face.v[2]].u;
      const double aspect = triangle_aspect(u0, u1, u2), old_aspect = triangle_aspect(o0, o1, o2);
      if (aspect < std::min(aspect_min_, old_aspect) || aspect < std::min(kMinSplitAspect, old_aspect)) return false;
      const Vec3 n = (u1 - u0).cross(u2 - u0), old_n = (o1 - o0).cross(o2 - o0);
      if (0.5 * n.norm() < std::min(min_area_, 0.5 * old_n.norm())) return false;
      if (n.dot(old_n) <= 0) return false;
      std::array<Vec3, 3> x, old_x;
      for (int i = 0; i < 3; ++i) old_x[i] = x[i] = m_.nodes[m_.face_node(f, i)].x;
      x[c] = x_keep;
      const Vec3 wn = world_cross(x[0], x[1], x[2]), old_wn = world_cross(old_x[0], old_x[1], old_x[2]);
      if (wn.dot(old_wn) <= 0 && old_wn.norm() > 0) return false;
      gone_to_surface = std::min(gone_to_surface, vertex_face_closest(g.x, x[0], x[1], x[2]).distance);
      if (rest.plastic()) {
        // The same face in the plastic shape: its corners' embedded positions, the removed one replaced by keep.
        std::array<Vec3, 3> y;
        for (int i = 0; i < 3; ++i) y[i] = rest.at(i == c ? keep : m_.face_node(f, i), f);
        gone_to_rest_surface =
            std::min(gone_to_rest_surface, vertex_face_closest(rest.at(gone, f), y[0], y[1], y[2]).distance);
      } else {
        gone_to_rest_surface =
            std::min(gone_to_rest_surface, vertex_face_closest(m_.verts[face.v[c]].u, u0, u1, u2).distance);
      }
    }
    // The removed node's distance to the faces that replace its fan bounds how far the surface moves; the part
    // the rest shape has too (a curved rest surface being coarsened) is no elastic change.
    if (o_.max_surface_change > 0 && std::isfinite(gone_to_surface) && std::isfinite(gone_to_rest_surface)) {
      const int f = edge.f[0] != kNone ? edge.f[0] : edge.f[1];
      const double rest_length = (m_.verts[vert_at(m_, f, gone)].u - m_.verts[vert_at(m_, f, keep)].u).norm();
      if (std::abs(gone_to_surface - gone_to_rest_surface) > o_.max_surface_change * rest_length) return false;
    }
    return true;
  }

  // A boundary node may go only where the boundary runs straight through it in rest space (it was made by a
  // split of a boundary edge): removing a corner would change the sheet's outline or a crack's path.
  bool boundary_node_on_chord(int node) const {
    std::vector<Vec3> ends;
    Vec3 here = Vec3::Zero();
    for (int e : m_.nodes[node].edges) {
      const Edge& edge = m_.edges[e];
      if (!edge.is_boundary()) continue;
      const int f = edge.f[0] != kNone ? edge.f[0] : edge.f[1];
      const int other = edge.n[0] == node ? edge.n[1] : edge.n[0];
      here = m_.verts[vert_at(m_, f, node)].u;
      ends.push_back(m_.verts[vert_at(m_, f, other)].u);
    }
    if (ends.size() != 2) return false;
    const Vec3 chord = ends[1] - ends[0];
    const double length = chord.norm();
    if (!(length > 0)) return false;
    const double off_line = chord.cross(here - ends[0]).norm() / length;
    return off_line <= kStraightBoundary * length;
  }

  bool collapse(int e) {
    // can_collapse reads only the faces around the edge's two nodes: an edge it turned down on both sides stays
    // turned down until an edit touches one of those neighbourhoods. (Most edges are shorter than 1 and asked
    // again in every round, and a round after the first makes a few dozen edits among ~20 000 such edges.)
    const Edge& edge = m_.edges[e];
    if (o_.remember_refused_collapses && static_cast<size_t>(e) < refused_at_.size() && refused_at_[e] >= 0 &&
        clock_.stamp(edge.n[0]) <= refused_at_[e] && clock_.stamp(edge.n[1]) <= refused_at_[e])
      return false;
    bool ruled_out = true;
    for (int side = 0; side < 2; ++side) {
      if (!can_collapse(e, side)) continue;
      ruled_out = false;
      const int keep = m_.edges[e].n[1 - side];
      if (!session_.collapse_edge(e, side).ok) continue;
      flip_around(keep);
      return true;
    }
    if (refused_at_.size() < m_.edges.size()) refused_at_.resize(m_.edges.size(), -1);
    refused_at_[e] = ruled_out ? clock_.edits() : -1;
    return false;
  }

  void collapse_rounds() {
    for (int round = 0; round < o_.max_rounds; ++round) {
      std::vector<std::pair<double, int>> short_edges;
      for (int e : active_edges()) {
        const double l = edge_metric_length(m_, e);
        if (l < 1) short_edges.emplace_back(l, e);
      }
      std::sort(short_edges.begin(), short_edges.end());
      int count = 0;
      for (const auto& [length, e] : short_edges)
        if (!m_.edges[e].dead && collapse(e)) ++count;
      if (count == 0) return;
    }
  }

  Mesh& m_;
  const std::vector<Material>& materials_;
  const RemeshOptions& o_;
  const std::vector<int>* subset_;
  NeighbourhoodClock clock_;  // before the session, which holds a pointer to it
  EditSession session_;
  // Per edge: the clock's count when can_collapse last turned down both of its sides (-1: not since).
  std::vector<long> refused_at_;
  double aspect_min_ = 0, min_area_ = 0;
};

}  // namespace

EditSessionOptions edit_session_options(const RemeshOptions& o) {
  EditSessionOptions s;
  s.reference = o.reference;
  s.plastic_embedding = o.sizing.remeshing.plastic_embedding;
  s.reproject = o.reproject;
  s.reprojection = o.reprojection;
  s.world_clearance = o.world_clearance;
  s.obstacles = o.obstacles;
  s.shared_guard = o.shared_guard;
  return s;
}

RemeshStats remesh_mesh(Mesh& mesh, const std::vector<Material>& materials, const RemeshOptions& options,
                        const std::vector<int>* face_subset) {
  return Remesher(mesh, materials, options, face_subset).run();
}

}  // namespace arcsim
