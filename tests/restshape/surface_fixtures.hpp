// Curved and flat test surfaces for the reference-surface tests, plus brute-force (tree-free) geometric queries
// used as independent expectations.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "mesh/mesh.hpp"

namespace arcsim::test {

constexpr double kPi = 3.14159265358979323846;

// Triangles with rest = world positions and one vert per node.
inline Mesh mesh_from_soup(const std::vector<Vec3>& points, const std::vector<std::array<int, 3>>& tris) {
  std::vector<int> vert_node(points.size());
  for (size_t i = 0; i < points.size(); ++i) vert_node[i] = static_cast<int>(i);
  Mesh m = Mesh::from_triangles(points, points, vert_node, tris);
  m.update_rest_data();
  return m;
}

// Icosahedron subdivided `levels` times and pushed onto the sphere (20 * 4^levels faces), faces CCW seen
// from outside.
inline void icosphere(int levels, double radius, const Vec3& center, std::vector<Vec3>& points,
                      std::vector<std::array<int, 3>>& tris) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> p = {{-1, g, 0}, {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                         {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  for (Vec3& v : p) v.normalize();
  std::vector<std::array<int, 3>> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      p.push_back((p[a] + p[b]).normalized());
      return midpoint[key] = static_cast<int>(p.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& f : t) {
      const int ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    t = std::move(next);
  }
  for (auto& f : t)  // outward orientation
    if ((p[f[1]] - p[f[0]]).cross(p[f[2]] - p[f[0]]).dot(p[f[0]]) < 0) std::swap(f[1], f[2]);
  points.clear();
  for (const Vec3& v : p) points.push_back(center + radius * v);
  tris = t;
}

// Keeps only the triangles whose centroid satisfies keep(centroid) (e.g. an open hemisphere).
template <typename Keep>
std::vector<std::array<int, 3>> filter_triangles(const std::vector<Vec3>& points,
                                                 const std::vector<std::array<int, 3>>& tris, Keep keep) {
  std::vector<std::array<int, 3>> kept;
  for (const auto& f : tris)
    if (keep((points[f[0]] + points[f[1]] + points[f[2]]) / 3)) kept.push_back(f);
  return kept;
}

// Side surface of a closed cylinder about the z axis: `segments` around, `rings` along [0, height], faces CCW
// seen from outside. Node (k, j) is at angle 2 pi k / segments, height j * height / rings.
inline void cylinder(int segments, int rings, double radius, double height, std::vector<Vec3>& points,
                     std::vector<std::array<int, 3>>& tris) {
  points.clear();
  tris.clear();
  for (int j = 0; j <= rings; ++j)
    for (int k = 0; k < segments; ++k) {
      const double phi = 2 * kPi * k / segments;
      points.emplace_back(radius * std::cos(phi), radius * std::sin(phi), height * j / rings);
    }
  auto node = [&](int k, int j) { return j * segments + (k % segments); };
  for (int j = 0; j < rings; ++j)
    for (int k = 0; k < segments; ++k) {
      tris.push_back({node(k, j), node(k + 1, j), node(k + 1, j + 1)});
      tris.push_back({node(k, j), node(k + 1, j + 1), node(k, j + 1)});
    }
}

// Independent point-on-mesh check: the smallest distance from p to any triangle whose plane projection of p
// falls inside it (barycentric coordinates >= -slack), else infinity. No Voronoi-region logic involved.
inline double distance_if_inside_some_triangle(const Vec3& p, const std::vector<Vec3>& points,
                                               const std::vector<std::array<int, 3>>& tris, double slack) {
  double best = kInfinity;
  for (const auto& f : tris) {
    const Vec3 &a = points[f[0]], &b = points[f[1]], &c = points[f[2]];
    // Cheap reject: a point within `slack` of the triangle is within its longest edge of corner a.
    const double reach = std::max((b - a).squaredNorm(), (c - a).squaredNorm());
    if ((p - a).squaredNorm() > 4 * reach) continue;
    const Vec3 n = (b - a).cross(c - a);
    const double n2 = n.squaredNorm();
    const double height = n.dot(p - a) / std::sqrt(n2);
    const Vec3 q = p - height * n / std::sqrt(n2);
    const double wa = (b - q).cross(c - q).dot(n) / n2, wb = (c - q).cross(a - q).dot(n) / n2,
                 wc = (a - q).cross(b - q).dot(n) / n2;
    if (wa >= -slack && wb >= -slack && wc >= -slack) best = std::min(best, std::abs(height));
  }
  return best;
}

// Moller-Trumbore line/triangle intersection over every triangle (both signs of t): the hit of smallest |t|
// with |t| <= t_limit. False if none. An implementation independent of the tree's watertight test.
inline bool brute_force_line_hit(const Vec3& o, const Vec3& d, double t_limit, const std::vector<Vec3>& points,
                                 const std::vector<std::array<int, 3>>& tris, Vec3& hit, double& t_hit) {
  bool found = false;
  t_hit = kInfinity;
  for (const auto& f : tris) {
    const Vec3 &a = points[f[0]], &b = points[f[1]], &c = points[f[2]];
    const Vec3 e1 = b - a, e2 = c - a, pv = d.cross(e2);
    const double det = e1.dot(pv);
    if (std::abs(det) < 1e-300) continue;
    const Vec3 tv = o - a;
    const double u = tv.dot(pv) / det;
    const Vec3 qv = tv.cross(e1);
    const double v = d.dot(qv) / det;
    if (u < -1e-12 || v < -1e-12 || u + v > 1 + 1e-12) continue;
    const double t = e2.dot(qv) / det;
    if (std::abs(t) <= t_limit && std::abs(t) < std::abs(t_hit)) {
      t_hit = t;
      hit = o + t * d;
      found = true;
    }
  }
  return found;
}

inline Vec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> g(0, 1);
  Vec3 v;
  do v = Vec3(g(rng), g(rng), g(rng));
  while (v.norm() < 1e-3);
  return v.normalized();
}

}  // namespace arcsim::test
