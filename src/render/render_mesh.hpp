// Plain triangle soups handed to the renderer, and helpers that build them from a simulation mesh.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "math/types.hpp"

namespace arcsim {

class Mesh;

struct RenderMesh {
  std::vector<Vec3> positions;                       // world positions (m)
  std::vector<std::array<int, 3>> triangles;         // indices into positions, counter-clockwise = front side
  std::vector<std::array<int, 2>> highlight_edges;   // drawn as dark lines (sheet border, crack lips)
};

// Edges used by exactly one triangle (sheet borders and, after fracture, crack lips), each as (a, b) in the
// direction it runs in its triangle, in order of first appearance. Degenerate triangles are ignored.
std::vector<std::array<int, 2>> boundary_edges(const std::vector<std::array<int, 3>>& triangles);

// Every distinct undirected edge of the triangles, as (min, max), sorted.
std::vector<std::array<int, 2>> unique_edges(const std::vector<std::array<int, 3>>& triangles);

// A render mesh of node positions and node triangles; with highlight_boundary its boundary edges are highlighted.
RenderMesh make_render_mesh(std::vector<Vec3> positions, std::vector<std::array<int, 3>> triangles,
                            bool highlight_boundary = true);

// The live nodes and faces of a simulation mesh (tombstones skipped). Highlights the mesh's boundary edges.
RenderMesh render_mesh_from(const Mesh& mesh, bool highlight_boundary = true);

// Bounding box of all finite positions (empty box if there are none).
Eigen::AlignedBox3d bounds_of(const RenderMesh& mesh);
Eigen::AlignedBox3d bounds_of(const std::vector<RenderMesh>& meshes);

// The box holding most of the points: per axis, from the `fraction`-quantile to the (1 - fraction)-quantile of
// the finite points' coordinates (all of them for fraction 0; empty box if there are none). For framing a
// camera on where a sheet is over an animation without the few points that leave the scene (a shard falling
// away from paper-tearing.json's sheet took the camera 80 m down with it).
Eigen::AlignedBox3d bulk_bounds(const std::vector<Vec3>& points, double fraction);

// Throws InputError "<what>: ..." naming the first triangle or edge with an index out of range or a vertex with a
// non-finite position. The renderer calls it; `what` names the mesh (e.g. "cloth 0").
void check_render_mesh(const RenderMesh& mesh, const std::string& what);

}  // namespace arcsim
