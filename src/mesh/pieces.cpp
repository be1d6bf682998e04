#include "mesh/pieces.hpp"

#include <algorithm>
#include <map>
#include <numeric>

#include "math/disjoint_sets.hpp"

namespace arcsim {

namespace {

struct Grouping {
  std::vector<Piece> pieces;  // largest first
  std::vector<int> of_face;
};

Grouping group_faces(const Mesh& mesh) {
  DisjointSets sets(mesh.nodes.size());
  for (int f = 0; f < static_cast<int>(mesh.faces.size()); ++f)
    if (!mesh.faces[f].dead)
      for (int c = 1; c < 3; ++c) sets.unite(mesh.face_node(f, c), mesh.face_node(f, 0));
  std::map<int, int> index_of_root;  // ordered by root node: deterministic before the sort
  std::vector<Piece> unsorted;
  std::vector<int> raw(mesh.faces.size(), -1);
  for (int f = 0; f < static_cast<int>(mesh.faces.size()); ++f) {
    const Face& face = mesh.faces[f];
    if (face.dead) continue;
    const int root = sets.find(mesh.face_node(f, 0));
    auto [it, fresh] = index_of_root.emplace(root, static_cast<int>(unsorted.size()));
    if (fresh) unsorted.emplace_back();
    Piece& p = unsorted[it->second];
    const Vec3 &a = mesh.nodes[mesh.face_node(f, 0)].x, &b = mesh.nodes[mesh.face_node(f, 1)].x,
               &c = mesh.nodes[mesh.face_node(f, 2)].x;
    ++p.faces;
    p.rest_area += face.rest_area;
    p.world_area += 0.5 * (b - a).cross(c - a).norm();
    raw[f] = it->second;
  }
  std::vector<int> order(unsorted.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) {
    if (unsorted[x].faces != unsorted[y].faces) return unsorted[x].faces > unsorted[y].faces;
    return unsorted[x].rest_area > unsorted[y].rest_area;
  });
  std::vector<int> rank(order.size());
  Grouping g;
  for (size_t k = 0; k < order.size(); ++k) {
    rank[order[k]] = static_cast<int>(k);
    g.pieces.push_back(unsorted[order[k]]);
  }
  g.of_face.assign(mesh.faces.size(), -1);
  for (size_t f = 0; f < raw.size(); ++f)
    if (raw[f] >= 0) g.of_face[f] = rank[raw[f]];
  return g;
}

}  // namespace

std::vector<Piece> mesh_pieces(const Mesh& mesh) { return group_faces(mesh).pieces; }

std::vector<int> face_pieces(const Mesh& mesh) { return group_faces(mesh).of_face; }

}  // namespace arcsim
