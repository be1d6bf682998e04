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
// Refused (nothing changes) when the cut would need a face or edge smaller than the sliver limits, follow an
// edge that is already a border, or leave an invalid mesh; the reason is returned.
#pragma once

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
  double sliver = 0.05;           // refused: an edge shorter than sliver * size_min, a face of area below
                                  // (sliver * size_min)^2
};

struct CrackOpening {
  bool ok = false;
  std::string refused;           // why, when !ok
  std::vector<int> crack_edges;  // the edges the crack follows (before the node split)
  std::vector<int> tips;         // far ends of the crack edges: the new crack tips, candidates next substep
  std::vector<int> nodes;        // the split node and the copies split_node made
  int edge_splits = 0, snaps = 0;
};

CrackOpening open_crack(EditSession& session, int node, const std::vector<CutRay>& rays,
                        const CrackOpeningOptions& options);

}  // namespace arcsim
