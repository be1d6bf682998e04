// Separation strength of a node (paper §4.1, Eq. 5-7, Fig. 4): how much tensile stress a split of the node
// along a plane would relieve, maximised over sampled planes.
//
// The fan of faces around the node is unfolded into a flat disc (or wedge, at a node on the sheet's border or
// on a crack) by the faces' rest corner angles at the node, in CCW order; each face's sigma+ (piecewise
// constant, fracture/fracture_stress.hpp) is rotated into the unfolded frame. A candidate split is
//   - at an interior node: a full plane, the two rays at unfolded angles phi and phi + (total angle)/2;
//   - at a node on a border or crack: one ray at angle phi into the material; the existing border edges are the
//     split's second hand (Fig. 4 right), so a crack tip propagates forwards and never cracks back.
// The split divides the fan into two sectors; q_k = sum over the sector's face pieces of sigma_i (the integral
// of the outward unit normal over that piece of the unit circle's arc) is the traction across the disc boundary
// of sector k (Eq. 5, 6). With q^ = (q1 - q2)/|q1 - q2|, Eq. 7 gives s = min(q1.q^, -q2.q^) (N/m): the
// smallest common component, so an unbalanced load (rigid motion) does not break.
//
// Normalisation (what makes `toughness` a strength in Pa, as in ARCSim, on any fan): for a uniform uniaxial
// stress sigma n n^T across a split (n the normal of its first ray), s = sigma * c(plane), where c depends only
// on the fan's geometry and the plane: c = 2 at an interior node (the unit disc's diameter), 1 for a straight
// border with a perpendicular cut, 2 at a crack tip cut straight ahead. The node's factor c is the largest
// c(plane) over its sampled planes (refined near the best sample), and the reported strength is s / c: uniform
// uniaxial stress sigma breaks every node, interior or border, exactly when sigma > tau, so onset does not depend
// on the mesh. (Dividing each plane's s by its own c(plane) instead would reward grazing rays: on a straight
// border loaded along it, s / c(plane) = sigma sin(phi) / (1 - |cos(phi)|) grows to 2.6 sigma at the grazing
// limit, and at a crack tip under mode I it is sigma for every ray, so nothing would prefer straight ahead.)
// Planes with c(plane) below kMinGeometryFactor (a ray grazing a border) and planes whose rays lie in an
// unbreakable face (toughness 0) are not candidates.
//
// Sampling: `samples` angles uniformly over the fan's total angle (200 as in the paper); the per-face arc
// integrals up to each face are precomputed (prefix sums), so a sample costs two look-ups. Interior planes repeat
// after half the total angle: the distinct planes are 360/200 = 1.8 deg apart; border rays total/200 apart.
// Cheap skip (as ARCSim): a node whose faces' largest eigenvalue of sigma+ is below half the fan's smallest
// toughness is not evaluated. Since s <= lambda_max * (total angle) / 2, this never skips a breaking node when
// c >= total / 4: flat interior nodes, straight borders, crack tips; it may at sharp convex corners (a 90 deg
// corner has c = 0.29), where stress is rare.
#pragma once

#include <vector>

#include "fracture/fracture_stress.hpp"
#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "physics/material.hpp"

namespace arcsim {

constexpr double kMinGeometryFactor = 0.25;

// One hand of a split plane: a ray from the node into `face` (one of the node's faces), along the rest-space
// unit `direction`, which lies in the face's rest plane between (or on) its two edges at the node.
struct CutRay {
  int face = kNone;
  Vec3 direction = Vec3::Zero();
};

struct NodeSeparation {
  int node = kNone;
  double strength = 0;     // s / c (N/m), see above; 0 when skipped or no candidate plane
  double raw = 0;          // s of Eq. 7 (N/m) for the best plane
  double factor = 0;       // the node's geometric factor c (dimensionless), see above
  double toughness = 0;    // tau (N/m) of the faces the best plane cuts (their mean area toughness)
  bool on_boundary = false;
  std::vector<CutRay> rays;  // the best plane: 2 rays at an interior node, 1 at a border / crack node
  bool breaks() const { return toughness > 0 && strength > toughness; }
  double ratio() const { return toughness > 0 ? strength / toughness : 0; }
};

struct SeparationOptions {
  int samples = 200;
  // For callers that keep only the nodes that break: a node whose sampled bound (raw over the sampled geometry
  // factor, which the refined factor can only raise) shows that it does not break returns as a skipped node
  // (strength 0, no rays) without refining its factor. Breaking nodes get the full result.
  bool breaking_only = false;
};

// The separation strength of `node` and its best plane, from the faces' sigma+ (indexed like mesh.faces).
// A node without faces, with an inconsistent fan, or whose faces are all unbreakable gets strength 0.
NodeSeparation node_separation(const Mesh& mesh, const std::vector<Material>& materials, int node,
                               const std::vector<FaceFractureStress>& stress, const SeparationOptions& options = {});

}  // namespace arcsim
