// Real roots of a cubic on the unit interval, for continuous collision detection (time of coplanarity).
#pragma once

#include <array>
#include <vector>

namespace arcsim {

// p(t) = c[0] + c[1] t + c[2] t^2 + c[3] t^3.
double evaluate_cubic(const std::array<double, 4>& c, double t);

// Critical points of the cubic (roots of p') inside (0, 1), ascending. Any of the coefficients may be zero.
std::vector<double> cubic_critical_points(const std::array<double, 4>& c);

// Roots of p in [0, 1], ascending, found by bisection on the monotone pieces between critical points, so that
// degenerate cubics (leading coefficients zero or tiny) need no special formula. Each root is accurate to a
// few ulps in t. A piece on which p is identically zero yields its left end only; tangential (double) roots
// are found only if p is exactly zero there (callers test critical points themselves).
std::vector<double> cubic_roots_in_unit_interval(const std::array<double, 4>& c);

}  // namespace arcsim
