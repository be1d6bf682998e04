// Which triangles of a scene's sheets cross each other or an obstacle, exactly (triangle_intersection.hpp), with
// bounding-volume hierarchies so the cost follows the overlapping pairs, not the square of the face count. A
// checking tool for results (`arcsim inspect`, the tests' no-intersection invariant), not part of the time step.
#pragma once

#include <vector>

#include "mesh/mesh.hpp"

namespace arcsim {

struct IntersectingPair {
  int sheet_a = 0, face_a = 0;  // a live face of sheets[sheet_a]
  // The other face: of sheets[sheet_b] when `obstacle` is false, of obstacles[sheet_b] when it is true.
  int sheet_b = 0, face_b = 0;
  bool obstacle = false;
};

// Every pair of live faces, in world positions, that shares a point: within each sheet (faces sharing a node are
// adjacent and skipped), between any two sheets, and between a sheet and an obstacle (obstacles among
// themselves are not checked). Sorted (sheet_a, face_a, obstacle, sheet_b, face_b), so the result does not
// depend on the thread count.
std::vector<IntersectingPair> intersecting_pairs(const std::vector<const Mesh*>& sheets,
                                                 const std::vector<const Mesh*>& obstacles);

}  // namespace arcsim
