#include "mesh/mesh_stats.hpp"

#include <algorithm>
#include <array>
#include <vector>

namespace arcsim {

namespace {

// Sorts `values` and returns (min, median, max); zeros for an empty list.
std::array<double, 3> min_median_max(std::vector<double>& values) {
  if (values.empty()) return {0, 0, 0};
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  const double median = n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  return {values.front(), median, values.back()};
}

}  // namespace

MeshSizeStats mesh_size_stats(const Mesh& mesh) {
  MeshSizeStats s;
  for (const Node& n : mesh.nodes)
    if (!n.dead) ++s.nodes;
  std::vector<double> world, rest;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Face& face = mesh.faces[f];
    if (face.dead) continue;
    ++s.faces;
    for (int i = 0; i < 3; ++i) {
      const Edge& e = mesh.edges[face.e[i]];
      // Each edge once: from its f[0] side, or from its only face.
      const int owner = e.f[0] != kNone ? e.f[0] : e.f[1];
      if (owner != static_cast<int>(f)) continue;
      world.push_back((mesh.nodes[e.n[1]].x - mesh.nodes[e.n[0]].x).norm());
      rest.push_back((mesh.verts[face.v[(i + 1) % 3]].u - mesh.verts[face.v[i]].u).norm());
    }
  }
  s.edges = static_cast<int>(world.size());
  const auto w = min_median_max(world);
  const auto r = min_median_max(rest);
  s.edge_min = w[0], s.edge_median = w[1], s.edge_max = w[2];
  s.rest_edge_min = r[0], s.rest_edge_median = r[1], s.rest_edge_max = r[2];
  return s;
}

}  // namespace arcsim
