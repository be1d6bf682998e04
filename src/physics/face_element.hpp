// The one place where a face's element data is set up from the mesh and its material: rest frame (Dm_inv with
// the plastic stretch), rest area, membrane and bending stiffness with thickness and damage weakening, and the
// lumped masses. The full implicit step (cloth_physics), the zone solve (zone_solve), the world reprojection
// of remeshing, the plastic embedding and the stretching flow rule all call these functions, so a change of
// how an element is built (a new per-element field, a new weakening law) is made here once.
//
// Free functions over Eigen types; nothing here owns state. Every function performs exactly the floating-point
// operations, in the order, that its callers used to perform inline (frames stay byte-identical).
#pragma once

#include <array>
#include <vector>

#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "physics/material.hpp"

namespace arcsim {

// Stiffness factor 1 / (1 + weakening * damage) of a damaged element (dimensionless).
double damage_weakening(const Material& material, double damage);

// A bending stiffness (N m) weakened by `damage`: kb / (1 + weakening * damage).
double weakened_bending_stiffness(double kb, const Material& material, double damage);

// Whether the membrane stiffness of a face is weakened by its damage. The physics, reprojection and flow rules
// weaken it; the plastic embedding (plasticity/plastic_embedding.cpp) measures Eq. 12 with the undamaged one.
enum class MembraneWeakening { kApplied, kIgnored };

// Membrane stiffness (N/m) of a face: the material's, scaled by the face's thickness, weakened by its damage.
MembraneStiffness face_membrane_stiffness(const Face& face, const Material& material,
                                          MembraneWeakening weakening = MembraneWeakening::kApplied);

// Plastic stretch Fp (2x2) of a face expressed in its material frame (exactly the identity when Fp is).
Mat2 face_plastic_stretch_2d(const Face& face);

// The membrane's rest measure of a face: Dm_inv * Fp2 (1/m), so that F Dm_inv Fp2 = F_el (F_el = F Fp).
Mat2 face_elastic_dm_inv(const Face& face);

// Mass (kg) a face lumps onto each of its three corners: area density * rest area / 3.
double face_corner_mass(const Face& face, const Material& material);

// Plate-bending matrix Q (J/rad^2, see physics/plate_bending.hpp) of face f, with the direction-dependent
// bending stiffness sqrt(kb_i kb_j) of its edges, each weakened by the edge's damage. `has_wing` says which
// edges have a hinge (the caller's choice: a mesh neighbour, or one that is also embedded).
Mat3 face_bending_matrix(const Mesh& mesh, const Material& material, int f, const std::array<bool, 3>& has_wing);

// Membrane element of one face: F_el = [x1-x0, x2-x0] Dm_inv.
struct FaceElement {
  std::array<int, 3> nodes;   // mesh nodes, in the face's corner order (positions are read from them)
  std::array<int, 3> dofs;    // rows of the linear system (-1: held fixed); the nodes in the full step
  std::array<int, 9> blocks;  // block ids of the dof pairs in the system's pattern (-1: not assembled)
  Mat2 Dm_inv;                // 1/m, includes the plastic stretch: F_el = F Fp
  double area;                // rest area (m^2)
  MembraneStiffness k;        // N/m, thickness-scaled and weakened
  double damping;             // stiffness-proportional damping beta (s)
};

// Plate bending of one face (physics/plate_bending.hpp): corners then the wings across its three edges.
struct BendingElement {
  std::array<int, 6> nodes;   // c0, c1, c2, w0, w1, w2 (a missing wing repeats c0; has_wing says which)
  std::array<int, 6> dofs;    // rows of the linear system (-1: held fixed)
  std::array<bool, 3> has_wing;
  std::array<int, 36> blocks;
  Vec3 rest_theta;            // rad, per edge
  Mat3 Q;                     // J/rad^2, see plate_bending_matrix
  double damping;             // beta (s)
};

// The faces whose bending element reads node n (sorted): its own faces and the faces across the edges opposite
// it (n is their wing). Its membrane elements are those of Mesh::node_faces.
std::vector<int> bending_faces_of_node(const Mesh& mesh, int n);

// The elements of face f with dofs = nodes and no block ids yet.
FaceElement make_face_element(const Mesh& mesh, const std::vector<Material>& materials, int f);
BendingElement make_bending_element(const Mesh& mesh, const std::vector<Material>& materials, int f);

}  // namespace arcsim
