#include "collision/cubic.hpp"

#include <algorithm>
#include <cmath>

namespace arcsim {

double evaluate_cubic(const std::array<double, 4>& c, double t) {
  return ((c[3] * t + c[2]) * t + c[1]) * t + c[0];
}

CubicTimes cubic_critical_points(const std::array<double, 4>& c) {
  // p'(t) = A t^2 + B t + C.
  const double A = 3 * c[3], B = 2 * c[2], C = c[1];
  CubicTimes roots;
  if (A == 0) {
    if (B != 0) roots.push_back(-C / B);
  } else {
    const double disc = B * B - 4 * A * C;
    if (disc >= 0) {
      // Cancellation-free form: q = -(B + sign(B) sqrt(disc)) / 2, roots q / A and C / q.
      const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
      roots.push_back(q / A);
      if (q != 0) roots.push_back(C / q);
    }
  }
  CubicTimes inside;
  for (double t : roots)
    if (t > 0 && t < 1) inside.push_back(t);
  inside.sort_unique();
  return inside;
}

CubicTimes cubic_roots_in_unit_interval(const std::array<double, 4>& c) {
  CubicTimes bounds;
  bounds.push_back(0.0);
  for (double t : cubic_critical_points(c)) bounds.push_back(t);
  bounds.push_back(1.0);

  CubicTimes roots;
  for (size_t k = 0; k + 1 < bounds.size(); ++k) {
    double lo = bounds[k], hi = bounds[k + 1];
    double flo = evaluate_cubic(c, lo), fhi = evaluate_cubic(c, hi);
    if (flo == 0) {
      roots.push_back(lo);
      continue;
    }
    if (fhi == 0) {
      roots.push_back(hi);
      continue;
    }
    if ((flo < 0) == (fhi < 0)) continue;
    // Bisection: the piece is monotone, so the sign change brackets exactly one root. 64 halvings of a
    // sub-interval of [0, 1] reach the spacing of doubles.
    for (int it = 0; it < 64; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      const double fm = evaluate_cubic(c, mid);
      if (fm == 0) {
        lo = hi = mid;
        break;
      }
      if ((fm < 0) == (flo < 0)) {
        lo = mid;
        flo = fm;
      } else {
        hi = mid;
      }
    }
    roots.push_back(0.5 * (lo + hi));
  }
  roots.sort_unique();
  return roots;
}

}  // namespace arcsim
