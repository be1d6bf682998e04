#include "collision/ccd.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "collision/cubic.hpp"

namespace arcsim {

std::array<double, 4> coplanarity_cubic(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1) {
  // Edge vectors e_k(t) = a_k + t b_k relative to point 0; det[e1, e2, e3] expanded in t.
  std::array<Vec3, 3> a, b;
  for (int k = 0; k < 3; ++k) {
    a[k] = x0[k + 1] - x0[0];
    b[k] = (x1[k + 1] - x1[0]) - a[k];
  }
  const Vec3 aa = a[0].cross(a[1]);
  const Vec3 ab = a[0].cross(b[1]) + b[0].cross(a[1]);
  const Vec3 bb = b[0].cross(b[1]);
  return {aa.dot(a[2]), ab.dot(a[2]) + aa.dot(b[2]), bb.dot(a[2]) + ab.dot(b[2]), bb.dot(b[2])};
}

namespace {

enum class PairKind { kVertexFace, kEdgeEdge };

std::array<Vec3, 4> lerp(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, double t) {
  std::array<Vec3, 4> x;
  for (int i = 0; i < 4; ++i) x[i] = (1 - t) * x0[i] + t * x1[i];
  return x;
}

ClosestPoints closest(PairKind kind, const std::array<Vec3, 4>& x) {
  return kind == PairKind::kVertexFace ? vertex_face_closest(x[0], x[1], x[2], x[3])
                                       : edge_edge_closest(x[0], x[1], x[2], x[3]);
}

// Normal of the plane the pair shares when coplanar (face normal, or the two edges' cross product), not
// normalised: its length converts the coplanarity cubic into a height (m).
Vec3 coplanarity_normal(PairKind kind, const std::array<Vec3, 4>& x) {
  return kind == PairKind::kVertexFace ? Vec3((x[2] - x[1]).cross(x[3] - x[1]))
                                       : Vec3((x[1] - x[0]).cross(x[3] - x[2]));
}

// Points in the order coplanarity_cubic expects (for VF the vertex goes last).
std::array<Vec3, 4> cubic_order(PairKind kind, const std::array<Vec3, 4>& x) {
  return kind == PairKind::kVertexFace ? std::array<Vec3, 4>{x[1], x[2], x[3], x[0]} : x;
}

Vec3 weighted_sum(const std::array<double, 4>& w, const std::array<Vec3, 4>& x) {
  return w[0] * x[0] + w[1] * x[1] + w[2] * x[2] + w[3] * x[3];
}

double size_of(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1) {
  double s = 0;
  for (int i = 1; i < 4; ++i) s = std::max({s, (x0[i] - x0[0]).norm(), (x1[i] - x1[0]).norm()});
  return s;
}

// Bound on how fast the distance between the primitives can change (m per unit t): the closest points are
// convex combinations of the nodes, so their relative speed is at most the largest node-pair speed.
double distance_rate_bound(PairKind kind, const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1) {
  std::array<Vec3, 4> u;
  for (int i = 0; i < 4; ++i) u[i] = x1[i] - x0[i];
  double bound = 0;
  if (kind == PairKind::kVertexFace) {
    for (int j = 1; j < 4; ++j) bound = std::max(bound, (u[0] - u[j]).norm());
  } else {
    for (int i = 0; i < 2; ++i)
      for (int j = 2; j < 4; ++j) bound = std::max(bound, (u[i] - u[j]).norm());
  }
  return bound;
}

// A plane normal is used for an impact only where the primitives span a plane (the sine of the angle between
// the face's edges or between the two edges is above kMinPlaneSine) and the gap at the start of the step, or
// else at contact, leaves that plane at a cosine above kMinGapAlongPlane (which also picks the side).
constexpr double kMinPlaneSine = 1e-3;
constexpr double kMinGapAlongPlane = 0.1;

class ImpactSearch {
 public:
  ImpactSearch(PairKind kind, const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1,
               const CcdOptions& options)
      : kind_(kind), x0_(x0), x1_(x1), options_(options), scale_(size_of(x0, x1)) {}

  std::optional<Impact> run() const {
    const double threshold = options_.contact_distance;
    const std::array<double, 4> cubic = coplanarity_cubic(cubic_order(kind_, x0_), cubic_order(kind_, x1_));
    const CubicTimes critical = cubic_critical_points(cubic);
    // How far from coplanar the pair ever gets (m), from the cubic's extremes over the step and the size of the
    // coplanarity normal.
    double cubic_max = std::max(std::abs(cubic[0]), std::abs(evaluate_cubic(cubic, 1.0)));
    for (double t : critical) cubic_max = std::max(cubic_max, std::abs(evaluate_cubic(cubic, t)));
    double normal_max = 0;
    for (double t : {0.0, 0.5, 1.0}) normal_max = std::max(normal_max, coplanarity_normal(kind_, at(t)).norm());
    if (!(cubic_max > threshold * normal_max) || normal_max <= 1e-12 * scale_ * scale_)
      return conservative_advancement();

    // The distance is at least the height over the shared plane (point to plane, or line to line), so only
    // times where that height is within the contact distance need the closest points: the start and end if
    // close, the coplanarity roots, and near-tangent extremes.
    auto near_coplanar = [&](double t) {
      const double normal = coplanarity_normal(kind_, at(t)).norm();
      return !(std::abs(evaluate_cubic(cubic, t)) > threshold * normal);
    };
    if (near_coplanar(0.0))
      if (auto hit = contact_at(0.0, true)) return hit;
    CubicTimes candidates = cubic_roots_in_unit_interval(cubic);
    for (double t : critical)
      if (near_coplanar(t)) candidates.push_back(t);
    if (near_coplanar(1.0)) candidates.push_back(1.0);
    std::sort(candidates.begin(), candidates.end());
    for (double t : candidates) {
      if (t <= 0) continue;  // handled above
      if (auto hit = contact_at(t, false)) return hit;
    }
    return std::nullopt;
  }

 private:
  std::array<Vec3, 4> at(double t) const { return lerp(x0_, x1_, t); }

  // The gap's direction is meaningful above this distance (m); below it the primitives' own normal is used.
  double exact_contact() const { return 1e-12 * std::max(scale_, 1e-300); }

  // An impact at time t if the pair is within the contact distance there. With `only_approaching` (the start
  // of the step, and coplanar motion where the gap's direction is the in-plane approach direction) a pair
  // moving apart does not count. At a coplanarity root the gap may point anywhere in the shared plane, so
  // there it is not consulted.
  std::optional<Impact> contact_at(double t, bool only_approaching) const {
    const ClosestPoints c = closest(kind_, at(t));
    if (c.distance > options_.contact_distance) return std::nullopt;
    if (only_approaching) {
      const bool exact = c.distance <= exact_contact();
      if (t == 0 && exact) return std::nullopt;  // starts in exact contact: every direction leaves it
      const Vec3 relative_motion = weighted_sum(c.weights, x1_) - weighted_sum(c.weights, x0_);
      if (!exact && c.normal.dot(relative_motion) > 0) return std::nullopt;  // separating
    }
    return Impact{t, with_plane_normal(oriented(c), at(t))};
  }

  // The impact's constraint normal: the plane the primitives span at contact (the face's normal; the two
  // edges' cross product), on the side the first primitive came from (the sign of the weighted gap at the
  // start of the step, or at contact when it started in the plane). WHY: near a vertex or an edge end of the
  // other primitive the gap's direction turns with the contact time, so pairs around one obstacle vertex
  // touched at slightly different times gave nearly opposite normals for the same node, and the impact zone
  // met them only by moving a node of small weight by thickness / weight (27 cm in one 1 ms step of
  // conf/metal-crumple-remesh.json). Plane normals signed by the start all hold at the start positions, so
  // the zone's constraints cannot contradict each other. Kept as the gap's direction where the plane is
  // undefined (near-parallel edges, degenerate faces) or the gap runs within it (an in-plane approach).
  ClosestPoints with_plane_normal(ClosestPoints c, const std::array<Vec3, 4>& x) const {
    const Vec3 plane = coplanarity_normal(kind_, x);
    const double length = plane.norm();
    const double sides = kind_ == PairKind::kVertexFace ? (x[2] - x[1]).norm() * (x[3] - x[1]).norm()
                                                        : (x[1] - x[0]).norm() * (x[3] - x[2]).norm();
    if (!(length > kMinPlaneSine * sides)) return c;
    const Vec3 n = plane / length;
    const Vec3 start_gap = weighted_sum(c.weights, x0_);
    const double start_side = n.dot(start_gap), contact_side = n.dot(c.normal);
    double side = 0;
    if (std::abs(start_side) > kMinGapAlongPlane * start_gap.norm()) {
      side = start_side;
    } else if (std::abs(contact_side) > kMinGapAlongPlane) {
      side = contact_side;
    }
    if (side == 0) return c;  // approached within the plane: the gap's direction is the side
    c.normal = side > 0 ? n : Vec3(-n);
    return c;
  }

  // Orients the normal toward the side the first primitive came from.
  ClosestPoints oriented(ClosestPoints c) const {
    if (c.distance > exact_contact()) return c;  // the gap's own direction is the side at contact
    const Vec3 start_gap = weighted_sum(c.weights, x0_);
    const double along = c.normal.dot(start_gap);
    if (std::abs(along) >= 0.1 * start_gap.norm() && along != 0) {
      if (along < 0) c.normal = -c.normal;
    } else if (start_gap.norm() > 0) {
      // Approached within the shared plane (e.g. coplanar sliding): separate the way they came.
      c.normal = start_gap.normalized();
    }
    return c;
  }

  // First time the distance reaches the contact distance, stepping by distance / (bound on its rate): never
  // steps over a contact. Used when the motion is coplanar.
  std::optional<Impact> conservative_advancement() const {
    const double rate = distance_rate_bound(kind_, x0_, x1_);
    const double threshold = options_.contact_distance;
    if (!(rate > 0)) return std::nullopt;  // no relative motion: nothing approaches
    if (auto hit = contact_at(0.0, true)) return hit;
    double t = 0;
    for (int it = 0; it < options_.max_advancement_steps; ++it) {
      const ClosestPoints c = closest(kind_, at(t));
      if (c.distance <= threshold && t > 0) {
        if (auto hit = contact_at(t, true)) return hit;
      }
      // Step so the distance cannot fall below half the threshold; inside the threshold (moving apart) step
      // by the threshold's worth of motion.
      const double gap = c.distance > threshold ? c.distance - 0.5 * threshold : 0.5 * threshold;
      const double next = t + gap / rate;
      if (t >= 1) break;
      t = std::min(1.0, next);
    }
    return std::nullopt;
  }

  PairKind kind_;
  const std::array<Vec3, 4>& x0_;
  const std::array<Vec3, 4>& x1_;
  const CcdOptions& options_;
  double scale_;
};

}  // namespace

std::optional<Impact> vertex_face_impact(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1,
                                         const CcdOptions& options) {
  return ImpactSearch(PairKind::kVertexFace, x0, x1, options).run();
}

std::optional<Impact> edge_edge_impact(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1,
                                       const CcdOptions& options) {
  return ImpactSearch(PairKind::kEdgeEdge, x0, x1, options).run();
}

}  // namespace arcsim
