#include "sim/persistent_fallback.hpp"

#include <algorithm>
#include <iterator>

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

void PersistentFallback::record_failure(int failed_substep, const std::vector<std::vector<int>>& fallback_nodes,
                                        int level) {
  if (failed_substep < 0 || !any(fallback_nodes)) {
    streak_ = 0;
    nodes_.clear();
    streak_nodes_.clear();
    return;
  }
  std::vector<std::vector<int>> sorted = fallback_nodes;
  for (std::vector<int>& nodes : sorted) std::sort(nodes.begin(), nodes.end());
  // The failed substep lies within the one that failed one attempt before (a finer level splits each substep
  // into 2^(level difference)): the fallback came at the same moment of the step, whatever the length.
  const int finer_by = level - level_;
  const bool nested = finer_by > 0 && finer_by < 31 && (failed_substep >> finer_by) == substep_;
  const bool continues = streak_ > 0 && nested && share_a_node(sorted, nodes_);
  if (!continues) {
    streak_ = 0;
    streak_level_ = level;
    streak_nodes_.clear();
  }
  ++streak_;
  streak_nodes_.resize(std::max(streak_nodes_.size(), sorted.size()));
  for (size_t c = 0; c < sorted.size(); ++c) {
    std::vector<int> merged;
    std::set_union(streak_nodes_[c].begin(), streak_nodes_[c].end(), sorted[c].begin(), sorted[c].end(),
                   std::back_inserter(merged));
    streak_nodes_[c] = std::move(merged);
  }
  nodes_ = std::move(sorted);
  level_ = level;
  substep_ = failed_substep;
}

}  // namespace arcsim
