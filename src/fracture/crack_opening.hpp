// Crack opening (paper §4.1): splits a node along a chosen plane, through the edit session
// (edit/edit_session.hpp) like every other topology edit.
//
// For each ray of the plane (fracture/separation_strength.hpp's CutRay): the ray leaves the node inside one
// face; it either runs along one of that face's edges at the node (within the snap angle), and the crack
// follows that edge; or it crosses the face's opposite edge at parameter t. A crossing within the snap
// distance of an end of that edge snaps the crack to the edge from the node to that end (no sliver faces);
// otherwise the opposite edge is split at t (EditSession::split_edge) and the crack follows the new edge.
// Then the node is split along the crack edge(s) (EditSession::split_node), which also separates far ends that
// already were on a border (no bow-ties where a crack reaches the border or another crack). The session
// reprojects the split nodes (Eq. 13) locally.
//
// Mass and linear momentum are conserved exactly (up to round-off): a split edge's new node interpolates the
// velocity linearly at t, which is what the lumped masses redistribute; a node split copies the velocity.
// Refused when the cut would need a face or edge smaller than the sliver limits, follow an edge that is already
// a border, put both rays on one edge, when a lip of the split could not be set lip_gap apart (checked through
// the session's world guard before the node split: lips left coincident have no contact normal, and their faces
// cross once a later edit removes the node they share), when the lips, set apart, would cross each other (where a
// crack reaches a border, the twin pairs at its two ends can be set apart in directions that cross the two lips'
// edges in an X, which no contact normal parts; checked before the split on the faces around it, moved as the
// lips will be), or the session refuses an edit; the reason is returned.
// A refused node is not tried again in the same fracture pass (fracture_step.hpp); the next step may retry it. Every check that
// needs no edit runs on all rays before the first edit, so a refusal normally changes nothing. Only when the
// session refuses a later step after the first ray's edge split succeeded (or the second ray's plan changes
// because of that split) does a refused opening leave that split in place: mesh_changed says so, and the mesh
// is valid (a split edge alone is an ordinary remeshing edit).
//
// Snap rule, per ray, in the face it leaves through (rest space):
//   1. the ray is within snap_angle of one of the face's two edges at the node: follow that edge;
//   2. else it crosses the opposite edge at t (from the end of the face's edge_out); if t < snap_fraction and
//      t * |opposite edge| < snap_distance * size_min, follow the edge to that end (likewise 1 - t for the
//      other end); with size_min = 0 rule 2 never snaps;
//   3. else split the opposite edge at t, unless an edge of the split is shorter than sliver * size_min or a
//      child face (either side of the opposite edge) has an area below (sliver * size_min)^2.
// Unlike ARCSim, a snap never slides the end vertex onto the cut: rest positions only move through the session.
// A ray's face is a hint: if it is dead, lacks the node or does not hold the direction, the node's face that
// holds it is used (this also follows a ray into the children of a face split for the other ray).
//
// Preserve flags: split_node marks the node, its copies and split far ends preserved; the new tips (far ends
// that were interior) are not touched: a driver that wants them kept by remeshing marks them itself.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "edit/edit_session.hpp"
#include "fracture/separation_strength.hpp"
#include "mesh/mesh.hpp"

namespace arcsim {

struct CrackOpeningOptions {
  double size_min = 0;            // m: the cloth's remeshing size_min (sliver limits scale with it)
  double snap_angle = 5 * M_PI / 180;  // rad: a ray this close to an existing edge follows that edge
  double snap_fraction = 0.2;     // a crossing within this fraction of the opposite edge from an end snaps...
  double snap_distance = 0.1;     // ...if it is also within this many size_min of that end (rest space)
  // The lips of a new crack start this far apart (m; each side moves half of it, in the sheet's plane, away
  // from the crack): coincident lips have no defined contact normal, so collision handling could not keep
  // them apart. 0: the lips start coincident.
  double lip_gap = 2e-6;
  double sliver = 0.05;           // refused: an edge shorter than sliver * size_min, a face of area below
                                  // (sliver * size_min)^2
  // Refused: an opening that would cut off a piece of fewer faces. A shard of one or two triangles is below
  // any resolution the sheet has, and it starts coincident with the faces it broke from, an in-plane contact
  // that collision handling cannot resolve (paper-tearing.json, frame 1101: a one-triangle shard at the tip).
  int min_piece_faces = 4;
};

struct CrackOpening {
  bool ok = false;
  std::string refused;           // why, when !ok
  std::vector<int> crack_edges;  // the edges the crack follows (before the node split)
  std::vector<int> tips;         // far ends of the crack edges that were interior: the new crack tips (now on a
                                 // crack lip), candidates next substep; far ends already on a border are split
                                 // with the node instead (the crack reached the border) and are not tips
  std::vector<int> nodes;        // the split node and its copies
  // Far ends already on a border that split_node split with the node: {far end, its copy}. Their halves are
  // set lip_gap apart like the node's (coincident halves have no contact normal: paper-tearing.json, step 966).
  std::vector<std::array<int, 2>> far_ends;
  // Every node the opening split: `nodes`, then both halves of each far end. They all start coincident with a
  // twin, so their lips are set apart and their neighbourhoods count as touched by the opening.
  std::vector<int> split_nodes() const {
    std::vector<int> out = nodes;
    for (const std::array<int, 2>& twins : far_ends) out.insert(out.end(), twins.begin(), twins.end());
    return out;
  }
  int edge_splits = 0, snaps = 0;
  bool mesh_changed = false;     // an edit succeeded (true when ok; see above for when it is true and !ok)
};

CrackOpening open_crack(EditSession& session, int node, const std::vector<CutRay>& rays,
                        const CrackOpeningOptions& options);

}  // namespace arcsim
