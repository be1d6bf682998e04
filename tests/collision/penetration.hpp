// How deep cloth nodes lie inside obstacles, for the collision tests. Inside a closed obstacle mesh means a
// winding number above 1/2 (the sum of the solid angles its faces subtend, Van Oosterom and Strackee 1983:
// exact for closed meshes, no pseudonormal corner cases); the depth is then the distance to the surface. Open
// obstacle meshes (a floor sheet, a wall) have no inside; the floor proxy's inside is below the plane
// y = floor height.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "collision/distance.hpp"
#include "sim/simulation.hpp"

namespace arcsim::testing {

// An obstacle mesh's triangles, whether it is closed (every edge shared by exactly two faces), and the depth
// of points inside it.
class ObstacleSurface {
 public:
  explicit ObstacleSurface(const Mesh& m) {
    std::map<std::pair<int, int>, int> edge_faces;
    for (int f = 0; f < static_cast<int>(m.faces.size()); ++f) {
      std::array<Vec3, 3> t;
      for (int k = 0; k < 3; ++k) {
        t[k] = m.nodes[m.face_node(f, k)].x;
        ++edge_faces[std::minmax(m.face_node(f, k), m.face_node(f, (k + 1) % 3))];
      }
      tris_.push_back(t);
    }
    closed_ = !tris_.empty();
    for (const auto& e : edge_faces) closed_ = closed_ && e.second == 2;
  }

  bool closed() const { return closed_; }

  // Distance (m) from p to the surface.
  double distance(const Vec3& p) const {
    double best = kInfinity;
    for (const auto& t : tris_) {
      const Vec3 b = closest_triangle_barycentrics(p, t[0], t[1], t[2]);
      best = std::min(best, (p - (b[0] * t[0] + b[1] * t[1] + b[2] * t[2])).norm());
    }
    return best;
  }

  // Sum of the signed solid angles of the faces seen from p, over 4 pi: 1 inside a closed outward mesh, 0
  // outside.
  double winding_number(const Vec3& p) const {
    double total = 0;
    for (const auto& t : tris_) {
      const Vec3 a = t[0] - p, b = t[1] - p, c = t[2] - p;
      const double la = a.norm(), lb = b.norm(), lc = c.norm();
      total += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la);
    }
    return total / (4 * M_PI);
  }

  // How deep p lies inside (m): 0 outside, or for an open mesh.
  double depth(const Vec3& p) const {
    if (!closed_ || std::abs(winding_number(p)) < 0.5) return 0;
    return distance(p);
  }

 private:
  std::vector<std::array<Vec3, 3>> tris_;
  bool closed_ = false;
};

// The deepest any cloth node lies inside an active obstacle or under the floor proxy (m; 0 when none is).
inline double deepest_penetration(const Simulation& sim) {
  double deepest = 0;
  for (const Obstacle& o : sim.obstacles) {
    if (!o.active) continue;
    double floor = kInfinity;
    for (const Node& n : o.mesh.nodes) floor = std::min(floor, n.x.y());
    const ObstacleSurface surface(o.mesh);
    for (const Cloth& c : sim.cloths)
      for (const Node& n : c.mesh.nodes) {
        deepest = std::max(deepest, surface.depth(n.x));
        if (o.floor) deepest = std::max(deepest, floor - n.x.y());
      }
  }
  return deepest;
}

}  // namespace arcsim::testing
