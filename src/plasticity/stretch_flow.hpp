// Stretching plasticity of one face: the multiplicative flow rule of paper Eq. 9 with thinning.
//
// The membrane sees F_el = F Fp2 (F: 3x2 world image of the face's 2D material frame, Fp2 the face's plastic
// tensor in that frame, see plastic_tensors.hpp). Fp2 is the INVERSE of the plastic stretch P = Fp2^-1 that
// takes the reference shape to the plastic rest shape. With F_el = U diag(s1, s2) V^T and J = s1 s2, one step
// moves a fraction gamma of the isochoric part of the elastic stretch into P:
//   P  <- V (J^-1/3 Sigma)^gamma V^T P,   i.e.   Fp2 <- Fp2 V (J^-1/3 Sigma)^-gamma V^T,
//   h  <- h J^(-gamma/3)                  (thinning; in-plane area grows by J^(gamma/3))
// so that F_el becomes U Sigma^(1-gamma) J^(gamma/3) V^T. The paper prints Eq. 9 without the minus sign on
// gamma; with F_el = F Fp that would increase the elastic strain, so we apply the inverse (ARCSim likewise
// inverts the singular values when it builds its plastic stretch).
//
// Volume: det(P) h / h0 = 1 holds exactly after any number of steps, with det(P) = 1 / det(Fp2) the 2x2
// in-plane determinant; the thickness is updated as h <- h det(Fp2_new) / det(Fp2_old), which equals
// J^(-gamma/3) and stays volume-preserving when plastic_limit clamps the stretch.
//
// gamma = clamp(dt mu (sigma_M - sigma_0), 0, 1) with sigma_M the von Mises stress of the membrane stress of
// physics/membrane (second Piola-Kirchhoff, N/m, with the face's weakened stiffness) divided by the thickness
// (Pa), padded to 3D with zero out-of-plane stress (plane stress). We use the standard
// sigma_M = sqrt(3/2) |dev sigma| (= sigma under uniaxial tension) so that yield_stress is the handbook
// tensile yield strength; the paper's printed sqrt(3) would yield at sigma_0 / sqrt(2).
#pragma once

#include "math/types.hpp"
#include "mesh/mesh.hpp"
#include "physics/material.hpp"

namespace arcsim {

// True if the material has a stretching flow rule (finite yield_stress and flow_rate > 0).
bool has_stretch_plasticity(const Material& m);

// Von Mises effective stress (Pa) of an in-plane stress (Pa, symmetric 2x2) with zero out-of-plane stress.
double von_mises_plane_stress(const Mat2& sigma);

// gamma of Eq. 9 for a von Mises stress (Pa) and step dt (s).
double stretch_flow_fraction(const Material& m, double von_mises, double dt);

// One flow-rule update of plastic tensor Fp2 (2x2, material frame) for the elastic deformation gradient F_el
// (3x2): returns the new Fp2, clamped so that the singular values of the plastic stretch lie in
// [1/plastic_limit, plastic_limit]. Returns Fp2 unchanged when gamma <= 0 or F_el is degenerate.
Mat2 stretch_flow_update(const Mat2& Fp2, const Mat32& F_el, double gamma, double plastic_limit);

struct StretchFlowResult {
  bool changed = false;
  double work = 0;        // J, plastic work of this update (see plastic_step.hpp)
  double von_mises = 0;   // Pa, before the update
  double gamma = 0;
};

// Applies the flow rule to face `face` of `mesh` (material `m`, step dt in s): updates Fp and thickness.
// Faces of materials without stretching plasticity, or with no thickness or area, are left untouched.
StretchFlowResult apply_stretch_flow(Mesh& mesh, int face, const Material& m, double dt);

}  // namespace arcsim
