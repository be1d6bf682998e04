// In-plane (membrane) elasticity of one triangle: St. Venant-Kirchhoff energy on the Green strain measured in
// the face's material frame (paper Eq. 1, 2, 4), with its gradient, exact Hessian and a positive semi-definite
// Hessian for the implicit solver.
//
// Inputs shared by every function:
//   x0, x1, x2   world positions of the corners (m), in the face's corner order;
//   Dm_inv       inverse of the 2x2 rest edge matrix [u1-u0, u2-u0] expressed in the material frame (1/m).
//                Stretching plasticity enters here: pass Dm_inv * Fp (2x2) to measure the elastic strain;
//   rest_area    A (m^2);
//   k            stiffness (N/m), see material.hpp; `stiffness_factor` multiplies all four constants
//                (weakening by damage, thickness scaling...).
// Vectors of size 9 stack the corners (x0, x1, x2); the energy is in J.
#pragma once

#include "math/types.hpp"
#include "physics/material.hpp"

namespace arcsim {

// Which Hessian a combined evaluation computes.
enum class HessianKind {
  kNone,      // energy and gradient only
  kExact,     // the true second derivative (may be indefinite)
  kProjected  // positive semi-definite approximation for the implicit solver
};

// Deformation gradient F = [x1-x0, x2-x0] Dm_inv (3x2): world image of the material frame axes.
Mat32 membrane_deformation_gradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv);

// Green strain G = (F^T F - I)/2 (dimensionless, 2x2, material frame).
Mat2 membrane_green_strain(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv);

// Membrane stress (second Piola-Kirchhoff, N/m) for the Green strain G:
// S11 = k11 G11 + k12 G22, S22 = k12 G11 + k22 G22, S12 = S21 = k33 G12, all times stiffness_factor.
Mat2 membrane_stress(const Mat2& G, const MembraneStiffness& k, double stiffness_factor = 1);

// Energy A * (1/2) (k11 G11^2 + 2 k12 G11 G22 + k22 G22^2 + 2 k33 G12^2) (J).
double membrane_energy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv, double rest_area,
                       const MembraneStiffness& k, double stiffness_factor = 1);

// dE/dx (N), stacked (x0, x1, x2). The elastic force is its negative.
Vec9 membrane_gradient(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv, double rest_area,
                       const MembraneStiffness& k, double stiffness_factor = 1);

// Exact d2E/dx2 (N/m) = A [ dG : C : dG + dF : (dF S) ].
Mat9 membrane_hessian(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv, double rest_area,
                      const MembraneStiffness& k, double stiffness_factor = 1);

// Positive semi-definite Hessian: the exact one with the stress S in the geometric term dF : (dF S) replaced
// by its positive part (eigenvalues clamped at 0), and the stiffness C replaced by its positive part (only
// differs for indefinite data-driven stiffness, which some measured cloths have). Both terms are then sums of
// PSD forms. Equal to the exact Hessian under tension (S PSD) with a PSD stiffness.
Mat9 membrane_hessian_projected(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv,
                                double rest_area, const MembraneStiffness& k, double stiffness_factor = 1);

// Everything at once, sharing the kinematics (what the time step calls for each face).
struct MembraneTerms {
  double energy = 0;             // J
  Vec9 gradient = Vec9::Zero();  // N
  Mat9 hessian = Mat9::Zero();   // N/m; zero when HessianKind::kNone
};
MembraneTerms membrane_terms(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv,
                             double rest_area, const MembraneStiffness& k, double stiffness_factor,
                             HessianKind hessian);
// membrane_terms(...).energy bit for bit, without the gradient (line searches compare energies only).
double membrane_terms_energy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Mat2& Dm_inv, double rest_area,
                             const MembraneStiffness& k, double stiffness_factor);

}  // namespace arcsim
