// Which row of the implicit system each mesh node is. The full step solves for every node (row = node); a zone
// solve (physics/zone_solve.hpp) only for the zone's free nodes, numbered in mesh order, every other node held
// fixed (-1).
#pragma once

#include <algorithm>
#include <utility>
#include <vector>

namespace arcsim {

class SystemDofs {
 public:
  // Every node of a mesh of `node_count` nodes is a row, in node order.
  static SystemDofs all_nodes(int node_count) {
    SystemDofs d;
    d.count_ = node_count;
    return d;
  }
  // Only `free_nodes` (sorted, unique) are rows, in that order.
  static SystemDofs only(std::vector<int> free_nodes) {
    SystemDofs d;
    d.count_ = static_cast<int>(free_nodes.size());
    d.nodes_ = std::move(free_nodes);
    d.subset_ = true;
    return d;
  }
  int count() const { return count_; }
  // The mesh node of row `dof`.
  int node(int dof) const { return subset_ ? nodes_[dof] : dof; }
  // The row of mesh node `node`, -1 if it is held fixed (O(log count) for a subset).
  int dof(int node) const {
    if (!subset_) return node;
    const auto it = std::lower_bound(nodes_.begin(), nodes_.end(), node);
    return (it != nodes_.end() && *it == node) ? static_cast<int>(it - nodes_.begin()) : -1;
  }

 private:
  int count_ = 0;
  bool subset_ = false;
  std::vector<int> nodes_;
};

}  // namespace arcsim
