// Zone physics: one implicit Euler step (the full step's linearised backward Euler, physics/cloth_physics.hpp)
// over a set of nodes, the zone, with every other node held fixed. Fracture substepping solves many small zones
// around crack tips per step; this costs what the zone costs, not what the mesh costs.
//
// The zone's elements are the faces with a corner in the zone (membrane, wind) and the bending elements with a
// zone node among their six nodes; they are built with the same element builder (physics/face_element.hpp) and
// assembled by the same code (assemble_implicit_euler) as the full step, over the zone's free nodes only, on a
// block pattern of the zone, factored with the same CHOLMOD solver. The support, the nodes around the zone that
// the zone's elements read and that are held fixed (dv = 0: their positions and velocities enter as constants),
// is the n-ring of the zone (support_rings, n >= 1) plus the bending wings of the zone's elements (up to two
// rings out). The result equals the full step with every node outside the zone pinned (tests/physics/
// zone_solve_test.cpp) to solver precision.
//
// Work per solve: element gathering, building and assembly over the zone's elements; one symbolic analysis and
// factorisation of the zone's matrix. The loads' springs and contacts are scanned once (O(count log zone)).
#pragma once

#include <vector>

#include "mesh/mesh.hpp"
#include "physics/block_system.hpp"
#include "physics/cloth_physics.hpp"
#include "physics/face_element.hpp"
#include "physics/material.hpp"
#include "physics/system_dofs.hpp"

namespace arcsim {

struct ZoneSolveOptions {
  int support_rings = 1;  // rings of fixed support nodes listed around the zone (>= 1)
  // kNewtonFromRest: a Newton iteration of backward Euler started from rest, the mesh's nodes at the iterate
  // (x_0 + dt v_k, v_k; see assemble_implicit_euler): dv is the correction of v_k.
  Linearisation linearisation = Linearisation::kStep;
};

// The outcome of one zone step. The mesh is not changed by solve_zone: fracture evaluates a virtual update and
// rewinds it; apply_zone_solution (or zone_implicit_step) writes it.
struct ZoneSolution {
  std::vector<int> nodes;          // the zone's live nodes (sorted)
  std::vector<Vec3> dv;            // velocity change (m/s), per node (0 for nodes the loads pin)
  // v and x are the step's result (kStep) only: v + dv and x + dt (v + dv). With kNewtonFromRest the mesh's x
  // already holds the iterate x_0 + dt v_k, so the caller forms x_0 + dt (v_k + dv) itself.
  std::vector<Vec3> v;             // new velocity (m/s)
  std::vector<Vec3> x;             // new position x + dt v (m)
  std::vector<int> support_nodes;  // fixed nodes around the zone that it reads (sorted, none of the zone's)
  int face_elements = 0, bending_elements = 0;  // elements assembled
  StepTiming timing;
};

// One implicit step of size dt (s) over `zone_nodes` (any order; duplicates and dead nodes ignored) with the
// loads of the full step (gravity, wind, handle springs on zone nodes, contacts touching the zone). Zone nodes
// the loads pin keep their velocity (dv = 0) and are not rows of the system, as in the full step (nodes past
// the end of loads.pinned, added by edits after the loads were made, are free). Nodes outside
// the zone are not advanced. Leaves the mesh untouched. An empty zone gives an empty solution. Throws
// NumericalError if the zone's system cannot be factorised or the result is not finite.
ZoneSolution solve_zone(const Mesh& mesh, const std::vector<Material>& materials,
                        const std::vector<int>& zone_nodes, const ExternalLoads& loads, double dt,
                        CholeskySolver& solver, const ZoneSolveOptions& options = {});

// The structure of one zone's system: its nodes and rows, its elements (which hold rest-state quantities only)
// and their block pattern, built from the mesh's topology, rest state and the loads' pins and contacts. While
// those stay as they are and only positions and velocities change (fracture's Newton iterations of a virtual
// update), a zone solved repeatedly through one ZoneSystem builds them once, and the solver keeps the pattern's
// symbolic analysis (its id does not change): the same solutions as solve_zone's, bit for bit.
class ZoneSystem {
 public:
  ZoneSystem(const Mesh& mesh, const std::vector<Material>& materials, const std::vector<int>& zone_nodes,
             const ExternalLoads& loads, const ZoneSolveOptions& options = {});
  // solve_zone on the current positions and velocities. `loads` must pin the nodes and hold the contacts the
  // system was built with (gravity, wind and spring anchors may differ).
  ZoneSolution solve(const Mesh& mesh, const ExternalLoads& loads, double dt, CholeskySolver& solver) const;
  const BlockPattern& pattern() const { return pattern_; }

 private:
  ZoneSolveOptions options_;
  std::vector<int> nodes_;          // live zone nodes (sorted)
  SystemDofs dofs_;
  std::vector<FaceElement> faces_;
  std::vector<BendingElement> bending_;
  BlockPattern pattern_;
  std::vector<int> support_nodes_;
};

// Writes a zone solution into the mesh as the full step does for every node: v += dv, a = dv/dt, x0 = x,
// x += dt v, for the zone's nodes only.
void apply_zone_solution(Mesh& mesh, const ZoneSolution& solution, double dt);

// solve_zone then apply_zone_solution.
ZoneSolution zone_implicit_step(Mesh& mesh, const std::vector<Material>& materials,
                                const std::vector<int>& zone_nodes, const ExternalLoads& loads, double dt,
                                CholeskySolver& solver, const ZoneSolveOptions& options = {});

// The nodes within `rings` edge rings of `nodes` (the nodes themselves included), sorted: a way to make zones.
std::vector<int> node_rings(const Mesh& mesh, const std::vector<int>& nodes, int rings);

}  // namespace arcsim
