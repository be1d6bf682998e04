#include "remesh/sizing.hpp"

#include <algorithm>
#include <cmath>

#include "remesh/metric.hpp"

namespace arcsim {

namespace {

bool positive_finite(double x) { return std::isfinite(x) && x > 0; }

// Rest-space corner positions of a face in its own 2D frame (corner 0 at the origin).
std::array<Vec2, 3> frame_coordinates(const Mesh& mesh, int f) {
  const Face& face = mesh.faces[f];
  const Vec3& u0 = mesh.verts[face.v[0]].u;
  std::array<Vec2, 3> p;
  for (int i = 0; i < 3; ++i) p[i] = face.rest_frame.transpose() * (mesh.verts[face.v[i]].u - u0);
  return p;
}

// Rest-frame gradient (3x2) of a per-node vector field interpolated linearly over the face.
Mat32 field_gradient(const Face& face, const Vec3& y0, const Vec3& y1, const Vec3& y2) {
  Mat32 D;
  D.col(0) = y1 - y0;
  D.col(1) = y2 - y0;
  return D * face.Dm_inv;
}

Mat2 perp(const Mat2& A) {
  Mat2 J;
  J << 0, -1, 1, 0;
  return J * A * J.transpose();
}

Mat2 compression_term(const Mat32& F, const Mat2& curvature_squared, double c, double rib_stiffening) {
  const Mat2 G = F.transpose() * F - Mat2::Identity();
  const Mat2 D = G * G - 4 * c * c * rib_stiffening * perp(curvature_squared);
  // The signed root (as ARCSim's): where the curvature across a compression outweighs it, D turns negative and
  // its root cancels the compression instead of leaving -G / (2 c^2) behind (a rib that stiff does not buckle).
  return metric_positive_part((-G + metric_signed_sqrt(D)) / (2 * c * c));
}

Mat2 obstacle_term(const Mesh& mesh, int f, const std::vector<ObstaclePlane>& planes) {
  const Face& face = mesh.faces[f];
  Mat2 M = Mat2::Zero();
  for (int j = 0; j < 3; ++j) {
    const int node = mesh.face_node(f, j);
    if (node >= static_cast<int>(planes.size()) || !planes[node].valid) continue;
    const ObstaclePlane& plane = planes[node];
    Vec3 h;
    for (int k = 0; k < 3; ++k) h(k) = plane.normal.dot(mesh.nodes[mesh.face_node(f, k)].x - plane.point);
    const Vec2 grad = face.Dm_inv.transpose() * Vec2(h(1) - h(0), h(2) - h(0));
    // A face touching the plane would ask for zero size; the clamp to size_min bounds it anyway.
    const double mean = std::max(std::abs(h.mean()), 1e-9);
    M += grad * grad.transpose() / (3 * mean * mean);
  }
  return M;
}

Vec3 world_angles(const Mesh& mesh, int f) {
  Vec3 a;
  for (int i = 0; i < 3; ++i) a(i) = mesh.world_dihedral(mesh.faces[f].e[i]);
  return a;
}

Vec3 rest_angles(const Mesh& mesh, int f) {
  Vec3 a;
  for (int i = 0; i < 3; ++i) {
    const Edge& e = mesh.edges[mesh.faces[f].e[i]];
    a(i) = e.is_boundary() ? 0.0 : e.rest_theta;
  }
  return a;
}

}  // namespace

Mat2 face_bending_tensor(const Mesh& mesh, int f, const Vec3& angles) {
  const Face& face = mesh.faces[f];
  if (!(face.rest_area > 0)) return Mat2::Zero();
  const std::array<Vec2, 3> p = frame_coordinates(mesh, f);
  Mat2 S = Mat2::Zero();
  for (int i = 0; i < 3; ++i) {
    const Vec2 d = p[(i + 1) % 3] - p[i];
    const double l = d.norm();
    if (!(l > 0)) continue;
    const Vec2 n(d.y() / l, -d.x() / l);
    S += angles(i) * l * n * n.transpose();
  }
  return S / (2 * face.rest_area);
}

SizingTerms face_sizing_terms(const Mesh& mesh, int f, const SizingParams& params, const SizingExtras& extras) {
  SizingTerms t;
  const Face& face = mesh.faces[f];
  const RemeshingParams& r = params.remeshing;
  const Vec3& x0 = mesh.nodes[mesh.face_node(f, 0)].x;
  const Vec3& x1 = mesh.nodes[mesh.face_node(f, 1)].x;
  const Vec3& x2 = mesh.nodes[mesh.face_node(f, 2)].x;
  const Mat2 S = face_bending_tensor(mesh, f, world_angles(mesh, f));
  const Mat2 S2 = S.transpose() * S;
  if (positive_finite(r.refine_angle)) {
    const double a2 = r.refine_angle * r.refine_angle;
    t.curvature = S2 / a2;
    const Mat2 Srp = face_bending_tensor(mesh, f, rest_angles(mesh, f));
    t.rest_curvature = Srp.transpose() * Srp / a2;
  }
  if (positive_finite(r.refine_compression))
    t.compression = compression_term(field_gradient(face, x0, x1, x2), S2, r.refine_compression,
                                     params.rib_stiffening);
  if (positive_finite(r.refine_velocity)) {
    const Mat32 V = field_gradient(face, mesh.nodes[mesh.face_node(f, 0)].v, mesh.nodes[mesh.face_node(f, 1)].v,
                                   mesh.nodes[mesh.face_node(f, 2)].v);
    t.velocity = V.transpose() * V / (r.refine_velocity * r.refine_velocity);
  }
  if (extras.node_planes != nullptr) t.obstacle = obstacle_term(mesh, f, *extras.node_planes);
  if (extras.face_terms != nullptr && f < static_cast<int>(extras.face_terms->size()))
    t.extra = face.rest_frame.transpose() * (*extras.face_terms)[f] * face.rest_frame;
  return t;
}

Mat2 face_sizing(const Mesh& mesh, int f, const SizingParams& params, const SizingExtras& extras) {
  const Face& face = mesh.faces[f];
  const RemeshingParams& r = params.remeshing;
  if (extras.uniform_size > 0) return Mat2::Identity() / (extras.uniform_size * extras.uniform_size);
  const SizingTerms t = face_sizing_terms(mesh, f, params, extras);
  const std::vector<Mat2> terms{t.curvature, t.rest_curvature, t.compression, t.velocity, t.obstacle, t.extra};
  Mat2 M = Mat2::Zero();
  if (params.combine_tensors) {
    M = metric_max(terms);
  } else {
    for (const Mat2& term : terms) M += term;
  }
  if (extras.plastic_transform && !face.Fp.isIdentity(0)) {
    const Mat2 Fp = face.rest_frame.transpose() * face.Fp * face.rest_frame;
    if (std::abs(Fp.determinant()) > 1e-12) {
      const Mat2 inv = Fp.inverse();
      M = inv.transpose() * M * inv;
    }
  }
  M = clamp_metric(M, r.size_min, r.size_max, r.aspect_min);
  // Bad state (NaN velocities...) must not produce a NaN metric: fall back to the coarsest size.
  if (!M.allFinite()) M = clamp_metric(Mat2::Zero(), r.size_min, r.size_max, r.aspect_min);
  return M;
}

Mat3 face_metric_to_rest(const Face& face, const Mat2& M) {
  return face.rest_frame * M * face.rest_frame.transpose();
}

void compute_vertex_sizing(Mesh& mesh, const SizingParams& params, const SizingExtras& extras) {
  std::vector<double> weight(mesh.verts.size(), 0.0);
  for (Vert& v : mesh.verts) v.sizing.setZero();
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Face& face = mesh.faces[f];
    if (face.dead) continue;
    const Mat3 M = face_metric_to_rest(face, face_sizing(mesh, static_cast<int>(f), params, extras));
    for (int i = 0; i < 3; ++i) {
      mesh.verts[face.v[i]].sizing += face.rest_area * M;
      weight[face.v[i]] += face.rest_area;
    }
  }
  for (size_t v = 0; v < mesh.verts.size(); ++v)
    if (weight[v] > 0) mesh.verts[v].sizing /= weight[v];
}

void compute_vertex_sizing(Mesh& mesh, const SizingParams& params, const SizingExtras& extras,
                           const std::vector<int>& faces) {
  std::vector<int> verts;
  for (int f : faces)
    if (f >= 0 && f < static_cast<int>(mesh.faces.size()) && !mesh.faces[f].dead)
      for (int corner = 0; corner < 3; ++corner) {
        // Every vert of the corner's node: a border edge of the subset on a seam is measured in both faces.
        const std::vector<int>& of_node = mesh.nodes[mesh.face_node(f, corner)].verts;
        verts.insert(verts.end(), of_node.begin(), of_node.end());
      }
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  std::vector<int> around;
  for (int v : verts) {
    // Ascending face order, as the whole-mesh loop adds them.
    around = mesh.verts[v].faces;
    std::sort(around.begin(), around.end());
    Mat3 sum = Mat3::Zero();
    double weight = 0;
    for (int f : around) {
      const Face& face = mesh.faces[f];
      if (face.dead) continue;
      sum += face.rest_area * face_metric_to_rest(face, face_sizing(mesh, f, params, extras));
      weight += face.rest_area;
    }
    mesh.verts[v].sizing = weight > 0 ? Mat3(sum / weight) : Mat3::Zero();
  }
}

double vert_pair_metric_length(const Mesh& mesh, int a, int b) {
  const Vec3 du = mesh.verts[b].u - mesh.verts[a].u;
  const double m = 0.5 * (du.dot(mesh.verts[a].sizing * du) + du.dot(mesh.verts[b].sizing * du));
  return std::sqrt(std::max(m, 0.0));
}

double edge_metric_length(const Mesh& mesh, int e) {
  const Edge& edge = mesh.edges[e];
  double length = 0;
  for (int s = 0; s < 2; ++s) {
    const int f = edge.f[s];
    if (f == kNone) continue;
    const int a = mesh.faces[f].v[mesh.corner_of_node(f, edge.n[0])];
    const int b = mesh.faces[f].v[mesh.corner_of_node(f, edge.n[1])];
    length = std::max(length, vert_pair_metric_length(mesh, a, b));
  }
  return length;
}

Mat2 fracture_sizing_term(double lambda, double toughness, double size_min) {
  if (!(toughness > 0) || !(size_min > 0) || !std::isfinite(size_min)) return Mat2::Zero();
  const double s = 2 * std::max(lambda, 0.0) / (toughness * size_min);
  return s * s * Mat2::Identity();
}

}  // namespace arcsim
