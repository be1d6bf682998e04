#include "sim/remesh_cloth.hpp"

#include <algorithm>
#include <cmath>


namespace arcsim {

RemeshOptions remesh_options(const Scene& scene) {
  RemeshOptions o;
  o.sizing.rib_stiffening = scene.magic.rib_stiffening;
  o.sizing.combine_tensors = scene.magic.combine_tensors;
  o.edge_flip_threshold = scene.magic.edge_flip_threshold;
  o.reprojection.gravity = scene.gravity;
  o.reprojection.max_displacement = 0.5 * scene.magic.repulsion_thickness;
  // Edits keep the gap the impact-zone projection enforces (collision_settings in sim/simulation.cpp).
  o.world_clearance = scene.magic.projection_thickness >= 0 ? scene.magic.projection_thickness
                                                            : 0.1 * scene.magic.repulsion_thickness;
  return o;
}

RemeshStats remesh(Cloth& cloth, const std::vector<int>* face_subset, const RemeshOptions& options) {
  RemeshOptions o = options;
  o.sizing.remeshing = cloth.remeshing;
  o.reference = cloth.reference.get();
  return remesh_mesh(cloth.mesh, cloth.materials, o, face_subset);
}

bool edited(const RemeshStats& stats) { return stats.splits + stats.flips + stats.collapses > 0; }

RemeshStats refine_to_size_min(Cloth& cloth, const RemeshOptions& options) {
  const double size = cloth.remeshing.size_min;
  if (!(std::isfinite(size) && size > 0)) return {};
  RemeshOptions o = options;
  o.extras.uniform_size = size;
  return remesh(cloth, nullptr, o);
}

void remap_handles(std::vector<Handle>& handles, int cloth, const Mesh::Compaction& compaction) {
  for (Handle& h : handles) {
    if (h.cloth != cloth) continue;
    std::vector<int> nodes;
    std::vector<Vec3> anchors;
    for (size_t i = 0; i < h.nodes.size(); ++i) {
      const int n = h.nodes[i];
      const int mapped = n >= 0 && n < static_cast<int>(compaction.node.size()) ? compaction.node[n] : kNone;
      if (mapped == kNone) continue;
      nodes.push_back(mapped);
      if (i < h.anchors.size()) anchors.push_back(h.anchors[i]);
    }
    h.nodes = std::move(nodes);
    h.anchors = std::move(anchors);
  }
}

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
