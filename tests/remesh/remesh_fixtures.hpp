// Curved test sheets for the remeshing tests (rest = world unless stated) and measurements of their shape.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"
#include "mesh/validate.hpp"
#include "physics/material.hpp"

namespace arcsim::remesh_test {

constexpr double kPi = 3.14159265358979323846;

// Orients every triangle so that its normal points away from `inside(p)`'s reference point: outward(p) returns
// the outward direction at point p.
template <typename Outward>
void orient(std::vector<std::array<int, 3>>& tris, const std::vector<Vec3>& p, Outward outward) {
  for (auto& t : tris) {
    const Vec3 c = (p[t[0]] + p[t[1]] + p[t[2]]) / 3;
    if ((p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]).dot(outward(c)) < 0) std::swap(t[1], t[2]);
  }
}

inline Mesh mesh_from(const std::vector<Vec3>& p, const std::vector<std::array<int, 3>>& tris) {
  std::vector<int> vert_node(p.size());
  for (size_t i = 0; i < p.size(); ++i) vert_node[i] = static_cast<int>(i);
  return Mesh::from_triangles(p, p, vert_node, tris);
}

// Icosahedron subdivided `levels` times, on the sphere of `radius` about the origin.
inline Mesh make_icosphere(double radius, int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> p{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                      {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> tris{{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      p.push_back(0.5 * (p[a] + p[b]));
      return mid[key] = static_cast<int>(p.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& tr : tris) {
      const int ab = midpoint(tr[0], tr[1]), bc = midpoint(tr[1], tr[2]), ca = midpoint(tr[2], tr[0]);
      next.push_back({tr[0], ab, ca});
      next.push_back({tr[1], bc, ab});
      next.push_back({tr[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    tris = next;
  }
  for (Vec3& q : p) q = radius * q.normalized();
  orient(tris, p, [](const Vec3& c) { return c; });
  return mesh_from(p, tris);
}

// Spherical cap of `radius` about the origin around +z, up to polar angle `polar_max` (rad): a hexagonal disk of
// `rings` rings (6 i nodes on ring i) mapped to polar angle polar_max i / rings.
inline Mesh make_spherical_cap(double radius, double polar_max, int rings) {
  std::vector<Vec3> p{Vec3(0, 0, radius)};
  std::vector<int> ring_start{0};
  for (int i = 1; i <= rings; ++i) {
    ring_start.push_back(static_cast<int>(p.size()));
    const double polar = polar_max * i / rings;
    for (int k = 0; k < 6 * i; ++k) {
      const double azimuth = 2 * kPi * k / (6 * i);
      p.emplace_back(radius * std::sin(polar) * std::cos(azimuth), radius * std::sin(polar) * std::sin(azimuth),
                     radius * std::cos(polar));
    }
  }
  auto node = [&](int ring, int k) {
    if (ring == 0) return 0;
    return ring_start[ring] + (k % (6 * ring) + 6 * ring) % (6 * ring);
  };
  std::vector<std::array<int, 3>> tris;
  for (int i = 1; i <= rings; ++i)
    for (int s = 0; s < 6; ++s) {
      for (int k = 0; k < i; ++k)
        tris.push_back({node(i - 1, s * (i - 1) + k), node(i, s * i + k), node(i, s * i + k + 1)});
      for (int k = 0; k + 1 < i; ++k)
        tris.push_back({node(i - 1, s * (i - 1) + k), node(i, s * i + k + 1), node(i - 1, s * (i - 1) + k + 1)});
    }
  orient(tris, p, [](const Vec3& c) { return c; });
  return mesh_from(p, tris);
}

// Upper hemisphere (z >= 0) of `radius` about the origin, `rings` rings from the pole to the equator.
inline Mesh make_hemisphere(double radius, int rings) { return make_spherical_cap(radius, 0.5 * kPi, rings); }

// Open tube of `radius` about the z axis over z in [0, length]: `around` nodes per ring, `rings` + 1 rings.
inline Mesh make_cylinder(double radius, double length, int around, int rings) {
  std::vector<Vec3> p;
  for (int j = 0; j <= rings; ++j)
    for (int i = 0; i < around; ++i) {
      const double phi = 2 * kPi * (i + 0.5 * (j % 2)) / around;
      p.emplace_back(radius * std::cos(phi), radius * std::sin(phi), length * j / rings);
    }
  auto id = [&](int i, int j) { return j * around + (i % around); };
  std::vector<std::array<int, 3>> tris;
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < around; ++i) {
      // Staggered rings: nearly equilateral triangles.
      if (j % 2 == 0) {
        tris.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        tris.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  orient(tris, p, [](const Vec3& c) { return Vec3(c.x(), c.y(), 0); });
  return mesh_from(p, tris);
}

inline Material glass() {
  Material m;
  m.name = "glass";
  m.thickness = 2e-3;
  m.density = 2500;
  m.youngs_modulus = 50e9;
  m.poisson_ratio = 0.2;
  return m;
}

inline Material cotton() {
  Material m;
  m.name = "cloth";
  m.thickness = 5e-4;
  m.density = 300;
  m.youngs_modulus = 5e6;
  m.poisson_ratio = 0.3;
  return m;
}

inline void set_thickness(Mesh& mesh, const Material& m) {
  for (Face& f : mesh.faces) f.thickness = m.thickness;
}

inline int live_faces(const Mesh& m) {
  return static_cast<int>(std::count_if(m.faces.begin(), m.faces.end(), [](const Face& f) { return !f.dead; }));
}

inline double rest_area(const Mesh& m) {
  double a = 0;
  for (const Face& f : m.faces)
    if (!f.dead) a += f.rest_area;
  return a;
}

// Volume enclosed by a closed rest surface (divergence theorem).
inline double rest_volume(const Mesh& m) {
  double v = 0;
  for (const Face& f : m.faces)
    if (!f.dead) v += m.verts[f.v[0]].u.dot(m.verts[f.v[1]].u.cross(m.verts[f.v[2]].u)) / 6;
  return v;
}

// Volume enclosed by a rest tube about the z axis between the planes of its ends (m^3): the flux of
// (x, y, 0) / 2, whose divergence is 1, through the faces (the flat end caps add none). Exact per face with the
// centroid, as the field is linear.
inline double rest_volume_about_z(const Mesh& m) {
  double v = 0;
  for (const Face& f : m.faces) {
    if (f.dead) continue;
    const Vec3 &u0 = m.verts[f.v[0]].u, &u1 = m.verts[f.v[1]].u, &u2 = m.verts[f.v[2]].u;
    const Vec3 c = (u0 + u1 + u2) / 3;
    v += (u1 - u0).cross(u2 - u0).dot(Vec3(c.x(), c.y(), 0)) / 4;
  }
  return v;
}

// Every live face keeps a positive rest area and a rest normal within 90 degrees of the direction outward(c).
template <typename Outward>
std::string inverted_face(const Mesh& m, Outward outward) {
  for (size_t f = 0; f < m.faces.size(); ++f) {
    const Face& face = m.faces[f];
    if (face.dead) continue;
    const Vec3 c = (m.verts[face.v[0]].u + m.verts[face.v[1]].u + m.verts[face.v[2]].u) / 3;
    if (!(face.rest_area > 0) || face.rest_normal.dot(outward(c)) <= 0) return "face " + std::to_string(f);
  }
  return "";
}

}  // namespace arcsim::remesh_test
