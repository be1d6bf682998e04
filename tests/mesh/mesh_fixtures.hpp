// Small meshes and helpers shared by the mesh tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "mesh/mesh.hpp"

namespace arcsim::test {

constexpr double kPi = 3.14159265358979323846;

// Grid node (i, j) of an (nx+1) x (ny+1) node lattice.
inline int grid_node(int nx, int i, int j) { return j * (nx + 1) + i; }

// Triangles of an nx x ny cell lattice over vert indices vert(i, j), counter-clockwise in the (i, j) plane,
// with alternating diagonals so that nodes have different valences.
template <typename VertIndex>
std::vector<std::array<int, 3>> grid_triangles(int nx, int ny, VertIndex vert) {
  std::vector<std::array<int, 3>> tris;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = vert(i, j), b = vert(i + 1, j), c = vert(i + 1, j + 1), d = vert(i, j + 1);
      if ((i + j) % 2 == 0) {
        tris.push_back({a, b, c});
        tris.push_back({a, c, d});
      } else {
        tris.push_back({a, b, d});
        tris.push_back({b, c, d});
      }
    }
  return tris;
}

// Flat sheet [0, w] x [0, h] in the xy plane; world = rest, lifted by 1 m in z so that x and u differ.
inline Mesh make_flat_grid(int nx, int ny, double w = 1.0, double h = 1.0) {
  std::vector<Vec3> x, u;
  std::vector<int> vert_node;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const Vec3 p(w * i / nx, h * j / ny, 0.0);
      u.push_back(p);
      x.push_back(p + Vec3(0, 0, 1));
      vert_node.push_back(static_cast<int>(vert_node.size()));
    }
  return Mesh::from_triangles(x, u, vert_node, grid_triangles(nx, ny, [&](int i, int j) { return grid_node(nx, i, j); }));
}

// A curved sheet: the grid rolled onto a cylinder of `radius` over `angle` radians, in rest and world space.
inline Mesh make_cylinder_patch(int nx, int ny, double radius, double angle, double height) {
  std::vector<Vec3> x, u;
  std::vector<int> vert_node;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const double phi = angle * i / nx;
      const Vec3 p(radius * std::sin(phi), height * j / ny, radius * std::cos(phi));
      u.push_back(p);
      x.push_back(p);
      vert_node.push_back(static_cast<int>(vert_node.size()));
    }
  return Mesh::from_triangles(x, u, vert_node, grid_triangles(nx, ny, [&](int i, int j) { return grid_node(nx, i, j); }));
}

// A closed tube in world space whose rest shape is the flat unrolled rectangle [0, circumference] x [0, height]:
// the nodes of column 0 carry two rest verts each (u.x = 0 and u.x = circumference), a rest-space seam.
// Vert (i, j) for i in [0, nx] has index j*(nx+1)+i; node (i mod nx, j) has index j*nx + (i mod nx).
inline Mesh make_seamed_tube(int nx, int ny, double radius, double height) {
  const double circumference = 2 * kPi * radius;
  std::vector<Vec3> x, u;
  std::vector<int> vert_node;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double phi = 2 * kPi * i / nx;
      x.emplace_back(radius * std::cos(phi), radius * std::sin(phi), height * j / ny);
    }
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      u.emplace_back(circumference * i / nx, height * j / ny, 0.0);
      vert_node.push_back(j * nx + i % nx);
    }
  return Mesh::from_triangles(x, u, vert_node, grid_triangles(nx, ny, [&](int i, int j) { return j * (nx + 1) + i; }));
}

// Fills per-element state with distinct random values in known ranges: thickness in [1, 2] mm, damage in
// [0, 1], Fp = I + entries in [-0.1, 0.1], Sp entries in [-1, 1], node v and a in [-1, 1], edge damage in
// [0, 1] and a plastic offset in [-0.1, 0.1] on top of the rest dihedral.
inline void fill_random_state(Mesh& m, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0), sym(-1.0, 1.0);
  for (Face& f : m.faces) {
    f.thickness = 1e-3 * (1 + unit(rng));
    f.damage = unit(rng);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        f.Fp(r, c) = (r == c ? 1.0 : 0.0) + 0.1 * sym(rng);
        f.Sp(r, c) = sym(rng);
      }
  }
  for (Node& n : m.nodes) {
    n.v = Vec3(sym(rng), sym(rng), sym(rng));
    n.a = Vec3(sym(rng), sym(rng), sym(rng));
    n.x0 = n.x + 0.01 * Vec3(sym(rng), sym(rng), sym(rng));
    n.mass = 0.1 + unit(rng);
  }
  for (size_t e = 0; e < m.edges.size(); ++e) {
    m.edges[e].damage = unit(rng);
    m.edges[e].rest_theta = m.rest_dihedral(static_cast<int>(e)) + 0.1 * sym(rng);
  }
}

// A hash of everything an edit could touch, to see that a refused edit changed nothing.
class Fingerprint {
 public:
  // One 64-bit word at a time (FNV-style mixing): fast enough to run after every edit.
  void add_word(uint64_t w) { hash_ = (hash_ ^ w ^ (w >> 29)) * 1099511628211ull; }
  void add_int(long long v) { add_word(static_cast<uint64_t>(v)); }
  void add_double(double v) {
    uint64_t w;
    std::memcpy(&w, &v, sizeof w);
    add_word(w);
  }
  template <typename M>
  void add_matrix(const M& matrix) {
    for (int i = 0; i < matrix.size(); ++i) add_double(matrix.data()[i]);
  }
  void add_list(const std::vector<int>& list) {
    add_int(static_cast<long long>(list.size()));
    for (int x : list) add_int(x);
  }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 1469598103934665603ull;
};

inline uint64_t fingerprint(const Mesh& m) {
  Fingerprint h;
  for (const Node& n : m.nodes) {
    h.add_int(n.dead);
    h.add_matrix(n.x);
    h.add_matrix(n.x0);
    h.add_matrix(n.v);
    h.add_matrix(n.a);
    h.add_int(n.label);
    h.add_int(n.preserve);
    h.add_double(n.mass);
    h.add_list(n.verts);
    h.add_list(n.edges);
  }
  for (const Vert& v : m.verts) {
    h.add_int(v.dead);
    h.add_matrix(v.u);
    h.add_int(v.node);
    h.add_list(v.faces);
    h.add_matrix(v.sizing);
  }
  for (const Edge& e : m.edges) {
    h.add_int(e.dead);
    for (int s = 0; s < 2; ++s) {
      h.add_int(e.n[s]);
      h.add_int(e.f[s]);
    }
    h.add_double(e.rest_theta);
    h.add_double(e.damage);
    h.add_int(e.preserve);
  }
  for (const Face& f : m.faces) {
    h.add_int(f.dead);
    for (int i = 0; i < 3; ++i) {
      h.add_int(f.v[i]);
      h.add_int(f.e[i]);
    }
    h.add_int(f.material);
    h.add_double(f.thickness);
    h.add_matrix(f.Fp);
    h.add_matrix(f.Sp);
    h.add_double(f.damage);
    h.add_double(f.rest_area);
  }
  h.add_int(m.is_compact());
  return h.value();
}

// Total rest area of the live faces (m^2).
inline double total_rest_area(const Mesh& m) {
  double area = 0;
  for (const Face& f : m.faces)
    if (!f.dead) area += f.rest_area;
  return area;
}

inline int live_count(const std::vector<Face>& faces) {
  int n = 0;
  for (const Face& f : faces) n += !f.dead;
  return n;
}
inline int live_count(const std::vector<Node>& nodes) {
  int n = 0;
  for (const Node& x : nodes) n += !x.dead;
  return n;
}
inline int live_count(const std::vector<Edge>& edges) {
  int n = 0;
  for (const Edge& x : edges) n += !x.dead;
  return n;
}
inline int live_count(const std::vector<Vert>& verts) {
  int n = 0;
  for (const Vert& x : verts) n += !x.dead;
  return n;
}

// The live face over nodes {a, b, c} (any order), or kNone.
inline int find_face(const Mesh& m, int a, int b, int c) {
  std::array<int, 3> want{a, b, c};
  std::sort(want.begin(), want.end());
  for (size_t f = 0; f < m.faces.size(); ++f) {
    if (m.faces[f].dead) continue;
    const int fi = static_cast<int>(f);
    std::array<int, 3> have{m.face_node(fi, 0), m.face_node(fi, 1), m.face_node(fi, 2)};
    std::sort(have.begin(), have.end());
    if (have == want) return fi;
  }
  return kNone;
}

// Component label of every face (kNone for dead faces), by flood fill across interior edges.
inline std::vector<int> face_components(const Mesh& m) {
  std::vector<int> label(m.faces.size(), kNone);
  int next = 0;
  for (size_t seed = 0; seed < m.faces.size(); ++seed) {
    if (m.faces[seed].dead || label[seed] != kNone) continue;
    std::vector<int> stack{static_cast<int>(seed)};
    label[seed] = next;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      for (int e : m.faces[f].e) {
        const int g = m.other_face(e, f);
        if (g != kNone && label[g] == kNone) {
          label[g] = next;
          stack.push_back(g);
        }
      }
    }
    ++next;
  }
  return label;
}

}  // namespace arcsim::test
