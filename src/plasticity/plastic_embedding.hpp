// Local plastic embedding for remeshing (paper §5.2, Eq. 11-12): keeps plastic deformation through splits,
// flips and collapses instead of diffusing it by interpolation.
//
// Before an edit, the faces it will replace and the faces across their edges ("flaps") are unfolded into a
// 3D plastic space, one hinge at a time: every face keeps its plastic edge lengths (plastic edge vectors are
// Fp2^-1 e, see plastic_tensors.hpp: F_el = F Fp) and every hinge its plastic angle theta^p = Edge::rest_theta.
// After the edit, a new node (split) is placed on the smooth surface the neighbourhood's plastic curvature
// describes (off the old faces' plane by the sagitta of the split edge) and settles from there by Gauss-Newton
// steps on the plastic energy E_p of Eq. 12 with every other node fixed (place_split_node_in_embedding says why
// it does not start on the chord); then Fp and Sp of the new faces are read back from the embedding
// (Eq. 11): Fp from the plastic metric of the embedded triangle, Sp from its three embedded dihedral angles.
//
// Eq. 12 as implemented, for the node's faces and the faces that have it as a bending wing:
//   E_p(y) = sum_faces A/2 G^p : sigma^p  +  plate bending of the embedded dihedrals against theta^p,
// with G^p the Green strain of the embedded triangle against the reference metric (the paper's Eq. 12) and
// theta^p the edges' plastic angles (Edge::rest_theta; the paper writes theta^R, which pulls every placed node
// towards the flat reference: a uniformly curved plastic sheet was not reproduced by a split). Faces of a
// material with a stretching flow rule measure G^p against their plastic metric (the Fp the edit gave them)
// instead: there the reference would pull a boundary node of a plastically stretched sheet inwards.
//
// Multi-material: only faces of plastic materials (finite yield_curv, or a stretching flow rule) are rebuilt;
// every other face keeps Fp and Sp exactly as the edit left them (copied from a parent of the same material).
#pragma once

#include <vector>

#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "physics/material.hpp"
#include "physics/membrane.hpp"

namespace arcsim {

// Node positions in plastic space (m), for the nodes of one neighbourhood.
struct PlasticEmbedding {
  std::vector<int> nodes;
  std::vector<Vec3> y;
  bool has(int node) const;
  const Vec3& at(int node) const;  // the node must be embedded
  void set(int node, const Vec3& position);
};

// True if faces of this material carry plasticity (bending or stretching flow rule).
bool is_plastic_material(const Material& material);

// True if the neighbourhood holds plastic state worth transferring: some face of a plastic material among
// `faces` or their flaps has Fp != I or Sp != 0, or some edge of theirs a rest angle off its rest dihedral.
bool neighbourhood_has_plasticity(const Mesh& mesh, const std::vector<Material>& materials,
                                  const std::vector<int>& faces);

// Unfolds `faces` and their flaps (faces across any of their edges) into plastic space, starting from the
// first face. A node is placed once; a face whose nodes are all placed already is not re-checked (a closed fan
// around an interior node closes with whatever mismatch its plastic state has).
PlasticEmbedding build_plastic_embedding(const Mesh& mesh, const std::vector<int>& faces);

// Eq. 12 restricted to one node: energy (J), gradient (N) and 3x3 Hessian (N/m) with respect to its plastic
// position y, all other nodes at their embedded positions. kProjected gives the Gauss-Newton matrix (PSD),
// kExact the true Hessian. Faces with a node missing from the embedding are skipped.
struct PlasticNodeEnergy {
  double energy = 0;
  Vec3 gradient = Vec3::Zero();
  Mat3 hessian = Mat3::Zero();
};
PlasticNodeEnergy plastic_node_energy(const Mesh& mesh, const std::vector<Material>& materials,
                                      const PlasticEmbedding& embedding, int node, const Vec3& y,
                                      HessianKind hessian);

// Moves the node's plastic position to the minimiser of plastic_node_energy by damped Gauss-Newton steps with
// a backtracking line search. Returns the number of accepted steps.
int place_node_in_embedding(const Mesh& mesh, const std::vector<Material>& materials,
                            PlasticEmbedding& embedding, int node, int max_iterations = 6);

// Places the node a split of edge (end0, end1) created: it starts at the middle of the embedded edge plus the
// sagitta e^T S e / 8 of the edge e under the plastic curvature S estimated from the neighbourhood's edge offsets
// (rest angles), on the convex side, and settles from there by Gauss-Newton on Eq. 12 in every direction. WHY
// the start: the middle of a flat coarse face spanning a curved plastic region is a saddle of the membrane term
// (no gradient across the plane), so Gauss-Newton from the chord never leaves it and every refine / coarsen
// cycle flattened the sheet a little (-0.7% .. -2% of a constant-curvature arc in 10 cycles; -12% of a
// simulator-bent strip in 100). WHY Eq. 12 decides the height rather than the estimate: holding the node at
// the estimated sagitta fed the estimate's noise back into the plastic state (a simulator-bent strip gained
// 39.5% rest curvature over 100 cycles; 0.8% now). Returns the accepted Gauss-Newton steps.
int place_split_node_in_embedding(const Mesh& mesh, const std::vector<Material>& materials,
                                  PlasticEmbedding& embedding, int node, int end0, int end1);

// World position of an embedded node that keeps its plastic neighbourhood's shape: the best rigid map of its
// embedded neighbours onto their world positions, applied to it (a starting point for the world reprojection,
// so that it does not have to find a plastically bulged position from the chord). Its current x when fewer than
// three neighbours are embedded.
Vec3 world_position_from_embedding(const Mesh& mesh, const PlasticEmbedding& embedding, int node);

// Eq. 11: sets Fp (polar rotation of the face's current Fp kept, stretch clamped by plastic_limit, thickness
// scaled to keep the volume) of every face of a plastic material among `new_faces`, and Sp of those with
// bending plasticity, then the rest angles of their edges. Sp is chosen so that every edge's rest angle (mean of its faces' offsets,
// update_edge_rest_angles_from_Sp) equals its embedded dihedral: an edge shared with an unchanged face gets
// the offset 2 (theta_emb - theta^R) - (that face's offset), which is the old face's own offset when nothing
// moved. Edges without both wings in the embedding keep their current plastic offset.
void rebuild_plasticity_from_embedding(Mesh& mesh, const std::vector<Material>& materials,
                                       const PlasticEmbedding& embedding, const std::vector<int>& new_faces);

// Naive transfer (scene option "plastic_transfer": "interpolate"): the edit's interpolated Sp is the truth,
// so the edges of `new_faces` take their rest angles from it.
void interpolate_plasticity(Mesh& mesh, const std::vector<Material>& materials, const std::vector<int>& new_faces);

}  // namespace arcsim
