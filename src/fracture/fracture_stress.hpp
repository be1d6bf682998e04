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
// II of a face is the finite-element derivative of the world vertex normals (area-weighted face normals at each
// node), pulled back to the material frame: II = sym(F^T [n1-n0, n2-n0] Dm_inv) (1/m). The elastic part
// subtracts what the sheet rests in: the same derivative of the rest vertex normals (curved rest shapes: a
// glass sphere at rest does not crack) and the plastic curvature (the bending tensor of the edges' plastic
// angle offsets, rest_theta - rest dihedral, remesh/sizing.hpp's face_bending_tensor). With alpha = 0 the
// bending term is skipped entirely (F_B = F_el).
// A material with bending plasticity (finite yield_curv) measures II on the hinges instead: each face's bending
// tensor (face_bending_tensor) of its edges' elastic angles, world dihedral minus rest_theta (rest dihedral plus
// plastic offset), 0 on a border edge; averaged at each vert over its faces by rest area, and a face's II is the
// mean of its three corner verts' (rest space); ARCSim filters its bending-fracture curvature the same way. WHY:
// the plastic state lives on the hinges, so the elastic part must be measured with the same operator. The normal
// derivative minus the plastic hinges' tensor disagreed on a crack's lips (a border node's normal averages one
// side only, a border edge has no plastic hinge): the plastically folded tube of paper Fig. 9 read elastic
// curvatures of 1e3 1/m on its new lip faces and cracked on in parallel slivers (docs/stability.md, 2026-12-05
// evening). Elastic materials keep the normal derivative: with the hinge measure conf/paper-dome.json (acrylic)
// cracked differently and left 2 intersecting triangle pairs in 11 of its 13 frames.
// Sign: II > 0 along a direction in which the sheet bends away from its normal side (the normals spread, as on
// a sphere with outward normals); dihedral angles (mesh.hpp) are negative where it bends towards it, and the
// bending tensor of the angles has their sign, so the plastic part cancels the world part of a sheet resting in
// its plastic shape (tested: fracture_stress_test, PlasticCurvatureIsSubtracted).
//
// Units: sigma in N/m (force per unit length of the sheet's mid-surface); divide by h for Pa.
#pragma once

#include <vector>

#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "physics/material.hpp"

namespace arcsim {

// Elastic second fundamental form (1/m, 2x2 symmetric, face material frame) of face f, before the eigenvalue
// reversal: world part minus rest part minus plastic part (see above).
Mat2 face_elastic_curvature(const Mesh& mesh, int f, const std::vector<Vec3>& node_normals,
                            const std::vector<Vec3>& vert_normals);

// The same for a material with bending plasticity: its corner verts' mean of the hinges' elastic bending tensors
// (see above). Unlike face_elastic_curvature, a sheet resting in its plastic shape reads zero on border faces too.
Mat2 face_hinge_elastic_curvature(const Mesh& mesh, int f);

// The tensile fracture stress of one face.
struct FaceFractureStress {
  Mat2 sigma = Mat2::Zero();   // sigma+ (N/m), face material frame (Face::rest_frame columns t1, t2)
  double lambda_max = 0;       // its largest eigenvalue (N/m), >= 0
};

// sigma+ of face f. `node_normals` / `vert_normals` are only read when the face's material has
// fracture_bending_mult > 0 and no bending plasticity (they may be empty otherwise).
FaceFractureStress face_fracture_stress(const Mesh& mesh, const std::vector<Material>& materials, int f,
                                        const std::vector<Vec3>& node_normals,
                                        const std::vector<Vec3>& vert_normals);

// sigma+ of every face (indexed like mesh.faces; dead faces and faces of unbreakable materials, toughness 0,
// get zero). Computes the normals once, only if some material needs them. OpenMP-parallel over faces,
// deterministic.
std::vector<FaceFractureStress> fracture_stresses(const Mesh& mesh, const std::vector<Material>& materials);

// The same for a subset of faces only (others left as they are in `out`, which is resized to mesh.faces). Only
// the normals of the subset's corners are computed (the same values): the cost follows the subset.
void update_fracture_stresses(const Mesh& mesh, const std::vector<Material>& materials,
                              const std::vector<int>& faces, std::vector<FaceFractureStress>& out);

// Area toughness tau = toughness * h (N/m) of a face (0: unbreakable).
double face_toughness(const Face& face, const Material& material);

// The stress (N/m) as a rest-space 3x3 tensor R sigma R^T (R = Face::rest_frame).
Mat3 stress_to_rest(const Face& face, const Mat2& sigma);

}  // namespace arcsim
