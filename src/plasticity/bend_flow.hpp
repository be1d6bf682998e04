// Bending plasticity of one face: paper Eq. 10 (Narain et al. 2013) with ARCSim's damage rule.
//
//   S_el = 1/(2A) sum_i (theta_i - rest_theta_i) l_i n_i n_i^T        (Eq. 3, 1/m; world dihedrals theta_i
//                                                                     against the edges' rest + plastic angles)
//   if |S_el| > kappa_0:  Sp <- Sp + S_el/|S_el| (|S_el| - kappa_0),   damage <- damage + |S_el|/kappa_0 - 1
// with |.| the Frobenius norm and kappa_0 = yield_curv (1/m). The edges' rest angles are then rebuilt from Sp
// (plastic_tensors.hpp), which the caller does once for all changed faces.
#pragma once

#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "physics/material.hpp"

namespace arcsim {

// True if the material has bending plasticity (finite yield_curv).
bool has_bending_plasticity(const Material& m);

// Elastic bending strain S_el of face `face` (rest space 3D, in the rest tangent plane, 1/m): Eq. 3 with the
// world dihedral angles measured against Edge::rest_theta. Boundary edges contribute nothing.
Mat3 face_elastic_bending_strain(const Mesh& mesh, int face);

// The Eq. 10 increment of Sp for an elastic strain S_el and yield curvature kappa_0 (zero below yield).
Mat3 bend_flow_increment(const Mat3& S_el, double yield_curv);

struct BendFlowResult {
  bool changed = false;
  double work = 0;    // J, plastic work of this update (see plastic_step.hpp)
  double excess = 0;  // |S_el| / kappa_0 - 1 (> 0 when the face yielded), the damage added
};

// Applies Eq. 10 to face `face` (material `m`): updates Sp and damage of the face only (not its edges).
BendFlowResult apply_bend_flow(Mesh& mesh, int face, const Material& m);

}  // namespace arcsim
