#include "sim/persistent_fallback.hpp"

#include <algorithm>

namespace arcsim {

namespace {

bool any(const std::vector<std::vector<int>>& per_cloth) {
  for (const std::vector<int>& nodes : per_cloth)
    if (!nodes.empty()) return true;
  return false;
}

// Both sorted per cloth.
bool share_a_node(const std::vector<std::vector<int>>& a, const std::vector<std::vector<int>>& b) {
  for (size_t c = 0; c < a.size() && c < b.size(); ++c) {
    auto i = a[c].begin(), j = b[c].begin();
    while (i != a[c].end() && j != b[c].end()) {
      if (*i == *j) return true;
      if (*i < *j) ++i; else ++j;
    }
  }
  return false;
}

}  // namespace

void PersistentFallback::record_failure(int failed_substep, const std::vector<std::vector<int>>& fallback_nodes) {
  if (failed_substep != 0 || !any(fallback_nodes)) {
    streak_ = 0;
    nodes_.clear();
    return;
  }
  std::vector<std::vector<int>> sorted = fallback_nodes;
  for (std::vector<int>& nodes : sorted) std::sort(nodes.begin(), nodes.end());
  streak_ = streak_ == 0 || share_a_node(sorted, nodes_) ? streak_ + 1 : 1;
  nodes_ = std::move(sorted);
}

}  // namespace arcsim
