// Sorting long lists whose leading key is a small integer (node, edge or kind-and-index), as std::sort does.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace arcsim {

// Sorts v[first, end) by T's operator< and drops duplicates, as std::sort and std::unique would, when
// key(t) in [0, key_count) is T's leading sort key: a counting sort by key, then each (small) bucket by
// operator<. Linear in the length for the node-pair and candidate-pair lists of a step (10^4-10^6 entries), where
// std::sort took percents of a heavy scene's wall. Ranges shorter than `min_count`, and any key out of range, go
// to std::sort.
template <typename T, typename Key>
void counting_sort_unique(std::vector<T>& v, size_t first, size_t key_count, Key key, size_t min_count = 0) {
  const auto begin = v.begin() + static_cast<std::ptrdiff_t>(first);
  const size_t count = v.size() - first;
  const bool in_range = std::all_of(begin, v.end(), [&](const T& t) {
    const auto k = key(t);
    return k >= 0 && static_cast<size_t>(k) < key_count;
  });
  if (count < min_count || !in_range) {
    std::sort(begin, v.end());
  } else {
    std::vector<size_t> start(key_count + 1, 0);
    for (auto it = begin; it != v.end(); ++it) ++start[static_cast<size_t>(key(*it)) + 1];
    for (size_t k = 0; k < key_count; ++k) start[k + 1] += start[k];
    std::vector<T> sorted(count);
    {
      std::vector<size_t> next(start.begin(), start.end() - 1);
      for (auto it = begin; it != v.end(); ++it) sorted[next[static_cast<size_t>(key(*it))]++] = *it;
    }
    for (size_t k = 0; k < key_count; ++k)
      if (start[k + 1] - start[k] > 1)
        std::sort(sorted.begin() + static_cast<std::ptrdiff_t>(start[k]),
                  sorted.begin() + static_cast<std::ptrdiff_t>(start[k + 1]));
    if (first == 0)
      v.swap(sorted);
    else
      std::copy(sorted.begin(), sorted.end(), begin);
  }
  v.erase(std::unique(v.begin() + static_cast<std::ptrdiff_t>(first), v.end()), v.end());
}

}  // namespace arcsim
