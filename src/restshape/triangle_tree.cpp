#include "restshape/triangle_tree.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "restshape/triangle_geometry.hpp"

namespace arcsim {

namespace {

constexpr int kLeafSize = 4;
// Deep enough for any median-split tree of < 2^60 triangles.
constexpr int kStackSize = 128;

double squared_distance_to_box(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 below = (lo - p).cwiseMax(0.0), above = (p - hi).cwiseMax(0.0);
  return below.squaredNorm() + above.squaredNorm();
}

}  // namespace

TriangleTree::TriangleTree(std::vector<std::array<Vec3, 3>> triangles) : triangles_(std::move(triangles)) {
  if (triangles_.empty()) throw std::invalid_argument("TriangleTree: no triangles");
  Vec3 lo = Vec3::Constant(kInfinity), hi = Vec3::Constant(-kInfinity);
  for (const auto& tri : triangles_)
    for (const Vec3& p : tri) {
      if (!p.allFinite()) throw std::invalid_argument("TriangleTree: corner is not finite");
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  // Box tests round differently from triangle tests; a pad far above rounding but far below any feature
  // keeps a triangle touching its box face from being culled.
  pad_ = 1e-12 * std::max((hi - lo).norm(), lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).maxCoeff()) + 1e-300;
  std::vector<Vec3> centroids(triangles_.size());
  for (size_t i = 0; i < triangles_.size(); ++i)
    centroids[i] = (triangles_[i][0] + triangles_[i][1] + triangles_[i][2]) / 3;
  nodes_.reserve(2 * triangles_.size() / kLeafSize + 2);
  build(0, static_cast<int>(triangles_.size()), centroids);
}

int TriangleTree::build(int first, int count, std::vector<Vec3>& centroids) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back(Node());
  Vec3 lo = Vec3::Constant(kInfinity), hi = Vec3::Constant(-kInfinity);
  Vec3 clo = lo, chi = hi;
  for (int i = first; i < first + count; ++i) {
    for (const Vec3& p : triangles_[i]) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    clo = clo.cwiseMin(centroids[i]);
    chi = chi.cwiseMax(centroids[i]);
  }
  nodes_[index].lo = lo - Vec3::Constant(pad_);
  nodes_[index].hi = hi + Vec3::Constant(pad_);
  if (count <= kLeafSize) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  // Median split along the widest centroid axis; triangles and centroids are permuted together.
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const int half = count / 2;
  std::vector<int> order(count);
  for (int i = 0; i < count; ++i) order[i] = first + i;
  std::nth_element(order.begin(), order.begin() + half, order.end(),
                   [&](int a, int b) { return centroids[a][axis] < centroids[b][axis]; });
  std::vector<std::array<Vec3, 3>> tris(count);
  std::vector<Vec3> cents(count);
  for (int i = 0; i < count; ++i) {
    tris[i] = triangles_[order[i]];
    cents[i] = centroids[order[i]];
  }
  std::copy(tris.begin(), tris.end(), triangles_.begin() + first);
  std::copy(cents.begin(), cents.end(), centroids.begin() + first);
  const int left = build(first, half, centroids);
  const int right = build(first + half, count - half, centroids);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

Vec3 TriangleTree::closest_point(const Vec3& p) const {
  Vec3 best_point = triangles_[0][0];
  double best = (best_point - p).squaredNorm();
  if (!p.allFinite()) return best_point;
  // Depth-first, nearer child first, pruning boxes farther than the best point found so far.
  int stack[kStackSize];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (squared_distance_to_box(p, node.lo, node.hi) > best) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const auto& tri = triangles_[i];
        const Vec3 q = closest_point_on_triangle(p, tri[0], tri[1], tri[2]);
        const double d = (q - p).squaredNorm();
        if (d < best) {
          best = d;
          best_point = q;
        }
      }
      continue;
    }
    const double dl = squared_distance_to_box(p, nodes_[node.left].lo, nodes_[node.left].hi);
    const double dr = squared_distance_to_box(p, nodes_[node.right].lo, nodes_[node.right].hi);
    const bool left_first = dl <= dr;
    const int near = left_first ? node.left : node.right, far = left_first ? node.right : node.left;
    if (std::min(dl, dr) > best) continue;
    if (std::max(dl, dr) <= best) stack[top++] = far;
    stack[top++] = near;
  }
  return best_point;
}

bool TriangleTree::nearest_line_hit(const Vec3& origin, const Vec3& direction, double t_limit,
                                    Vec3& hit_point) const {
  if (!origin.allFinite() || !direction.allFinite() || direction.squaredNorm() == 0 || !(t_limit >= 0))
    return false;
  const LineCaster line(origin, direction);
  // |t| of the nearest hit so far; boxes whose part of the line is all farther are skipped.
  double best = t_limit;
  bool found = false;
  // Smallest |t| over the line's stretch inside a box, or infinity if the line misses it. A missed box must be
  // skipped even while best is still infinite (t_limit = infinity), hence the explicit "< kInfinity" tests.
  auto box_reach = [&](const Node& node) {
    double t0, t1;
    if (!line.clip_to_box(node.lo, node.hi, t0, t1)) return kInfinity;
    if (t0 <= 0 && t1 >= 0) return 0.0;
    return std::min(std::abs(t0), std::abs(t1));
  };
  // Depth-first, nearer child first; each entry carries its box's reach so that no box is clipped twice.
  struct Entry {
    int node;
    double reach;
  };
  Entry stack[kStackSize];
  int top = 0;
  const double root_reach = box_reach(nodes_[0]);
  if (root_reach < kInfinity) stack[top++] = {0, root_reach};
  while (top > 0) {
    const Entry entry = stack[--top];
    if (entry.reach > best) continue;  // a nearer hit was found after this entry was pushed
    const Node& node = nodes_[entry.node];
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const auto& tri = triangles_[i];
        LineCaster::Hit hit;
        if (line.intersect(tri[0], tri[1], tri[2], hit) && std::abs(hit.t) <= best) {
          if (found && std::abs(hit.t) == best) continue;
          best = std::abs(hit.t);
          hit_point = hit.point;
          found = true;
        }
      }
      continue;
    }
    const Entry left{node.left, box_reach(nodes_[node.left])}, right{node.right, box_reach(nodes_[node.right])};
    const bool left_first = left.reach <= right.reach;
    const Entry& near = left_first ? left : right;
    const Entry& far = left_first ? right : left;
    if (far.reach < kInfinity && far.reach <= best) stack[top++] = far;
    if (near.reach < kInfinity && near.reach <= best) stack[top++] = near;
  }
  return found;
}

}  // namespace arcsim
