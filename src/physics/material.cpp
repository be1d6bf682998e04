#include "physics/material.hpp"

#include <cmath>

namespace arcsim {

double Material::area_density(double h) const {
  if (data_driven) return dde_area_density * density_mult * thicken;
  return density * h;
}

MembraneStiffness Material::membrane_stiffness(double h) const {
  MembraneStiffness k;
  if (data_driven) {
    const auto& s = dde_stretching[0];  // small-strain sample
    const double m = stretching_mult * thicken;
    k.k11 = m * s[0];
    k.k12 = m * s[1];
    k.k22 = m * s[2];
    k.k33 = m * s[3];
    return k;
  }
  const double nu = poisson_ratio;
  const double ks = youngs_modulus * h / (1 - nu * nu) * stretching_mult;
  k.k11 = k.k22 = ks;
  k.k12 = ks * nu;
  k.k33 = ks * (1 - nu);
  return k;
}

double Material::bending_stiffness(double h, double angle) const {
  if (data_driven) {
    // Samples at 0, 45 and 90 degrees (and symmetric beyond); linear interpolation in the folded angle.
    double a = std::fmod(std::fabs(angle), M_PI);
    if (a > M_PI / 2) a = M_PI - a;  // bending along direction a and pi - a is the same
    const double t = a / (M_PI / 4);  // 0..2
    const int i = t >= 1 ? 1 : 0;
    const double w = t - i;
    const double kb = (1 - w) * dde_bending[i][0] + w * dde_bending[i + 1][0];
    return kb * bending_mult * thicken;
  }
  const double nu = poisson_ratio;
  return youngs_modulus * h * h * h / (12 * (1 - nu * nu)) * bending_mult;
}

}  // namespace arcsim
