#include "remesh/world_guard.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "collision/distance.hpp"
#include "collision/triangle_intersection.hpp"

namespace arcsim {

namespace {

// A face whose box spans more cells than this is checked against every query instead (large obstacle
// triangles such as a floor).
constexpr long kMaxCellsPerFace = 512;

// Cell coordinates are offset into 21 bits each.
constexpr int kCoordinateBits = 21;
constexpr int kCoordinateOffset = 1 << (kCoordinateBits - 1);

Eigen::AlignedBox3d box_of(const std::array<Vec3, 3>& x, double margin) {
  Eigen::AlignedBox3d b;
  for (const Vec3& p : x) b.extend(p);
  b.min().array() -= margin;
  b.max().array() += margin;
  return b;
}

double median_edge_length(const Mesh& m) {
  std::vector<double> lengths;
  for (const Edge& e : m.edges)
    if (!e.dead) lengths.push_back((m.nodes[e.n[1]].x - m.nodes[e.n[0]].x).norm());
  if (lengths.empty()) return 0;
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  return lengths[lengths.size() / 2];
}

// Signed volume (times 6) of tetrahedron (a, b, c, d).
double volume6(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) { return (b - a).dot((c - a).cross(d - a)); }

// True if the triangle meets the solid tetrahedron: an edge of one crosses a face of the other, or the triangle
// lies inside (its corners are).
bool triangle_meets_tetrahedron(const std::array<Vec3, 3>& t, const std::array<Vec3, 4>& q) {
  static constexpr int kFaces[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
  for (const auto& f : kFaces)
    if (triangles_cross(t, {q[f[0]], q[f[1]], q[f[2]]})) return true;
  const double v = volume6(q[0], q[1], q[2], q[3]);
  if (v == 0) return false;
  for (const Vec3& p : t) {
    const double s0 = volume6(p, q[1], q[2], q[3]), s1 = volume6(q[0], p, q[2], q[3]);
    const double s2 = volume6(q[0], q[1], p, q[3]), s3 = volume6(q[0], q[1], q[2], p);
    if (s0 * v >= 0 && s1 * v >= 0 && s2 * v >= 0 && s3 * v >= 0) return true;
  }
  return false;
}

// A ball holding the points (centre: their mean): the distance between two point sets is at least the
// distance between their balls, a cheap test before the exact ones.
template <size_t N>
std::pair<Vec3, double> enclosing_ball(const std::array<Vec3, N>& x) {
  Vec3 centre = Vec3::Zero();
  for (const Vec3& p : x) centre += p / static_cast<double>(N);
  double radius = 0;
  for (const Vec3& p : x) radius = std::max(radius, (p - centre).norm());
  return {centre, radius};
}

template <size_t N, size_t M>
double ball_gap(const std::array<Vec3, N>& a, const std::array<Vec3, M>& b) {
  const auto [ca, ra] = enclosing_ball(a);
  const auto [cb, rb] = enclosing_ball(b);
  return (ca - cb).norm() - ra - rb;
}

}  // namespace

WorldGuard::WorldGuard(const Mesh& mesh, const std::vector<const Mesh*>& others, double clearance)
    : mesh_(mesh), clearance_(clearance) {
  meshes_.push_back(&mesh);
  meshes_.insert(meshes_.end(), others.begin(), others.end());
  seen_.resize(meshes_.size());
  build();
}

void WorldGuard::build() {
  cells_.clear();
  large_.clear();
  // Cells about an edge long: a query touches a few cells and each holds a few faces.
  cell_ = std::max({median_edge_length(mesh_), 4 * clearance_, 1e-6});
  built_faces_ = added_faces_ = 0;
  for (size_t k = 0; k < meshes_.size(); ++k)
    for (size_t f = 0; f < meshes_[k]->faces.size(); ++f)
      if (!meshes_[k]->faces[f].dead) {
        insert(static_cast<int>(k), static_cast<int>(f));
        ++built_faces_;
      }
}

WorldGuard::Key WorldGuard::key(int i, int j, int k) const {
  auto part = [](int c) {
    return static_cast<Key>(std::clamp(c + kCoordinateOffset, 0, (1 << kCoordinateBits) - 1));
  };
  return part(i) << (2 * kCoordinateBits) | part(j) << kCoordinateBits | part(k);
}

std::array<int, 3> WorldGuard::cell_of(const Vec3& p) const {
  std::array<int, 3> c;
  for (int d = 0; d < 3; ++d)
    c[d] = static_cast<int>(std::clamp(std::floor(p[d] / cell_), -1e9, 1e9));
  return c;
}

GuardTriangle WorldGuard::triangle(int mesh, int face) const {
  const Mesh& m = *meshes_[mesh];
  GuardTriangle t;
  for (int i = 0; i < 3; ++i) {
    const int n = m.face_node(face, i);
    t.x[i] = m.nodes[n].x;
    t.nodes[i] = mesh == 0 ? n : kNone;
  }
  return t;
}

void WorldGuard::insert(int mesh, int face) {
  const GuardTriangle t = triangle(mesh, face);
  const Eigen::AlignedBox3d b = box_of(t.x, 0);
  if (!b.min().allFinite() || !b.max().allFinite()) return;
  const std::array<int, 3> lo = cell_of(b.min()), hi = cell_of(b.max());
  long cells = 1;
  for (int d = 0; d < 3; ++d) cells *= hi[d] - lo[d] + 1;
  const std::int64_t entry = static_cast<std::int64_t>(mesh) << 32 | face;
  if (cells > kMaxCellsPerFace) {
    large_.push_back(entry);
    return;
  }
  for (int i = lo[0]; i <= hi[0]; ++i)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int k = lo[2]; k <= hi[2]; ++k) cells_[key(i, j, k)].push_back(entry);
}

void WorldGuard::update_face(int f) {
  if (mesh_.faces[f].dead) return;
  // The queries' answers do not depend on the grid (candidates are filtered by their boxes and taken in entry
  // order), so a rebuild changes no result.
  if (++added_faces_ > 2 * built_faces_ + 64) {
    build();
    return;
  }
  insert(0, f);
}

void WorldGuard::update_node(int n) {
  for (int f : mesh_.node_faces(n)) update_face(f);
}

std::vector<GuardTriangle> WorldGuard::fan(int n) const {
  std::vector<GuardTriangle> triangles;
  for (int f : mesh_.node_faces(n)) triangles.push_back(triangle(0, f));
  return triangles;
}

std::vector<GuardSweep> WorldGuard::fan_sweep(int n, const Vec3& from) const {
  std::vector<GuardSweep> sweeps;
  for (int f : mesh_.node_faces(n)) {
    const int c = mesh_.corner_of_node(f, n);
    const int b0 = mesh_.face_node(f, (c + 1) % 3), b1 = mesh_.face_node(f, (c + 2) % 3);
    sweeps.push_back({{from, mesh_.nodes[n].x, mesh_.nodes[b0].x, mesh_.nodes[b1].x}, {n, n, b0, b1}});
  }
  return sweeps;
}

std::vector<std::int64_t> WorldGuard::candidates(const Eigen::AlignedBox3d& box) const {
  // Only faces whose box (where they are now) meets the query box: the callers skip the others anyway. The grid
  // holds a face once per cell it covers, and again (stale) after it moved: each is looked at once per query.
  if (++query_ == 0) {
    for (auto& stamps : seen_) std::fill(stamps.begin(), stamps.end(), 0);
    query_ = 1;
  }
  std::vector<std::int64_t> found;
  auto add = [&](std::int64_t entry) {
    const int mesh = static_cast<int>(entry >> 32), face = static_cast<int>(entry & 0xffffffff);
    std::vector<std::uint32_t>& stamps = seen_[mesh];
    if (stamps.size() <= static_cast<size_t>(face)) stamps.resize(meshes_[mesh]->faces.size(), 0);
    if (stamps[face] == query_) return;
    stamps[face] = query_;
    if (mesh == 0 && mesh_.faces[face].dead) return;  // never counts
    const GuardTriangle t = triangle(mesh, face);
    if (box.intersects(box_of(t.x, 0))) found.push_back(entry);
  };
  for (const std::int64_t entry : large_) add(entry);
  const std::array<int, 3> lo = cell_of(box.min()), hi = cell_of(box.max());
  for (int i = lo[0]; i <= hi[0]; ++i)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int k = lo[2]; k <= hi[2]; ++k) {
        const auto it = cells_.find(key(i, j, k));
        if (it != cells_.end())
          for (const std::int64_t entry : it->second) add(entry);
      }
  std::sort(found.begin(), found.end());
  return found;
}

bool WorldGuard::counts(std::int64_t entry, const std::vector<int>& replaced) const {
  const int mesh = static_cast<int>(entry >> 32), face = static_cast<int>(entry & 0xffffffff);
  return mesh != 0 || (!mesh_.faces[face].dead && !std::binary_search(replaced.begin(), replaced.end(), face));
}

bool WorldGuard::touches(std::int64_t entry, const int* nodes, int count) const {
  const int mesh = static_cast<int>(entry >> 32), face = static_cast<int>(entry & 0xffffffff);
  if (mesh != 0) return false;
  for (int i = 0; i < 3; ++i)
    if (std::find(nodes, nodes + count, mesh_.face_node(face, i)) != nodes + count) return true;
  return false;
}

namespace {

// The boxes the queries test candidates against: each triangle's grown by the clearance, each sweep's own. Empty
// if one is not finite (a query then answers as if blocked).
std::vector<Eigen::AlignedBox3d> separation_boxes(const std::vector<GuardTriangle>& triangles, double clearance) {
  std::vector<Eigen::AlignedBox3d> boxes;
  for (const GuardTriangle& t : triangles) {
    boxes.push_back(box_of(t.x, clearance));
    if (!boxes.back().min().allFinite() || !boxes.back().max().allFinite()) return {};
  }
  return boxes;
}

std::vector<Eigen::AlignedBox3d> sweep_boxes(const std::vector<GuardSweep>& sweeps) {
  std::vector<Eigen::AlignedBox3d> boxes;
  for (const GuardSweep& s : sweeps) {
    Eigen::AlignedBox3d b;
    for (const Vec3& p : s.x) b.extend(p);
    if (!b.min().allFinite() || !b.max().allFinite()) return {};
    boxes.push_back(b);
  }
  return boxes;
}

Eigen::AlignedBox3d union_of(const std::vector<Eigen::AlignedBox3d>& boxes) {
  Eigen::AlignedBox3d all;
  for (const Eigen::AlignedBox3d& b : boxes) all.extend(b);
  return all;
}

}  // namespace

// Each query gathers the candidates of all its shapes at once (one grid walk and one sort), then tests each
// candidate against the shapes whose boxes it meets; so any superset of the candidates gives the same answer,
// and allows() walks the grid once for its three queries.
double WorldGuard::separation(const std::vector<GuardTriangle>& triangles, const std::vector<int>& replaced) const {
  if (triangles.empty()) return clearance_;
  const std::vector<Eigen::AlignedBox3d> boxes = separation_boxes(triangles, clearance_);
  if (boxes.empty()) return 0;
  return separation_among(triangles, boxes, replaced, candidates(union_of(boxes)));
}

double WorldGuard::separation_among(const std::vector<GuardTriangle>& triangles,
                                    const std::vector<Eigen::AlignedBox3d>& boxes, const std::vector<int>& replaced,
                                    const std::vector<std::int64_t>& found) const {
  double nearest = clearance_;
  for (const std::int64_t entry : found) {
    if (!counts(entry, replaced)) continue;
    const GuardTriangle other = triangle(static_cast<int>(entry >> 32), static_cast<int>(entry & 0xffffffff));
    const Eigen::AlignedBox3d other_box = box_of(other.x, 0);
    for (size_t i = 0; i < triangles.size(); ++i) {
      const GuardTriangle& t = triangles[i];
      if (!boxes[i].intersects(other_box) || touches(entry, t.nodes.data(), 3)) continue;
      if (ball_gap(t.x, other.x) >= nearest) continue;
      nearest = std::min(nearest, triangle_separation(t.x, other.x));
      if (nearest <= 0) return 0;
    }
  }
  return nearest;
}

bool WorldGuard::sweep_is_clear(const std::vector<GuardSweep>& sweeps, const std::vector<int>& replaced) const {
  if (sweeps.empty()) return true;
  const std::vector<Eigen::AlignedBox3d> boxes = sweep_boxes(sweeps);
  if (boxes.empty()) return false;
  return sweep_is_clear_among(sweeps, boxes, replaced, candidates(union_of(boxes)));
}

bool WorldGuard::sweep_is_clear_among(const std::vector<GuardSweep>& sweeps,
                                      const std::vector<Eigen::AlignedBox3d>& boxes, const std::vector<int>& replaced,
                                      const std::vector<std::int64_t>& found) const {
  for (const std::int64_t entry : found) {
    if (!counts(entry, replaced)) continue;
    const GuardTriangle other = triangle(static_cast<int>(entry >> 32), static_cast<int>(entry & 0xffffffff));
    const Eigen::AlignedBox3d other_box = box_of(other.x, 0);
    for (size_t i = 0; i < sweeps.size(); ++i) {
      const GuardSweep& s = sweeps[i];
      if (!boxes[i].intersects(other_box) || touches(entry, s.nodes.data(), 4)) continue;
      if (ball_gap(other.x, s.x) <= 0 && triangle_meets_tetrahedron(other.x, s.x)) return false;
    }
  }
  return true;
}

namespace {

// The corners of a and b at their one shared node, or {-1, -1} unless they share exactly one (kNone never
// counts).
std::array<int, 2> single_shared_corner(const std::array<int, 3>& a, const std::array<int, 3>& b) {
  std::array<int, 2> found{-1, -1};
  int shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a[i] != kNone && a[i] == b[j]) found = {i, j}, ++shared;
  return shared == 1 ? found : std::array<int, 2>{-1, -1};
}

}  // namespace

bool WorldGuard::folds_through_neighbours(const std::vector<GuardTriangle>& triangles,
                                          const std::vector<int>& replaced) const {
  Eigen::AlignedBox3d all;
  for (const GuardTriangle& t : triangles) all.extend(box_of(t.x, 0));
  if (triangles.empty() || !all.min().allFinite() || !all.max().allFinite())
    return folds_among(triangles, replaced, nullptr);
  const std::vector<std::int64_t> found = candidates(all);
  return folds_among(triangles, replaced, &found);
}

bool WorldGuard::folds_among(const std::vector<GuardTriangle>& triangles, const std::vector<int>& replaced,
                             const std::vector<std::int64_t>* found) const {
  auto folds = [](const GuardTriangle& a, const GuardTriangle& b) {
    const std::array<int, 2> c = single_shared_corner(a.nodes, b.nodes);
    return c[0] >= 0 && triangles_meet_beyond_corner(a.x, c[0], b.x, c[1]);
  };
  for (size_t i = 0; i < triangles.size(); ++i)
    for (size_t k = i + 1; k < triangles.size(); ++k)
      if (folds(triangles[i], triangles[k])) return true;
  if (found == nullptr) return false;
  // A face that folds through a triangle shares a node with it and meets it elsewhere, so its box meets the
  // triangle's: every candidate list that holds the faces meeting the triangles' boxes gives the same answer.
  for (const std::int64_t entry : *found) {
    if (entry >> 32 != 0 || !counts(entry, replaced)) continue;
    const GuardTriangle other = triangle(0, static_cast<int>(entry & 0xffffffff));
    for (const GuardTriangle& t : triangles)
      if (folds(t, other)) return true;
  }
  return false;
}

bool edit_makes_crossing(const std::vector<GuardTriangle>& before, const std::vector<GuardTriangle>& after) {
  auto share_a_node = [](const std::array<int, 3>& a, const std::array<int, 3>& b) {
    for (int x : a)
      if (x != kNone && std::find(b.begin(), b.end(), x) != b.end()) return true;
    return false;
  };
  if (before.size() != after.size())
    throw std::invalid_argument("edit_makes_crossing: " + std::to_string(before.size()) + " triangles before but " +
                                std::to_string(after.size()) + " after (they must be the same faces, index for index)");
  const size_t n = before.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      if (share_a_node(after[i].nodes, after[j].nodes) || !triangles_intersect(after[i].x, after[j].x)) continue;
      const bool crossed_before =
          !share_a_node(before[i].nodes, before[j].nodes) && triangles_intersect(before[i].x, before[j].x);
      if (!crossed_before) return true;
    }
  return false;
}

bool WorldGuard::allows(const std::vector<GuardTriangle>& before, const std::vector<GuardTriangle>& after,
                        const std::vector<GuardSweep>& sweeps, const std::vector<int>& replaced) const {
  return allows_move(before, after, sweeps, nullptr, replaced);
}

bool WorldGuard::allows_move(const std::vector<GuardTriangle>& before, const std::vector<GuardTriangle>& after,
                             const std::vector<GuardSweep>& sweeps, const std::vector<int>* fold_replaced,
                             const std::vector<int>& replaced) const {
  std::vector<int> sorted = replaced;
  std::sort(sorted.begin(), sorted.end());
  const std::vector<Eigen::AlignedBox3d> sweep_box = sweep_boxes(sweeps);
  const std::vector<Eigen::AlignedBox3d> after_box = separation_boxes(after, clearance_);
  const std::vector<Eigen::AlignedBox3d> before_box = separation_boxes(before, clearance_);
  if (sweep_box.size() != sweeps.size() || after_box.size() != after.size() || before_box.size() != before.size()) {
    // A shape that is not finite: the separate queries give their own answers.
    if (fold_replaced != nullptr && folds_through_neighbours(after, *fold_replaced)) return false;
    if (!sweep_is_clear(sweeps, sorted)) return false;
    const double gap_after = separation(after, sorted);
    return gap_after >= clearance_ || gap_after >= separation(before, sorted);
  }
  // One walk of the grid for every query: each filters the candidates by its own shapes' boxes (the after
  // triangles' own boxes, which the fold test needs, lie inside their boxes grown by the clearance).
  Eigen::AlignedBox3d all = union_of(sweep_box);
  all.extend(union_of(after_box));
  all.extend(union_of(before_box));
  const std::vector<std::int64_t> found = all.isEmpty() ? std::vector<std::int64_t>() : candidates(all);
  if (fold_replaced != nullptr && folds_among(after, *fold_replaced, after.empty() ? nullptr : &found)) return false;
  if (!sweeps.empty() && !sweep_is_clear_among(sweeps, sweep_box, sorted, found)) return false;
  const double gap_after = after.empty() ? clearance_ : separation_among(after, after_box, sorted, found);
  if (gap_after >= clearance_) return true;
  return gap_after >= (before.empty() ? clearance_ : separation_among(before, before_box, sorted, found));
}

}  // namespace arcsim
