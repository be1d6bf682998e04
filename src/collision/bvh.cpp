#include "collision/bvh.hpp"

#include <algorithm>
#include <numeric>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace arcsim {

void Bvh::build(const std::vector<Aabb>& boxes) {
  nodes_.clear();
  leaf_of_.assign(boxes.size(), -1);
  if (boxes.empty()) return;
  nodes_.reserve(2 * boxes.size());
  std::vector<Vec3> centers(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) centers[i] = boxes[i].center();
  std::vector<int> ids(boxes.size());
  std::iota(ids.begin(), ids.end(), 0);
  build_range(ids, 0, static_cast<int>(ids.size()), centers, boxes);
}

int Bvh::build_range(std::vector<int>& ids, int begin, int end, const std::vector<Vec3>& centers,
                     const std::vector<Aabb>& boxes) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  if (end - begin == 1) {
    nodes_[index].primitive = ids[begin];
    nodes_[index].box = boxes[ids[begin]];
    leaf_of_[ids[begin]] = index;
    return index;
  }
  // Split at the median centre along the widest axis of the centres; ties broken by id keep the build
  // deterministic.
  Aabb spread;
  for (int k = begin; k < end; ++k) spread.extend(centers[ids[k]]);
  Eigen::Index axis;
  (spread.hi - spread.lo).maxCoeff(&axis);
  const int mid = begin + (end - begin) / 2;
  std::nth_element(ids.begin() + begin, ids.begin() + mid, ids.begin() + end, [&](int a, int b) {
    const double ca = centers[a][axis], cb = centers[b][axis];
    return ca != cb ? ca < cb : a < b;
  });
  const int left = build_range(ids, begin, mid, centers, boxes);
  const int right = build_range(ids, mid, end, centers, boxes);
  nodes_[index].left = left;
  nodes_[index].right = right;
  nodes_[index].box = nodes_[left].box;
  nodes_[index].box.extend(nodes_[right].box);
  return index;
}

void Bvh::refit(const std::vector<Aabb>& boxes) {
  // Children are stored after their parent, so a reverse sweep sees children first.
  for (int i = static_cast<int>(nodes_.size()) - 1; i >= 0; --i) {
    Node& n = nodes_[i];
    if (n.leaf()) {
      n.box = boxes[n.primitive];
    } else {
      n.box = nodes_[n.left].box;
      n.box.extend(nodes_[n.right].box);
    }
  }
}

// Pair enumeration between (sub)trees. A work item is either "all pairs inside subtree a" (self) or "all pairs
// between subtree a of tree A and subtree b of tree B".
struct BvhTraversal {
  static constexpr size_t kParallelNodes = 8192;
  const Bvh& A;
  const Bvh& B;
  bool same_tree;
  // Per tree node: the subtree holds a dirty primitive (empty: everything is dirty).
  std::vector<char> dirty_a, dirty_b;

  static std::vector<char> subtree_flags(const Bvh& t, const std::vector<char>* primitives) {
    if (!primitives) return {};
    std::vector<char> flags(t.nodes_.size(), 0);
    for (int i = static_cast<int>(t.nodes_.size()) - 1; i >= 0; --i) {
      const Bvh::Node& n = t.nodes_[i];
      flags[i] = n.leaf() ? (*primitives)[n.primitive] : (flags[n.left] || flags[n.right]);
    }
    return flags;
  }
  bool any_dirty(int a, int b) const {
    const bool da = dirty_a.empty() || dirty_a[a];
    const bool db = same_tree ? (dirty_a.empty() || dirty_a[b]) : (dirty_b.empty() || dirty_b[b]);
    return da || db;
  }

  struct Item {
    int a, b;
    bool self;
  };

  void self_pairs(int a, std::vector<std::pair<int, int>>& out) const {
    const Bvh::Node& n = A.nodes_[a];
    if (n.leaf() || !any_dirty(a, a)) return;
    self_pairs(n.left, out);
    self_pairs(n.right, out);
    cross_pairs(n.left, n.right, out);
  }

  void cross_pairs(int a, int b, std::vector<std::pair<int, int>>& out) const {
    const Bvh::Node& na = A.nodes_[a];
    const Bvh::Node& nb = B.nodes_[b];
    if (!na.box.overlaps(nb.box) || !any_dirty(a, b)) return;
    if (na.leaf() && nb.leaf()) {
      int i = na.primitive, j = nb.primitive;
      if (same_tree && i > j) std::swap(i, j);
      out.emplace_back(i, j);
      return;
    }
    // Descend the node that is not a leaf (the first one if neither is).
    if (!na.leaf()) {
      cross_pairs(na.left, b, out);
      cross_pairs(na.right, b, out);
    } else {
      cross_pairs(a, nb.left, out);
      cross_pairs(a, nb.right, out);
    }
  }

  // Splits the top of the traversal into independent items so that threads can share the work.
  std::vector<Item> split(Item root, size_t wanted) const {
    std::vector<Item> items{root};
    for (bool progress = true; progress && items.size() < wanted;) {
      progress = false;
      std::vector<Item> next;
      for (const Item& it : items) {
        const Bvh::Node& na = A.nodes_[it.a];
        if (it.self) {
          if (na.leaf()) continue;
          next.push_back({na.left, na.left, true});
          next.push_back({na.right, na.right, true});
          next.push_back({na.left, na.right, false});
          progress = true;
          continue;
        }
        const Bvh::Node& nb = B.nodes_[it.b];
        if (!na.box.overlaps(nb.box)) continue;
        if (!na.leaf()) {
          next.push_back({na.left, it.b, false});
          next.push_back({na.right, it.b, false});
          progress = true;
        } else if (!nb.leaf()) {
          next.push_back({it.a, nb.left, false});
          next.push_back({it.a, nb.right, false});
          progress = true;
        } else {
          next.push_back(it);
        }
      }
      items.swap(next);
    }
    return items;
  }

  std::vector<std::pair<int, int>> run(Item root) const {
    int threads = 1;
#ifdef _OPENMP
    threads = omp_get_max_threads();
#endif
    // Small trees are traversed serially: waking threads costs more than the traversal (and much more on a
    // loaded machine).
    const bool parallel = threads > 1 && A.nodes_.size() + B.nodes_.size() >= kParallelNodes;
    const std::vector<Item> items = parallel ? split(root, 16 * static_cast<size_t>(threads)) : std::vector<Item>{root};
    std::vector<std::vector<std::pair<int, int>>> found(items.size());
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
    for (int k = 0; k < static_cast<int>(items.size()); ++k) {
      const Item& it = items[k];
      if (it.self)
        self_pairs(it.a, found[k]);
      else
        cross_pairs(it.a, it.b, found[k]);
    }
    std::vector<std::pair<int, int>> pairs;
    size_t total = 0;
    for (const auto& f : found) total += f.size();
    pairs.reserve(total);
    for (const auto& f : found) pairs.insert(pairs.end(), f.begin(), f.end());
    return pairs;
  }
};

std::vector<std::pair<int, int>> Bvh::self_overlaps(const std::vector<char>* dirty) const {
  if (nodes_.empty()) return {};
  return BvhTraversal{*this, *this, true, BvhTraversal::subtree_flags(*this, dirty), {}}.run({0, 0, true});
}

std::vector<std::pair<int, int>> Bvh::overlaps(const Bvh& other, const std::vector<char>* dirty,
                                               const std::vector<char>* other_dirty) const {
  if (nodes_.empty() || other.nodes_.empty()) return {};
  // A clean side (no flags given while the other has them) counts as clean everywhere.
  std::vector<char> clean_a, clean_b;
  if (other_dirty && !dirty) clean_a.assign(primitive_count(), 0), dirty = &clean_a;
  if (dirty && !other_dirty) clean_b.assign(other.primitive_count(), 0), other_dirty = &clean_b;
  return BvhTraversal{*this, other, false, BvhTraversal::subtree_flags(*this, dirty),
                      BvhTraversal::subtree_flags(other, other_dirty)}
      .run({0, 0, false});
}

}  // namespace arcsim
