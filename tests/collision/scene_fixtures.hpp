// Helpers for the collision scenarios: scenes built in code from the repository's meshes and generated ones,
// and the checks (exact triangle-triangle intersections between non-adjacent triangles).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <random>
#include <string>

#include <Eigen/Geometry>

#include "collision/intersections.hpp"
#include "collision/triangle_intersection.hpp"
#include "io/obj.hpp"
#include "sim/simulation.hpp"
#include "support/files.hpp"

namespace arcsim::testing {

namespace fs = std::filesystem;

// A light, soft sheet (cloth-like): 0.15 kg/m^2.
inline Material sheet_material() {
  Material m;
  m.name = "test sheet";
  m.thickness = 5e-4;
  m.density = 300;
  m.youngs_modulus = 2e7;
  m.poisson_ratio = 0.3;
  return m;
}

inline Transform make_transform(const Vec3& translation, const Eigen::Quaterniond& rotation = Eigen::Quaterniond::Identity(),
                                double scale = 1) {
  Transform t;
  t.translation = translation;
  t.rotation = rotation;
  t.scale = scale;
  return t;
}

// Rotation taking the meshes' xy plane to the horizontal xz plane (y up): -90 degrees about x.
inline Eigen::Quaterniond lay_flat() { return Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitX())); }

inline Scene base_scene(double dt, double end_time) {
  Scene s;
  s.path = "collision-test-scene";
  s.frame_time = dt;
  s.frame_steps = 1;
  s.step_time = dt;
  s.end_time = end_time;
  s.gravity = Vec3(0, -9.8, 0);
  s.wind.density = 0;
  // Collision scenarios: fixed meshes (no remeshing) and only the dynamics and contact modules.
  s.disabled = {"remeshing", "plasticity", "fracture", "strainlimiting", "separation", "popfilter"};
  return s;
}

inline ClothSpec cloth_spec(const fs::path& mesh, const Transform& t, const Material& m = sheet_material()) {
  ClothSpec c;
  c.mesh = mesh.string();
  c.transform = t;
  c.materials = {m};
  return c;
}

inline ObstacleSpec obstacle_spec(const fs::path& mesh, const Transform& t, const std::string& proxy = "") {
  ObstacleSpec o;
  o.mesh = mesh.string();
  o.transform = t;
  o.proxy = proxy;
  return o;
}

// An icosahedron subdivided `levels` times, projected on the sphere of radius r about the origin.
inline Mesh make_sphere(double r, int levels) {
  const double p = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> x{{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                      {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  std::vector<std::array<int, 3>> tris{{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> middle;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = middle.find(key);
      if (it != middle.end()) return it->second;
      x.push_back(0.5 * (x[a] + x[b]));
      middle[key] = static_cast<int>(x.size()) - 1;
      return static_cast<int>(x.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& t : tris) {
      const int a = mid(t[0], t[1]), b = mid(t[1], t[2]), c = mid(t[2], t[0]);
      next.push_back({t[0], a, c});
      next.push_back({t[1], b, a});
      next.push_back({t[2], c, b});
      next.push_back({a, b, c});
    }
    tris.swap(next);
  }
  for (Vec3& v : x) v = r * v.normalized();
  std::vector<int> vert_node(x.size());
  for (size_t i = 0; i < x.size(); ++i) vert_node[i] = static_cast<int>(i);
  return Mesh::from_triangles(x, x, vert_node, tris);
}

inline std::array<Vec3, 3> world_triangle(const Mesh& m, int f) {
  return {m.nodes[m.face_node(f, 0)].x, m.nodes[m.face_node(f, 1)].x, m.nodes[m.face_node(f, 2)].x};
}

// Intersecting pairs of triangles: within each cloth (pairs sharing no node), between cloths, and between
// cloths and active obstacles (collision/intersections.hpp: exact, through bounding-volume hierarchies).
inline int count_intersecting_pairs(const Simulation& sim) {
  std::vector<const Mesh*> sheets, obstacles;
  for (const Cloth& c : sim.cloths) sheets.push_back(&c.mesh);
  for (const Obstacle& o : sim.obstacles)
    if (o.active) obstacles.push_back(&o.mesh);
  return static_cast<int>(intersecting_pairs(sheets, obstacles).size());
}

inline double lowest_cloth_y(const Simulation& sim) {
  double y = kInfinity;
  for (const Cloth& c : sim.cloths)
    for (const Node& n : c.mesh.nodes) y = std::min(y, n.x.y());
  return y;
}

}  // namespace arcsim::testing
