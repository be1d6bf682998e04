// Materials shared by the plasticity tests.
#pragma once

#include <string>

#include "physics/material.hpp"

namespace arcsim::testing {

// An aluminium sheet (2700 kg/m^3, E = 70 GPa, nu = 0.33) with bending plasticity from yield curvature
// `yield_curv` (1/m), `thickness` (m) thick.
inline Material aluminium_sheet(double yield_curv, double thickness = 1e-3, const std::string& name = "aluminium") {
  Material m;
  m.name = name;
  m.thickness = thickness;
  m.density = 2700;
  m.youngs_modulus = 70e9;
  m.poisson_ratio = 0.33;
  m.yield_curv = yield_curv;
  return m;
}

}  // namespace arcsim::testing
