// Bounding-volume hierarchy of axis-aligned boxes over the triangles of one mesh: built once per topology
// (median splits), refitted bottom-up whenever the boxes move, and traversed against itself or another tree
// to list the primitive pairs whose boxes overlap. Large traversals run in parallel (OpenMP); the pairs come in
// a deterministic order for a given thread count (callers that need more sort them: find_candidates does).
// Cost: the tree size plus the overlapping pairs.
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

  // Pairs (i, j), i < j, of primitives whose boxes overlap. With `dirty` (a flag per primitive), only pairs
  // with at least one dirty primitive, pruning clean subtrees (cost then follows the dirty part).
  std::vector<std::pair<int, int>> self_overlaps(const std::vector<char>* dirty = nullptr) const;
  // Pairs (i of this tree, j of `other`) whose boxes overlap; with flags, only pairs with a dirty member.
  std::vector<std::pair<int, int>> overlaps(const Bvh& other, const std::vector<char>* dirty = nullptr,
                                            const std::vector<char>* other_dirty = nullptr) const;

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
