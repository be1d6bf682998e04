#include "render/render_mesh.hpp"

#include <algorithm>
#include <cstdint>
#include <tuple>

#include "math/errors.hpp"
#include "mesh/mesh.hpp"

namespace arcsim {

namespace {

// One directed triangle side, remembered with its position in the input so results keep input order.
struct Side {
  int lo, hi;      // undirected key
  int from, to;    // direction in its triangle
  size_t order;    // 3 * triangle + corner
};

std::vector<Side> sides_of(const std::vector<std::array<int, 3>>& triangles) {
  std::vector<Side> sides;
  sides.reserve(3 * triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;
    for (int c = 0; c < 3; ++c) {
      const int a = tri[c], b = tri[(c + 1) % 3];
      sides.push_back({std::min(a, b), std::max(a, b), a, b, 3 * t + c});
    }
  }
  std::sort(sides.begin(), sides.end(), [](const Side& x, const Side& y) {
    return std::tie(x.lo, x.hi, x.order) < std::tie(y.lo, y.hi, y.order);
  });
  return sides;
}

}  // namespace

std::vector<std::array<int, 2>> boundary_edges(const std::vector<std::array<int, 3>>& triangles) {
  const std::vector<Side> sides = sides_of(triangles);
  std::vector<const Side*> lonely;
  for (size_t i = 0; i < sides.size();) {
    size_t j = i + 1;
    while (j < sides.size() && sides[j].lo == sides[i].lo && sides[j].hi == sides[i].hi) ++j;
    if (j - i == 1) lonely.push_back(&sides[i]);
    i = j;
  }
  std::sort(lonely.begin(), lonely.end(), [](const Side* x, const Side* y) { return x->order < y->order; });
  std::vector<std::array<int, 2>> edges;
  edges.reserve(lonely.size());
  for (const Side* s : lonely) edges.push_back({s->from, s->to});
  return edges;
}

std::vector<std::array<int, 2>> unique_edges(const std::vector<std::array<int, 3>>& triangles) {
  // Packing both indices into one integer makes the sort a plain integer sort (this runs every frame).
  std::vector<uint64_t> keys;
  keys.reserve(3 * triangles.size());
  for (const auto& tri : triangles)
    for (int c = 0; c < 3; ++c) {
      const int a = tri[c], b = tri[(c + 1) % 3];
      if (a == b) continue;
      const uint64_t lo = uint32_t(std::min(a, b)), hi = uint32_t(std::max(a, b));
      keys.push_back(lo << 32 | hi);
    }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<std::array<int, 2>> edges;
  edges.reserve(keys.size());
  for (uint64_t k : keys) edges.push_back({int(k >> 32), int(k & 0xffffffffu)});
  return edges;
}

RenderMesh make_render_mesh(std::vector<Vec3> positions, std::vector<std::array<int, 3>> triangles,
                            bool highlight_boundary) {
  RenderMesh mesh;
  mesh.positions = std::move(positions);
  mesh.triangles = std::move(triangles);
  if (highlight_boundary) mesh.highlight_edges = boundary_edges(mesh.triangles);
  return mesh;
}

RenderMesh render_mesh_from(const Mesh& mesh, bool highlight_boundary) {
  // Dead nodes are skipped, so node indices are renumbered densely.
  std::vector<int> render_index(mesh.nodes.size(), kNone);
  std::vector<Vec3> positions;
  positions.reserve(mesh.nodes.size());
  for (size_t n = 0; n < mesh.nodes.size(); ++n) {
    if (mesh.nodes[n].dead) continue;
    render_index[n] = int(positions.size());
    positions.push_back(mesh.nodes[n].x);
  }
  std::vector<std::array<int, 3>> triangles;
  triangles.reserve(mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (mesh.faces[f].dead) continue;
    std::array<int, 3> tri;
    bool ok = true;
    for (int c = 0; c < 3; ++c) {
      const int v = mesh.faces[f].v[c];
      const int node = v >= 0 && v < int(mesh.verts.size()) ? mesh.verts[v].node : kNone;
      tri[c] = node >= 0 && node < int(render_index.size()) ? render_index[node] : kNone;
      ok = ok && tri[c] != kNone;
    }
    if (ok) triangles.push_back(tri);
  }
  return make_render_mesh(std::move(positions), std::move(triangles), highlight_boundary);
}

Eigen::AlignedBox3d bounds_of(const RenderMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (const Vec3& p : mesh.positions)
    if (p.allFinite()) box.extend(p);
  return box;
}

Eigen::AlignedBox3d bounds_of(const std::vector<RenderMesh>& meshes) {
  Eigen::AlignedBox3d box;
  for (const RenderMesh& m : meshes) {
    const Eigen::AlignedBox3d b = bounds_of(m);
    if (!b.isEmpty()) box.extend(b);
  }
  return box;
}

Eigen::AlignedBox3d bulk_bounds(const std::vector<Vec3>& points, double fraction) {
  std::array<std::vector<double>, 3> coordinates;
  for (const Vec3& p : points)
    if (p.allFinite())
      for (int a = 0; a < 3; ++a) coordinates[a].push_back(p(a));
  Eigen::AlignedBox3d box;
  if (coordinates[0].empty()) return box;
  const size_t n = coordinates[0].size();
  const size_t low = std::min(n - 1, static_cast<size_t>(std::clamp(fraction, 0.0, 0.5) * (n - 1)));
  const size_t high = n - 1 - low;
  Vec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    std::vector<double>& c = coordinates[a];
    std::nth_element(c.begin(), c.begin() + low, c.end());
    lo(a) = c[low];
    std::nth_element(c.begin(), c.begin() + high, c.end());
    hi(a) = c[high];
  }
  box.extend(lo);
  box.extend(hi);
  return box;
}

void check_render_mesh(const RenderMesh& mesh, const std::string& what) {
  const int n = int(mesh.positions.size());
  for (int i = 0; i < n; ++i)
    if (!mesh.positions[i].allFinite())
      throw InputError(what + ": vertex " + std::to_string(i) + " has a non-finite position");
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int v : mesh.triangles[t])
      if (v < 0 || v >= n)
        throw InputError(what + ": triangle " + std::to_string(t) + " refers to vertex " + std::to_string(v) +
                         " of " + std::to_string(n));
  for (size_t e = 0; e < mesh.highlight_edges.size(); ++e)
    for (int v : mesh.highlight_edges[e])
      if (v < 0 || v >= n)
        throw InputError(what + ": highlight edge " + std::to_string(e) + " refers to vertex " +
                         std::to_string(v) + " of " + std::to_string(n));
}

}  // namespace arcsim
