// Axis-aligned bounding boxes (m).
#pragma once

#include "math/types.hpp"

namespace arcsim {

struct Aabb {
  Vec3 lo = Vec3::Constant(kInfinity);
  Vec3 hi = Vec3::Constant(-kInfinity);

  void extend(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void extend(const Aabb& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  void inflate(double margin) {
    lo.array() -= margin;
    hi.array() += margin;
  }
  bool overlaps(const Aabb& b) const {
    return lo.x() <= b.hi.x() && b.lo.x() <= hi.x() && lo.y() <= b.hi.y() && b.lo.y() <= hi.y() &&
           lo.z() <= b.hi.z() && b.lo.z() <= hi.z();
  }
  Vec3 center() const { return 0.5 * (lo + hi); }
};

}  // namespace arcsim
