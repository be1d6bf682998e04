// Real roots of a cubic on the unit interval, for continuous collision detection (time of coplanarity).
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>

namespace arcsim {

// A short ascending list of times in [0, 1], held inline: the narrow phase asks for these per candidate pair,
// hundreds of thousands of times a second, and heap vectors cost more than the roots themselves. Room for the
// roots (3), the critical points (2) and one more time, which is all a caller of this header collects.
class CubicTimes {
 public:
  static constexpr size_t kCapacity = 8;
  void push_back(double t) {
    assert(size_ < kCapacity);
    times_[size_++] = t;
  }
  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  double operator[](size_t k) const { return times_[k]; }
  const double* begin() const { return times_.data(); }
  const double* end() const { return times_.data() + size_; }
  double* begin() { return times_.data(); }
  double* end() { return times_.data() + size_; }
  // Sorts ascending and drops repeated times.
  void sort_unique() {
    std::sort(begin(), end());
    size_ = static_cast<size_t>(std::unique(begin(), end()) - begin());
  }

 private:
  std::array<double, kCapacity> times_{};
  size_t size_ = 0;
};

// p(t) = c[0] + c[1] t + c[2] t^2 + c[3] t^3.
double evaluate_cubic(const std::array<double, 4>& c, double t);

// Critical points of the cubic (roots of p') inside (0, 1), ascending. Any of the coefficients may be zero.
CubicTimes cubic_critical_points(const std::array<double, 4>& c);

// Roots of p in [0, 1], ascending, found by bisection on the monotone pieces between critical points, so that
// degenerate cubics (leading coefficients zero or tiny) need no special formula. Each root is accurate to a
// few ulps in t. A piece on which p is identically zero yields its left end only; tangential (double) roots
// are found only if p is exactly zero there (callers test critical points themselves).
CubicTimes cubic_roots_in_unit_interval(const std::array<double, 4>& c);

}  // namespace arcsim
