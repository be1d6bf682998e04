#include "support/mesh_factory.hpp"

#include <cmath>

namespace arcsim::testing {

Mesh make_grid(int nx, int ny, double width, double height, Diagonal diagonal, double x0, double y0) {
  std::vector<Vec3> x;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) x.emplace_back(x0 + width * i / nx, y0 + height * j / ny, 0.0);
  std::vector<int> vert_node(x.size());
  for (size_t k = 0; k < x.size(); ++k) vert_node[k] = static_cast<int>(k);
  std::vector<std::array<int, 3>> tris;
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      const bool forward = diagonal == Diagonal::kForward || (diagonal == Diagonal::kAlternating && (i + j) % 2 == 0);
      if (forward) {  // diagonal a-c
        tris.push_back({a, b, c});
        tris.push_back({a, c, d});
      } else {  // diagonal b-d
        tris.push_back({a, b, d});
        tris.push_back({b, c, d});
      }
    }
  }
  return Mesh::from_triangles(x, x, vert_node, tris);
}

Mesh make_equilateral_strip(double length, double width, double target_edge, bool rows_along_length,
                            double x0, double straight_line_x) {
  // Build in a local (s, t) frame where rows run along s; s spans `along`, t spans `across`.
  const double along = rows_along_length ? length : width;
  const double across = rows_along_length ? width : length;
  const int ns = std::max(1, static_cast<int>(std::round(along / target_edge)));
  const int nt = std::max(1, static_cast<int>(std::round(across / (target_edge * std::sqrt(3.0) / 2))));
  const double ds = along / ns, dt = across / nt;
  // Row j has ns + 1 points, shifted by half a cell on odd rows; the boundary points are clamped to the
  // rectangle so the strip has straight ends (those boundary triangles are slightly distorted).
  std::vector<Vec3> x;
  std::vector<std::vector<int>> row_ids(nt + 1);
  for (int j = 0; j <= nt; ++j) {
    const bool odd = j % 2 == 1;
    std::vector<double> s_values;
    if (!odd) {
      for (int i = 0; i <= ns; ++i) s_values.push_back(i * ds);
    } else {
      s_values.push_back(0);
      const double extra = straight_line_x - x0;
      for (int i = 0; i < ns; ++i) {
        const double s = (i + 0.5) * ds;
        if (rows_along_length && extra > s - 0.5 * ds + 1e-9 * ds && extra < s - 1e-9 * ds) s_values.push_back(extra);
        s_values.push_back(s);
        if (rows_along_length && extra > s + 1e-9 * ds && extra < s + 0.5 * ds - 1e-9 * ds) s_values.push_back(extra);
      }
      s_values.push_back(along);
    }
    for (double s : s_values) {
      const double t = j * dt;
      row_ids[j].push_back(static_cast<int>(x.size()));
      if (rows_along_length) x.emplace_back(x0 + s, t, 0.0);
      else x.emplace_back(x0 + t, s, 0.0);
    }
  }
  std::vector<std::array<int, 3>> tris;
  for (int j = 0; j < nt; ++j) {
    const auto& lo = row_ids[j];
    const auto& hi = row_ids[j + 1];
    // Zip the two rows by their s coordinate.
    auto s_of = [&](int id) { return rows_along_length ? x[id].x() - x0 : x[id].y(); };
    size_t a = 0, b = 0;
    while (a + 1 < lo.size() || b + 1 < hi.size()) {
      const bool advance_lo =
          b + 1 >= hi.size() || (a + 1 < lo.size() && s_of(lo[a + 1]) <= s_of(hi[b + 1]) - 1e-12 * along);
      if (advance_lo) {
        tris.push_back({lo[a], lo[a + 1], hi[b]});
        ++a;
      } else {
        tris.push_back({lo[a], hi[b + 1], hi[b]});
        ++b;
      }
    }
  }
  // Orientation: rows along y mirror the frame, so flip to keep normals +z.
  if (!rows_along_length)
    for (auto& t : tris) std::swap(t[1], t[2]);
  std::vector<int> vert_node(x.size());
  for (size_t k = 0; k < x.size(); ++k) vert_node[k] = static_cast<int>(k);
  return Mesh::from_triangles(x, x, vert_node, tris);
}

}  // namespace arcsim::testing
