// Edge-length statistics of a mesh: the per-frame log reports them, and fracture takes its crack length scale
// from them on meshes without a minimum size.
#pragma once

#include "mesh/mesh.hpp"

namespace arcsim {

// Mesh size at a moment, for the per-frame log: live face and node counts and the min / median / max world
// edge length (m), and the same for rest-space lengths.
struct MeshSizeStats {
  int faces = 0, nodes = 0, edges = 0;
  double edge_min = 0, edge_median = 0, edge_max = 0;                 // world, m
  double rest_edge_min = 0, rest_edge_median = 0, rest_edge_max = 0;  // rest space, m
};
MeshSizeStats mesh_size_stats(const Mesh& mesh);

}  // namespace arcsim
