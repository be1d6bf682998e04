// Conversions between the per-face plasticity tensors and per-edge plastic rest angles (paper Eq. 3 and 11).
//
// Representation (shared by the flow rules and the remeshing transfer):
//  - Face::Sp is the source of truth for bending plasticity. It is a symmetric 3x3 tensor in the face's rest
//    tangent plane (1/m): Sp = 1/(2A) sum_i d_i l_i n_i n_i^T over the face's edges i (edge i joins corners i and
//    i+1), with l_i the rest edge length, n_i = (u_{i+1} - u_i) x rest_normal / l_i the unit in-plane edge normal
//    (the same vectors physics/plate_bending uses, so Sp and the bending energy agree) and d_i = theta^p_i -
//    theta^R_i the plastic offset of the edge's rest angle from the geometric rest dihedral (rad).
//  - Edge::rest_theta = Mesh::rest_dihedral(e) + mean of the offsets its faces imply (one face on a boundary).
//  - Face::Fp is the 3D embedding of a 2x2 in-plane tensor: R Fp2 R^T + n n^T with R the face's rest_frame.
#pragma once

#include <vector>

#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "physics/face_element.hpp"  // face_plastic_stretch_2d

namespace arcsim {

// Sp (1/m, rest space 3D) of `face` for per-edge plastic offsets (rad) in the face's edge order (Eq. 11 / 3).
Mat3 face_bending_strain_from_offsets(const Mesh& mesh, int face, const Vec3& offsets);

// The inverse: the three per-edge offsets (rad) whose tensor is the in-plane part of S. Zero for a degenerate
// face (no rest area) or for S = 0.
Vec3 face_offsets_from_bending_strain(const Mesh& mesh, int face, const Mat3& S);

// Sets edge.rest_theta = rest_dihedral + mean face offset for the given edges (all live edges if empty).
void update_edge_rest_angles_from_Sp(Mesh& mesh, const std::vector<int>& edges);

// Sets edge.damage to the mean damage of its live faces, as ARCSim does (all live edges if empty).
void update_edge_damage_from_faces(Mesh& mesh, const std::vector<int>& edges);

// The 3D embedding of a face's 2D plastic tensor (face_plastic_stretch_2d, physics/face_element.hpp, is the
// other way).
Mat3 face_plastic_stretch_3d(const Face& face, const Mat2& Fp2);

}  // namespace arcsim
