// Local world-space reprojection after a remeshing operation (paper §5.2, Eq. 13): the changed node's world
// position x minimises
//   E_s(x) = sum over its elements of (membrane + plate bending energy) + m (a - g) . x
// with every other node fixed. The elements are the faces incident to the node (membrane and bending) and the
// faces that have the node as a bending wing; m is the node's lumped mass from its faces, a the acceleration of
// the last physics step (interpolated by the edit) and g the gravity. WHY the gravity: the paper's m a . x term
// keeps the node's acceleration; with gravity included the node's elastic force balances m (a - g), so a sheet
// hanging at rest keeps carrying its own weight instead of sagging once per remesh.
// Solved by Newton's method on the 3 unknowns with a backtracking line search (a few iterations).
#pragma once

#include <vector>

#include "mesh/mesh.hpp"
#include "physics/material.hpp"

namespace arcsim {

struct ReprojectionParams {
  Vec3 gravity = Vec3::Zero();  // m/s^2
  int max_iterations = 10;
  // Farthest the node may move across the sheet (m, along its mean world normal). The solve sees only the
  // node's own elements, so a long move can carry its faces through a nearby layer of the same sheet (measured
  // on ARCSim's sphere.json: every cloth self-intersection in the first 0.7 s appeared at a reprojection).
  // Half the repulsion thickness cannot cross a layer that the proximity forces keep a thickness away.
  double max_displacement = kInfinity;
};

// The energy E_s (J) of node `node` at world position x, its gradient (N) and a positive semi-definite Hessian
// (N/m), for tests and the solver.
struct LocalEnergy {
  double energy = 0;
  Vec3 gradient = Vec3::Zero();
  Mat3 hessian = Mat3::Zero();
};
LocalEnergy node_local_energy(const Mesh& mesh, const std::vector<Material>& materials, int node, const Vec3& x,
                              const ReprojectionParams& params);

struct ReprojectionResult {
  bool moved = false;     // the position changed
  int iterations = 0;
  double energy_before = 0, energy_after = 0;  // J, the load term m (a - g) . (x - x_start)
};

// Moves nodes[node].x to the minimiser of E_s; x0 moves by the same displacement (the motion of the step is
// kept). Leaves the node where it was if no step lowers the energy.
ReprojectionResult reproject_node(Mesh& mesh, const std::vector<Material>& materials, int node,
                                  const ReprojectionParams& params);

}  // namespace arcsim
