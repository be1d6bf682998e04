// Local topology edits of the sheet mesh, used by remeshing (split, flip, collapse) and fracture (node split
// along a crack).
//
// All edits work in the edit phase: removed elements become tombstones and new ones are appended, so every
// index a caller holds stays valid (callers compact() later). Faces whose corners change are removed and
// re-added (new index, same state), so a caller tracks faces through the EditResult.
// An edit that is refused returns ok = false and leaves the mesh untouched; an edit that succeeds leaves the
// mesh manifold, oriented, free of degenerate rest triangles, with current rest data and finite state
// (check_mesh() passes if it passed before).
// Derived per-node data (mass) is not recomputed: new nodes get an interpolated or copied mass as a placeholder
// until the caller's next update of masses.
#pragma once

#include <vector>

#include "mesh/mesh.hpp"

namespace arcsim {

struct EditResult {
  bool ok = false;
  std::vector<int> added_nodes, added_verts, added_edges, added_faces;
  std::vector<int> removed_nodes, removed_verts, removed_edges, removed_faces;
};

// Splits `edge` at parameter t in (0, 1): a new node at (1-t)*n0 + t*n1 (x, x0, v, a interpolated; label kept
// if both ends share it, else 0), one new rest vert per distinct pair of side verts (a seam edge gets one per
// side), each adjacent face replaced by two with the parent's material, thickness, Fp, Sp and damage. The two
// halves of the edge copy its rest_theta, damage and preserve; the new edges inside the old faces get
// rest_theta = rest dihedral and damage = the face's damage. Refused for t outside (0, 1) or a child face that
// would be degenerate in rest space.
EditResult split_edge(Mesh& mesh, int edge, double t);

// Replaces the diagonal of the two faces of `edge` by the other diagonal. Only for an interior, non-seam,
// non-preserved edge between faces of one material; refused if the other diagonal already exists or a new face
// would be degenerate or inverted in rest space (its rest normal turned by more than 60 degrees from either old
// face: an inversion on a flat sheet, a face standing across a curved one). New faces get the area-weighted average thickness, Fp, Sp,
// damage; the new edge rest_theta = rest dihedral. The four outer edges keep their plastic offset
// (rest_theta minus rest dihedral) while their rest dihedral follows the new faces.
EditResult flip_edge(Mesh& mesh, int edge);

// Merges node edges[edge].n[remove_side] into the other end (which keeps its position and state). Refused when
// the edge or the removed node is preserved, the removed node touches a preserved edge, the removed node is on
// the boundary but the edge is not, the link condition fails (common neighbours other than the edge's
// opposite nodes), a duplicate face would appear, a node would be left without faces, the removed node's rest
// verts cannot be mapped onto the kept node's (a seam through the removed node not along the edge), or a
// surviving face would become degenerate or inverted in rest space (normal turned by more than 60 degrees).
// Surviving faces keep their state; edges whose wings change keep their plastic offset (see flip_edge).
EditResult collapse_edge(Mesh& mesh, int edge, int remove_side);
// The first of those rules, which read flags and boundaries only (a live edge, nothing preserved, a boundary
// node removed only along a boundary edge): false means collapse_edge refuses the edit. For callers that would
// otherwise pay for costlier checks (the edit session's world guard) before collapse_edge says no.
bool collapse_edge_precheck(const Mesh& mesh, int edge, int remove_side);

// Vertex split for a crack at `node` along 1 or 2 interior `cut_edges` incident to it. The cut edges (and, for a
// boundary node, the boundary) divide the faces around the node into sectors; one sector stays with the node and
// every other one moves to a new copy of it, with new rest verts. What moves: interior node, the sector walking
// CCW from cut_edges[0] to cut_edges[1]; boundary node with one cut, the sector walking CCW from the cut edge to
// the boundary; boundary node with two cuts, both sectors after the first cut in CCW order from the boundary
// (two copies). Each cut edge becomes two boundary edges (copies of rest_theta, damage, preserve). A far end of
// a cut edge that was already on the boundary would become a bow-tie, so it is split too (its part on the moving
// side goes to a copy). New nodes copy x, x0, v, a, label and mass; every split node and copy gets
// preserve = true. added_nodes lists the copies of `node` first, then those of far ends. Refused for an edge
// that is not incident, already on the boundary, repeated, more than two edges, or a single cut edge at an
// interior node.
EditResult split_node(Mesh& mesh, int node, const std::vector<int>& cut_edges);

// One face around a node: the node is corner `corner` of `face`; edge_out joins it to the next corner,
// edge_in to the previous one. Walking from edge_out to edge_in turns counter-clockwise about the rest normal.
struct FanCorner {
  int face = kNone, corner = kNone, edge_out = kNone, edge_in = kNone;
};
struct NodeFan {
  std::vector<FanCorner> corners;  // CCW; consecutive corners share edge_in / edge_out
  bool closed = false;             // interior node (no boundary edge)
};
// The faces around `node` in CCW order; an open fan starts at the face whose edge_out is on the boundary.
// Returns false if the node has no faces or they do not form one consistently oriented fan.
bool node_fan(const Mesh& mesh, int node, NodeFan& fan);

}  // namespace arcsim
