#include "collision/intersections.hpp"

#include <algorithm>
#include <array>
#include <tuple>

#include "collision/aabb.hpp"
#include "collision/bvh.hpp"
#include "collision/triangle_intersection.hpp"

namespace arcsim {

namespace {

// The live faces of a mesh with their world triangles and a hierarchy over their boxes.
struct FaceTree {
  const Mesh* mesh = nullptr;
  std::vector<int> face;  // primitive -> face index
  std::vector<std::array<Vec3, 3>> triangle;
  Bvh bvh;
};

FaceTree build_tree(const Mesh& mesh) {
  FaceTree t;
  t.mesh = &mesh;
  std::vector<Aabb> boxes;
  for (int f = 0; f < static_cast<int>(mesh.faces.size()); ++f) {
    if (mesh.faces[f].dead) continue;
    std::array<Vec3, 3> tri;
    Aabb box;
    for (int c = 0; c < 3; ++c) {
      tri[c] = mesh.nodes[mesh.face_node(f, c)].x;
      box.extend(tri[c]);
    }
    t.face.push_back(f);
    t.triangle.push_back(tri);
    boxes.push_back(box);
  }
  if (!boxes.empty()) t.bvh.build(boxes);
  return t;
}

bool share_node(const Mesh& m, int f, int g) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (m.face_node(f, i) == m.face_node(g, j)) return true;
  return false;
}

}  // namespace

std::vector<IntersectingPair> intersecting_pairs(const std::vector<const Mesh*>& sheets,
                                                 const std::vector<const Mesh*>& obstacles) {
  std::vector<FaceTree> sheet_trees, obstacle_trees;
  for (const Mesh* m : sheets) sheet_trees.push_back(build_tree(*m));
  for (const Mesh* m : obstacles) obstacle_trees.push_back(build_tree(*m));

  std::vector<IntersectingPair> out;
  auto add = [&](int a, int i, const FaceTree& other, int b, int j, bool obstacle) {
    const FaceTree& ta = sheet_trees[a];
    if (!triangles_intersect(ta.triangle[i], other.triangle[j])) return;
    IntersectingPair p;
    p.sheet_a = a;
    p.face_a = ta.face[i];
    p.sheet_b = b;
    p.face_b = other.face[j];
    p.obstacle = obstacle;
    out.push_back(p);
  };
  for (int a = 0; a < static_cast<int>(sheet_trees.size()); ++a) {
    const FaceTree& ta = sheet_trees[a];
    if (ta.bvh.empty()) continue;
    for (const auto& [i, j] : ta.bvh.self_overlaps())
      if (!share_node(*ta.mesh, ta.face[i], ta.face[j])) add(a, i, ta, a, j, false);
    for (int b = a + 1; b < static_cast<int>(sheet_trees.size()); ++b)
      if (!sheet_trees[b].bvh.empty())
        for (const auto& [i, j] : ta.bvh.overlaps(sheet_trees[b].bvh)) add(a, i, sheet_trees[b], b, j, false);
    for (int b = 0; b < static_cast<int>(obstacle_trees.size()); ++b)
      if (!obstacle_trees[b].bvh.empty())
        for (const auto& [i, j] : ta.bvh.overlaps(obstacle_trees[b].bvh)) add(a, i, obstacle_trees[b], b, j, true);
  }
  auto key = [](const IntersectingPair& p) { return std::make_tuple(p.sheet_a, p.face_a, p.obstacle, p.sheet_b, p.face_b); };
  std::sort(out.begin(), out.end(), [&](const IntersectingPair& x, const IntersectingPair& y) { return key(x) < key(y); });
  return out;
}

}  // namespace arcsim
