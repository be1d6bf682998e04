// Hinge bending of one interior edge (paper Eq. 4): E = w (theta - theta_bar)^2, with theta the signed world
// dihedral angle (mesh.hpp's dihedral_angle) and theta_bar the rest plus plastic angle.
//
// Inputs shared by every function:
//   x0, x1      world positions of the edge's nodes (m);
//   x2          wing of face A = (x0, x1, x2); x3 wing of face B = (x1, x0, x3) (the mesh's Edge::f[0], f[1]);
//   theta_bar   rest angle (rad); theta - theta_bar is wrapped into (-pi, pi];
//   weight      w = hinge_weight(...) (J, i.e. N m).
// Vectors of size 12 stack (x0, x1, x2, x3).
//
// Degenerate hinges stay finite: the wing heights are floored at 1e-3 times the edge length in the gradient
// (so a collapsing wing cannot produce an unbounded force), a wing with a zero-area triangle contributes no
// gradient, and a zero-length edge gives zero gradient and Hessian.
#pragma once

#include "math/types.hpp"
#include "physics/membrane.hpp"  // HessianKind

namespace arcsim {

// w = kb l^2 / (2 (A0 + A1)) (J) from the bending stiffness kb (N m), rest edge length l (m) and the rest areas
// of the two faces (m^2). WHY: a flat triangle on a surface with curvature tensor K has the slope of the linear
// interpolant, so across an edge of an equilateral mesh (height h, in-plane edge normal n, tangent t) the
// dihedral angle is theta = h (n.K.n - t.K.t / 3). For a cylinder (K = kappa e e^T) the sum of theta^2 over
// three edge directions 120 degrees apart is h^2 kappa^2 whatever the direction e, and the total hinge energy
// equals the continuum plate energy (1/2) kb kappa^2 Area exactly to leading order (tested in
// bending_test.cpp). Returns 0 when A0 + A1 <= 0 (degenerate rest faces carry no bending energy).
double hinge_weight(double kb, double l_rest, double A0, double A1);

// Wraps an angle difference (rad) into (-pi, pi].
double wrap_angle(double angle);

// d theta / dx of dihedral_angle(x0, x1, x2, x3) (1/m), closed form.
Vec12 dihedral_angle_gradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3);
// d2 theta / dx2 (1/m^2): forward-mode automatic differentiation of the closed-form gradient (exact).
Mat12 dihedral_angle_hessian(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3);

double hinge_energy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, double theta_bar,
                    double weight);
// dE/dx = 2 w (theta - theta_bar) d theta/dx (N).
Vec12 hinge_gradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, double theta_bar,
                     double weight);
// Exact d2E/dx2 = 2 w [ grad theta grad theta^T + (theta - theta_bar) d2 theta ] (N/m).
Mat12 hinge_hessian(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, double theta_bar,
                    double weight);
// Gauss-Newton Hessian 2 w grad theta grad theta^T: positive semi-definite (for w >= 0), for the solver.
Mat12 hinge_hessian_gauss_newton(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                                 double weight);

// Everything at once, sharing theta and its gradient. HessianKind::kProjected gives the Gauss-Newton Hessian.
struct HingeTerms {
  double theta = 0;                // world dihedral angle (rad)
  double energy = 0;               // J
  Vec12 gradient = Vec12::Zero();  // N
  Mat12 hessian = Mat12::Zero();   // N/m; zero when HessianKind::kNone
};
HingeTerms hinge_terms(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, double theta_bar,
                       double weight, HessianKind hessian);

}  // namespace arcsim
