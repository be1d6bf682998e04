// Checks of mesh validity: of raw input triangles before a Mesh is built, and of a built Mesh's topology and
// per-element state after edits.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"

namespace arcsim {

// Raw triangle soup as read from a file. vert_node[k] is the node of rest vertex k; tris hold vert indices.
// `tri_source_line[t]` (optional) is the file line of triangle t, used in messages.
struct TriangleInput {
  size_t node_count = 0;
  std::vector<int> vert_node;
  std::vector<Vec3> vert_u;
  std::vector<std::array<int, 3>> tris;
  std::vector<int> tri_source_line;
};

// Throws InputError ("<file>:<line>: <problem>" or "<file>: <problem> (node N)") on the first of: index out of
// range, degenerate face (a node repeated), zero-area face in rest space, duplicate face, non-manifold edge
// (more than two faces), inconsistent orientation (two faces run an edge the same way), non-manifold vertex
// (its faces form more than one fan), node referenced by no face. Node and face numbers in messages are
// 1-based, as in the OBJ file.
void validate_triangles(const TriangleInput& in, const std::string& file);

// Returns "" if the mesh is consistent, else a one-line description of the first problem, naming the element:
// live elements only reference live elements; adjacency lists agree both ways; each edge has 1 or 2 faces with
// the orientation convention of mesh.hpp; every node's faces form one fan (manifold); no degenerate faces;
// optionally every face has positive rest area and all per-element state is finite.
struct MeshCheckOptions {
  bool require_positive_rest_area = true;
  bool require_finite_state = true;
  // Derived rest data (rest_area, rest_normal) matches the rest vertices, i.e. update_rest_data ran after the
  // last edit or rest-shape change. Switch off while rest positions are being changed in bulk.
  bool require_current_rest_data = true;
};
std::string check_mesh(const Mesh& mesh, const MeshCheckOptions& options = {});

// Returns "" if every stored number of the live elements is finite (node x, x0, v, a, mass; vert u, sizing; edge
// rest angle, damage; face thickness, Fp, Sp, damage, derived rest data), else "<element> <index>: <problem>"
// (0-based index). check_mesh's require_finite_state, on its own: cheap enough to guard every file write.
std::string nonfinite_state(const Mesh& mesh);

// A rest triangle counts as degenerate (zero area) when twice its area is at most this fraction of its longest
// edge squared (about the sine of its smallest angle): the scale-free test shared by validate_triangles,
// check_mesh and the topology edits, so that no edit creates a face the checks reject.
constexpr double kDegenerateRelativeArea = 1e-12;
bool rest_triangle_degenerate(const Vec3& u0, const Vec3& u1, const Vec3& u2);

// Number of connected pieces of the sheet: live faces joined through shared (interior) edges.
int count_components(const Mesh& mesh);

}  // namespace arcsim
