// Bounding-volume hierarchy of axis-aligned boxes over the triangles of one mesh: built once per topology
// (median splits), refitted bottom-up whenever the boxes move, and traversed against itself or another tree
// to list the primitive pairs whose boxes overlap. Traversals run in parallel (OpenMP) and return their pairs
// sorted, so the result does not depend on the thread count. Cost: the tree size plus the overlapping pairs.
#pragma once

#include <utility>
#include <vector>

#include "collision/aabb.hpp"

namespace arcsim {

class Bvh {
 public:
  // Builds the hierarchy over one box per primitive (primitive i = boxes[i]).
  void build(const std::vector<Aabb>& boxes);
  // New boxes for the same primitives (same count and order as build).
  void refit(const std::vector<Aabb>& boxes);
  int primitive_count() const { return static_cast<int>(leaf_of_.size()); }
  bool empty() const { return nodes_.empty(); }
  const Aabb& bounds() const { return nodes_.front().box; }

  // Pairs (i, j), i < j, of primitives whose boxes overlap.
  std::vector<std::pair<int, int>> self_overlaps() const;
  // Pairs (i of this tree, j of `other`) whose boxes overlap.
  std::vector<std::pair<int, int>> overlaps(const Bvh& other) const;

 private:
  struct Node {
    Aabb box;
    int left = -1, right = -1;  // children (internal node); children always follow their parent
    int primitive = -1;         // leaf: the primitive
    bool leaf() const { return primitive >= 0; }
  };
  int build_range(std::vector<int>& ids, int begin, int end, const std::vector<Vec3>& centers,
                  const std::vector<Aabb>& boxes);
  friend struct BvhTraversal;

  std::vector<Node> nodes_;   // root first
  std::vector<int> leaf_of_;  // primitive -> its leaf node
};

}  // namespace arcsim
