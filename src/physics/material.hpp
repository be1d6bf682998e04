// Sheet materials: ARCSim's isotropic ("alt") model and its data-driven (DDE) file format, reduced to the
// stiffness constants the energies need.
#pragma once

#include <array>
#include <string>

#include "math/types.hpp"

namespace arcsim {

// In-plane (membrane) stiffness in the face's material frame (t1 = rest-space x axis projected on the face),
// units N/m. Stress from Green strain G: s11 = k11 G11 + k12 G22, s22 = k12 G11 + k22 G22, s12 = k33 G12.
// Energy density (J/m^2) = 1/2 (k11 G11^2 + 2 k12 G11 G22 + k22 G22^2 + 2 k33 G12^2).
// Isotropic: k11 = k22 = ks, k12 = ks*nu, k33 = ks*(1 - nu), ks = E h / (1 - nu^2).
struct MembraneStiffness {
  double k11 = 0, k12 = 0, k22 = 0, k33 = 0;
};

struct Material {
  std::string name;         // for messages
  bool data_driven = false; // true: stiffness from a DDE file (`data`), false: isotropic keys
  // Isotropic model
  double thickness = 0;     // h (m)
  double density = 0;       // volume density (kg/m^3); area density = density * h
  double youngs_modulus = 0;  // E (Pa)
  double poisson_ratio = 0;   // nu, in [0, 0.5)
  // DDE model (ARCSim materials/*.json): area density (kg/m^2), stretching samples (6 x 4, N/m), bending
  // samples (3 directions x 5 curvatures, N m). Only the small-strain row / first curvature sample is used
  // (linearised DDE), see docs/scene-format.md.
  double dde_area_density = 0;
  std::array<std::array<double, 4>, 6> dde_stretching{};
  std::array<std::array<double, 5>, 3> dde_bending{};
  double thicken = 1;       // DDE: multiplies density, stretching and bending
  double density_mult = 1;  // DDE: multiplies density
  // Common
  double stretching_mult = 1;
  double bending_mult = 1;
  double damping = 0;       // stiffness-proportional damping coefficient beta (s)
  Vec2 strain_limits{-kInfinity, kInfinity};  // min/max principal stretch (strain limiting)
  double yield_curv = kInfinity;   // bending plastic yield curvature kappa_0 (1/m)
  double weakening = 0;            // stiffness / (1 + weakening * damage)
  double yield_stretch = kInfinity;  // ARCSim key, parsed, unused by ARCSim
  double yield_stress = kInfinity;   // stretching plasticity yield stress sigma_0 (Pa) (paper Eq. 9)
  double flow_rate = 0;            // stretching plasticity flow rate mu (1/(Pa s)) (paper Eq. 9)
  double plastic_flow = 0;         // ARCSim key
  double plastic_limit = kInfinity;  // clamp of plastic stretch factors to [1/limit, limit]
  double toughness = 0;            // volume toughness tau_V (Pa); area toughness = tau_V * h. 0 = unbreakable
  double fracture_bending_mult = 0;  // alpha in paper Eq. 8: bending-fracture thickness = alpha * h

  // Area density (kg/m^2) of a face of thickness h.
  double area_density(double h) const;
  // Membrane stiffness of a face of thickness h (N/m).
  MembraneStiffness membrane_stiffness(double h) const;
  // Bending stiffness (N m) of a face of thickness h for bending about an axis along the in-plane direction
  // at angle `angle` (rad) from the material x axis (isotropic materials ignore the angle).
  double bending_stiffness(double h, double angle = 0) const;
};

}  // namespace arcsim
