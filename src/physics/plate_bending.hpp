// Bending energy of a thin plate on a triangle mesh from the face bending strain of paper Eq. 3
// (Gingold et al. 2004):
//   S_f = 1/(2 A) sum_i (theta_i - theta_bar_i) l_i n_i n_i^T      (1/m, rest-space in-plane 2x2)
//   E_f = A/2 kb [ (1 - nu) S:S + nu tr(S)^2 ]                      (J; kb = E h^3 / (12 (1 - nu^2)))
// over the face's three edges (l_i rest length, n_i unit in-plane normal of the edge, theta_i the dihedral
// angle at the edge, 0 deviation on boundary edges). This is the continuum plate energy
// (kb/2) [(tr S)^2 - 2 (1 - nu) det S] evaluated with the discrete shape operator.
//
// WHY not the classic per-hinge energy w (theta - theta_bar)^2: its constant depends on the triangle shapes
// (on a cylinder, right-triangle grids and equilateral meshes differ by >10%, and a free strip relaxes into a
// zig-zag mode), so it cannot match beam theory on general meshes. The face energy converges to the continuum
// on both (tests/physics/plate_bending_test.cpp, tests/physics/beam_test.cpp).
//
// The energy is a quadratic form in the three angle deviations d: E_f = d^T Q d, with
//   Q_ij = A kb c_i c_j [(1 - nu)(n_i . n_j)^2 + nu] / 2,   c_i = l_i / (2 A),
// a positive semi-definite 3x3 matrix that depends only on the rest state (precomputed per face).
//
// Element nodes (6): the face's corners c0, c1, c2, then the wings w0, w1, w2, where w_i is the node across
// edge i (joining corners i and i+1). A boundary edge has no wing (has_wing[i] = false; its slot is unused).
#pragma once

#include <array>

#include "math/types.hpp"
#include "physics/membrane.hpp"  // HessianKind

namespace arcsim {

using Vec18 = Eigen::Matrix<double, 18, 1>;
using Mat18 = Eigen::Matrix<double, 18, 18>;

// Q for a face with rest edge lengths l_i (m), rest unit in-plane edge normals n_i (any consistent 2D or 3D
// frame), rest area A (m^2), bending stiffness kb (N m) and Poisson ratio nu. A boundary edge gets zero row and
// column (pass has_edge[i] = false).
Mat3 plate_bending_matrix(const std::array<double, 3>& lengths, const std::array<Vec3, 3>& normals, double area,
                          double kb, double nu, const std::array<bool, 3>& has_edge);

// Element slots of the hinge of edge i, in dihedral_angle's order (mesh/mesh.hpp): corners c_i, c_i+1, c_i+2,
// then wing w_i. The face is the hinge's first face, in which the edge runs c_i -> c_i+1 counter-clockwise.
inline std::array<int, 4> plate_hinge_slots(int i) { return {i, (i + 1) % 3, (i + 2) % 3, 3 + i}; }

// The hinge's dihedral angle minus its rest angle, wrapped into (-pi, pi] (rad). Every evaluation of the plate
// energy (physics, energy checks, reprojection's local solve) takes its deviations from here.
double hinge_angle_deviation(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, double rest_theta);

struct PlateBendingTerms {
  double energy = 0;             // J
  Vec18 gradient = Vec18::Zero();  // N, stacked (c0, c1, c2, w0, w1, w2)
  Mat18 hessian;                   // N/m; set only when a Hessian is asked for (not with HessianKind::kNone)
  Vec3 theta = Vec3::Zero();       // world dihedral angles of the three edges (rad; 0 on boundary edges)
};

// x: the 6 element node positions (wing slots of boundary edges are ignored). rest_theta: rest (plus plastic)
// dihedral angles of the three edges. kProjected gives the Gauss-Newton Hessian 2 sum Q_ij grad_i grad_j^T.
PlateBendingTerms plate_bending_terms(const std::array<Vec3, 6>& x, const std::array<bool, 3>& has_wing,
                                      const Vec3& rest_theta, const Mat3& Q, HessianKind hessian);
// The same, written over `out` (every field): the assembly evaluates into its own buffer, with no copy of the
// 18x18 Hessian. `known_theta`, if given, is out.theta as computed before at these very positions.
void plate_bending_terms(const std::array<Vec3, 6>& x, const std::array<bool, 3>& has_wing, const Vec3& rest_theta,
                         const Mat3& Q, HessianKind hessian, PlateBendingTerms& out,
                         const Vec3* known_theta = nullptr);

// The energy alone (J), equal to plate_bending_terms(...).energy, without the angles' gradients (for energy
// checks that evaluate every element several times per step).
// `theta`, if given, gets the world dihedral angles as plate_bending_terms gives them (0 where no wing).
double plate_bending_energy(const std::array<Vec3, 6>& x, const std::array<bool, 3>& has_wing,
                            const Vec3& rest_theta, const Mat3& Q, Vec3* theta = nullptr);

}  // namespace arcsim
