// Derivatives of the signed dihedral angle of a hinge (mesh.hpp's dihedral_angle), for the plate bending
// energy (physics/plate_bending.hpp) and the local world-space reprojection (remesh/reprojection.cpp), and the
// angle wrapping shared with plasticity.
//
// Inputs shared by the derivative functions:
//   x0, x1      world positions of the edge's nodes (m);
//   x2          wing of face A = (x0, x1, x2); x3 wing of face B = (x1, x0, x3) (the mesh's Edge::f[0], f[1]).
// Vectors of size 12 stack (x0, x1, x2, x3).
//
// Degenerate hinges stay finite: the wing heights are floored at 1e-3 times the edge length in the gradient
// (so a collapsing wing cannot produce an unbounded force), a wing with a zero-area triangle contributes no
// gradient, and a zero-length edge gives zero gradient and Hessian.
#pragma once

#include "math/types.hpp"

namespace arcsim {

// Wraps an angle difference (rad) into (-pi, pi].
double wrap_angle(double angle);

// d theta / dx of dihedral_angle(x0, x1, x2, x3) (1/m), closed form.
Vec12 dihedral_angle_gradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3);
// d2 theta / dx2 (1/m^2): forward-mode automatic differentiation of the closed-form gradient (exact).
Mat12 dihedral_angle_hessian(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3);

}  // namespace arcsim
