// The stress that breaks a sheet (paper §4.1, Eq. 1, 2, 8): per face, the membrane stress of the elastic
// deformation, with bending fracture's extra surface strain, and only its tensile part.
//
//   F_el = F Fp                    the elastic deformation gradient (stretching plasticity, Face::Fp);
//   F_B  = F_el (I + 1/2 alpha h II*)   Eq. 8, alpha = Material::fracture_bending_mult, h = Face::thickness
//                                  (current, plastically thinned), II* = the face's elastic second fundamental
//                                  form with negative eigenvalues reversed (|eigenvalues|): bending in either
//                                  direction stretches one surface of the sheet;
//   G    = (F_B^T F_B - I) / 2     Green strain in the face's material frame (2x2);
//   sigma = membrane stress of G   Eq. 2, with the face's thickness-scaled, damage-weakened stiffness (N/m);
//   sigma+                         negative eigenvalues clamped to zero: compression never breaks.
//
// II of a face is its elastic part only, from its three hinges: the bending tensor (remesh/sizing.hpp's
// face_bending_tensor, sum of theta_e l_e n_e n_e^T / 2A) of each edge's elastic angle, world dihedral minus
// rest_theta (the rest dihedral plus bending plasticity's offset), 0 on a border edge. These are the angles the
// bending elements' energy sees, so a sheet resting in its curved or plastically bent shape reads no bending,
// on the border faces of a crack's lips too (ARCSim also builds its bending-fracture curvature from the hinge
// angles, world minus material space). WHY not the derivative of the node normals minus the plastic hinges'
// tensor (what it was): on a crack's lips the two disagreed (a border node's normal averages one side only, a
// border edge has no plastic hinge), and the plastically folded tube of paper Fig. 9 read elastic curvatures of
// 1e3 1/m on its new lip faces and cracked on in parallel slivers (docs/stability.md, 2026-12-05 evening).
// With alpha = 0 the bending term is skipped entirely (F_B = F_el).
// Sign: II > 0 along a direction in which the sheet bends away from its normal side (the normals spread, as on
// a sphere with outward normals); dihedral angles (mesh.hpp) are negative where it bends towards it, and the
// bending tensor of the angles has their sign, so the plastic offsets cancel the world angles of a sheet resting
// in its plastic shape (tested: fracture_stress_test, PlasticCurvatureIsSubtracted).
//
// Units: sigma in N/m (force per unit length of the sheet's mid-surface); divide by h for Pa.
#pragma once

#include <vector>

#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "physics/material.hpp"

namespace arcsim {

// Elastic second fundamental form (1/m, 2x2 symmetric, face material frame) of face f, before the eigenvalue
// reversal: the bending tensor of its hinges' elastic angles (see above).
Mat2 face_elastic_curvature(const Mesh& mesh, int f);

// The tensile fracture stress of one face.
struct FaceFractureStress {
  Mat2 sigma = Mat2::Zero();   // sigma+ (N/m), face material frame (Face::rest_frame columns t1, t2)
  double lambda_max = 0;       // its largest eigenvalue (N/m), >= 0
};

// sigma+ of face f.
FaceFractureStress face_fracture_stress(const Mesh& mesh, const std::vector<Material>& materials, int f);

// sigma+ of every face (indexed like mesh.faces; dead faces and faces of unbreakable materials, toughness 0,
// get zero). OpenMP-parallel over faces, deterministic.
std::vector<FaceFractureStress> fracture_stresses(const Mesh& mesh, const std::vector<Material>& materials);

// The same for a subset of faces only (others left as they are in `out`, which is resized to mesh.faces): the
// cost follows the subset.
void update_fracture_stresses(const Mesh& mesh, const std::vector<Material>& materials,
                              const std::vector<int>& faces, std::vector<FaceFractureStress>& out);

// Area toughness tau = toughness * h (N/m) of a face (0: unbreakable).
double face_toughness(const Face& face, const Material& material);

// The stress (N/m) as a rest-space 3x3 tensor R sigma R^T (R = Face::rest_frame).
Mat3 stress_to_rest(const Face& face, const Mat2& sigma);

}  // namespace arcsim
