// A static bounding-volume hierarchy over a triangle soup, answering closest-point and nearest-line-hit queries
// in O(log n) typical time. Built once (the reference surface never changes), so it favours simple median splits.
#pragma once

#include <array>
#include <vector>

#include "math/types.hpp"

namespace arcsim {

class TriangleTree {
 public:
  // Triangles as corner triples. Throws std::invalid_argument if the list is empty or a corner is not finite.
  explicit TriangleTree(std::vector<std::array<Vec3, 3>> triangles);

  // Closest point of all triangles to p.
  Vec3 closest_point(const Vec3& p) const;

  // Among the points where the line origin + t * direction meets a triangle with |t| <= t_limit, the one of
  // smallest |t| (ties: the first found). direction must be nonzero and finite. False if there is none.
  bool nearest_line_hit(const Vec3& origin, const Vec3& direction, double t_limit, Vec3& hit_point) const;

  size_t size() const { return triangles_.size(); }
  const std::array<Vec3, 3>& triangle(size_t i) const { return triangles_[i]; }
  // Diagonal of the bounding box of all triangles (m).
  double extent() const { return (nodes_[0].hi - nodes_[0].lo).norm(); }

 private:
  struct Node {
    Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // bounds, padded by a few roundings so that boundary hits are never culled
    int first = 0, count = 0;  // leaf: triangles [first, first + count); inner node: count == 0
    int left = 0, right = 0;   // children of an inner node
  };
  int build(int first, int count, std::vector<Vec3>& centroids);

  std::vector<std::array<Vec3, 3>> triangles_;  // reordered so that each leaf's triangles are contiguous
  std::vector<Node> nodes_;                     // nodes_[0] is the root
  double pad_ = 0;
};

}  // namespace arcsim
