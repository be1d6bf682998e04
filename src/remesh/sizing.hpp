// The sizing metric of adaptive remeshing (paper §5.1, Narain et al. 2012; facts §5.4).
//
// Representation: each term is a 2x2 symmetric metric (1/m^2) in the face's rest frame (Face::rest_frame, the
// in-plane axes t1, t2 of the rest triangle); an edge with rest vector e (in that frame) is short enough when
// e^T M e <= 1. Verts store the area-weighted mean of their faces' metrics as 3x3 rest-space tensors
// R M R^T (R = rest_frame, 3x2), so that edges of curved rest shapes, whose faces have different frames, are
// measured with 3D rest vectors directly.
//
// Terms of a face (each skipped when its parameter is not finite and positive):
//   curvature      S^T S / refine_angle^2, S = 1/(2A) sum_i theta_i l_i n_i n_i^T the bending tensor from the
//                  world dihedral angles theta_i (l_i rest edge length, n_i rest in-plane edge normal);
//   rest curvature S_rp^T S_rp / refine_angle^2 (paper's M_rc), S_rp the same tensor from the rest angles;
//                  keeps curved rest shapes resolved even when the world shape is (momentarily) flat;
//   compression    buckling term of Narain et al. 2012: the positive part of
//                  (-G + ssqrt(G^2 - 4 c^2 r perp(S^T S))) / (2 c^2), G = F^T F - I (twice the Green strain),
//                  ssqrt the signed root of each eigenvalue (a negative one stays negative),
//                  c = refine_compression (m), r = rib_stiffening, perp = rotation by 90 degrees: compression
//                  asks for the wavelength of the buckles it will form, less so where the sheet is already
//                  curved across the compression (a rib resists buckling);
//   velocity       V^T V / refine_velocity^2, V = rest-space gradient of the node velocities (1/s), so
//                  refine_velocity is a speed (m/s);
//   obstacle       (1/3) sum over corners with a nearest obstacle plane of grad(h) grad(h)^T / h^2, h the mean
//                  height of the face's nodes above that plane (only when planes are supplied, see
//                  SizingExtras: the collision module does not provide them yet);
//   extra          caller-supplied per-face terms, e.g. the fracture term M_frac (fracture_sizing_term).
// Combination: metric_max (Loewner-minimal-trace upper bound, ARCSim's "tensor max"), or the sum when
// combine_tensors is false. Then the plastic transform M' = Fp^-T M Fp^-1 (paper §5.1; Fp in the face frame)
// and the clamp of eigenvalues to [1/size_max^2, 1/size_min^2] and anisotropy >= aspect_min.
#pragma once

#include <vector>

#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "scene/scene.hpp"

namespace arcsim {

// Nearest obstacle plane of a cloth node (point on the plane and unit normal towards the cloth).
struct ObstaclePlane {
  bool valid = false;
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();
};

struct SizingParams {
  RemeshingParams remeshing;
  double rib_stiffening = 1;    // magic.rib_stiffening
  bool combine_tensors = true;  // magic.combine_tensors: tensor max (true) or sum (false)
};

// Optional inputs beyond the mesh state (hooks for other modules).
struct SizingExtras {
  // Per face (indexed like mesh.faces; may be shorter), a rest-space 3x3 metric combined with the other terms,
  // e.g. R fracture_sizing_term(...) R^T. Faces without an entry get none.
  const std::vector<Mat3>* face_terms = nullptr;
  // Per node (indexed like mesh.nodes), its nearest obstacle plane; enables the obstacle term.
  const std::vector<ObstaclePlane>* node_planes = nullptr;
  // Apply M' = Fp^-T M Fp^-1 with Face::Fp.
  bool plastic_transform = true;
  // > 0: every face gets the isotropic metric I / uniform_size^2 instead of the terms (static refinement).
  double uniform_size = 0;
};

// The individual terms of one face (2x2 in its rest frame), before combination; for tests and diagnostics.
struct SizingTerms {
  Mat2 curvature = Mat2::Zero(), rest_curvature = Mat2::Zero(), compression = Mat2::Zero(),
       velocity = Mat2::Zero(), obstacle = Mat2::Zero(), extra = Mat2::Zero();
};
SizingTerms face_sizing_terms(const Mesh& mesh, int face, const SizingParams& params, const SizingExtras& extras);

// Combined, plastically transformed and clamped metric of one face, 2x2 in its rest frame.
Mat2 face_sizing(const Mesh& mesh, int face, const SizingParams& params, const SizingExtras& extras);

// The rest-space 3x3 form R M R^T of a face-frame metric M.
Mat3 face_metric_to_rest(const Face& face, const Mat2& M);

// Sets every live vert's sizing to the rest-area-weighted mean of its faces' metrics (3x3, rest space).
void compute_vertex_sizing(Mesh& mesh, const SizingParams& params, const SizingExtras& extras);

// The same for the verts of the given faces' nodes only (each from all its live faces, summed in the same order, so
// the values are those compute_vertex_sizing gives them); other verts keep their sizing. Cost: the faces'
// neighbourhood, not the mesh.
void compute_vertex_sizing(Mesh& mesh, const SizingParams& params, const SizingExtras& extras,
                           const std::vector<int>& faces);

// Metric length of the rest segment between verts a and b: sqrt of the mean over both ends of
// du^T sizing du (dimensionless; > 1 means too long).
double vert_pair_metric_length(const Mesh& mesh, int vert_a, int vert_b);
// Metric length of an edge: the larger over its sides (the two sides of a rest-space seam have different verts).
double edge_metric_length(const Mesh& mesh, int edge);

// Bending tensor (1/m, 2x2 in the face's rest frame) 1/(2A) sum_i angle_i l_i n_i n_i^T for per-edge angles
// (angle i belongs to edge i, joining corners i and i+1).
Mat2 face_bending_tensor(const Mesh& mesh, int face, const Vec3& angles);

// Paper's fracture term M_frac = (2 lambda / (tau x_min))^2 I (1/m^2): lambda the largest eigenvalue of the
// tensile stress (N/m), tau the area toughness (N/m), x_min = size_min (m). Zero when tau or x_min is not
// positive.
Mat2 fracture_sizing_term(double lambda, double toughness, double size_min);

}  // namespace arcsim
