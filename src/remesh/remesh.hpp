// Adaptive anisotropic remeshing of a sheet (paper §5, Narain et al. 2012; facts §5.3): edge splits, flips and
// collapses driven by the sizing metric (remesh/sizing.hpp), over the whole mesh or a subset of faces.
//
// One pass:
//  1. vert sizing from the current state (area-weighted mean of face metrics);
//  2. anisotropic Delaunay flips (Bossen-Heckbert) on independent edge sets;
//  3. rounds of splits: every edge of metric length > 1, longest first, at its midpoint; flips around each;
//  4. rounds of collapses: edges of metric length < 1, shortest first, either end, under ARCSim's quality
//     rules (see can_collapse in remesh.cpp); flips around each.
// The remesher only chooses: sizing, which edge to edit and in which order. Every edit goes through an edit session
// (edit/edit_session.hpp), which projects new rest positions onto the cloth's reference surface, sets rest angles
// (plastic offset + the reference's rest dihedral, so a curved rest shape stays curved), carries the plastic state
// (local plastic embedding), reprojects the changed node (paper Eq. 13) and, with a world clearance, keeps every
// edit and move from bringing the surface into another one (remesh/world_guard.hpp). Loops are bounded (rounds,
// flips per call, face count). The mesh is left with tombstones: the caller compacts.
#pragma once

#include <vector>

#include "edit/edit_session.hpp"
#include "mesh/mesh.hpp"
#include "physics/material.hpp"
#include "remesh/reprojection.hpp"
#include "remesh/sizing.hpp"
#include "restshape/reference_surface.hpp"

namespace arcsim {

struct RemeshOptions {
  SizingParams sizing;    // remeshing parameters (sizes, refine_*, aspect_min) and magic knobs
  SizingExtras extras;    // hooks: fracture / obstacle terms, plastic transform, uniform size
  double edge_flip_threshold = 1e-2;   // magic.edge_flip_threshold: flip when sin(sum of opposite angles) < -this
  const ReferenceSurface* reference = nullptr;  // where new rest positions go; nullptr: left on the chord
  bool reproject = true;               // world-space reprojection after every split / collapse
  ReprojectionParams reprojection;
  // Collapses and flips may change the world surface, beyond what the rest surface changes (the plastic shape
  // where the neighbourhood holds plastic state, see should_flip), by at most this
  // fraction of the edge's rest length: the removed node's distance to the new faces, the distance between the
  // quad's diagonals (world minus rest). WHY: the sizing lets an edge bend by up to refine_angle, and flattening
  // such a wrinkle in one remesh is a visible pop (ARCSim's square-pop scene). <= 0: no limit.
  double max_surface_change = 0.005;
  // World-space guard (remesh/world_guard.hpp): an edit's new triangles keep this clearance (m) from every
  // surface they do not touch (the mesh itself and `obstacles`), or come no closer than before. <= 0: off.
  double world_clearance = 0;
  std::vector<const Mesh*> obstacles;  // other surfaces the edits may not approach: obstacles, other cloths
  WorldGuard* shared_guard = nullptr;  // see EditSessionOptions::shared_guard
  std::vector<EditObserver*> observers;  // told about every edit of the pass (edit/edit_session.hpp)
  int max_rounds = 30;                 // split rounds and collapse rounds, each
  // A collapse round asks again only the edges whose neighbourhood an edit touched since they were last turned
  // down (the same answers as asking every edge: tests compare the two). false: every edge in every round.
  bool remember_refused_collapses = true;
  size_t max_faces = 2000000;          // no split beyond this many live faces (a safety net, not a size control)
};

// What a pass did: the edit session's counts (edit/edit_session.hpp; node_splits stays 0, remeshing makes none)
// and the live faces of the active region after the pass: the subset's surviving faces plus every face created
// (all live faces when no subset was given), indices before compaction.
struct RemeshStats : EditCounts {
  std::vector<int> active_faces;
};

// The edit session options of remeshing (reference surface, plastic transfer, reprojection, world guard):
// fracture's openings use the same.
EditSessionOptions edit_session_options(const RemeshOptions& options);

// Remeshes `mesh` (whole mesh, or only the edges of the faces in `face_subset` when it is not null; the edits
// may still change faces just outside, as a split of a border edge must).
RemeshStats remesh_mesh(Mesh& mesh, const std::vector<Material>& materials, const RemeshOptions& options,
                        const std::vector<int>* face_subset = nullptr);

// Anisotropic Delaunay test of an interior edge (Bossen-Heckbert) in the mean metric of its four verts, with the
// flip restrictions of facts §5.3 (no boundary / seam / preserved edge, world dihedral and flipped rest and
// world dihedral below 40 degrees, no world-space inversion) and the world-surface limit (see
// RemeshOptions::max_surface_change). Uses the verts' current sizing. With `materials`, a neighbourhood holding
// plastic state measures the surface change against its plastic shape (the local plastic embedding) instead of
// the rest positions: a plastically bent sheet rests in that shape, not in its flat reference.
bool should_flip(const Mesh& mesh, int edge, double threshold, double max_surface_change = 0,
                 const std::vector<Material>* materials = nullptr);

// Mean ratio quality 12 sqrt(3) area / perimeter^2 of a triangle (1 for equilateral, 0 for degenerate).
double triangle_aspect(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace arcsim
