#include "plasticity/plastic_tensors.hpp"

#include <array>
#include <unordered_map>

#include <Eigen/LU>

namespace arcsim {

namespace {

// Rest length l_i and unit in-plane normal n_i of each edge of a face (see the header for the convention).
struct FaceEdgeGeometry {
  std::array<double, 3> length{0, 0, 0};
  std::array<Vec3, 3> normal{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
};

FaceEdgeGeometry face_edge_geometry(const Mesh& mesh, const Face& f) {
  FaceEdgeGeometry g;
  for (int i = 0; i < 3; ++i) {
    const Vec3 d = mesh.verts[f.v[(i + 1) % 3]].u - mesh.verts[f.v[i]].u;
    g.length[i] = d.norm();
    if (g.length[i] > 0) g.normal[i] = d.cross(f.rest_normal) / g.length[i];
  }
  return g;
}

int edge_slot(const Face& f, int e) {
  for (int i = 0; i < 3; ++i)
    if (f.e[i] == e) return i;
  return kNone;
}

// Which edges to visit: the given list, or every live edge.
std::vector<int> edges_or_all(const Mesh& mesh, const std::vector<int>& edges) {
  if (!edges.empty()) return edges;
  std::vector<int> all;
  all.reserve(mesh.edges.size());
  for (size_t e = 0; e < mesh.edges.size(); ++e)
    if (!mesh.edges[e].dead) all.push_back(static_cast<int>(e));
  return all;
}

bool live_face(const Mesh& mesh, int f) { return f != kNone && !mesh.faces[f].dead; }

}  // namespace

Mat3 face_bending_strain_from_offsets(const Mesh& mesh, int face, const Vec3& offsets) {
  const Face& f = mesh.faces[face];
  Mat3 S = Mat3::Zero();
  if (!(f.rest_area > 0)) return S;
  const FaceEdgeGeometry g = face_edge_geometry(mesh, f);
  for (int i = 0; i < 3; ++i)
    S += offsets[i] * g.length[i] / (2 * f.rest_area) * g.normal[i] * g.normal[i].transpose();
  return S;
}

Vec3 face_offsets_from_bending_strain(const Mesh& mesh, int face, const Mat3& S) {
  const Face& f = mesh.faces[face];
  if (!(f.rest_area > 0) || S.isZero(0)) return Vec3::Zero();
  // In the face's 2D frame, S = sum_i d_i c_i n_i n_i^T is linear in d: the columns hold the (xx, yy, xy)
  // components of c_i n_i n_i^T. Three distinct edge directions make the system invertible.
  const FaceEdgeGeometry g = face_edge_geometry(mesh, f);
  Mat3 M;
  for (int i = 0; i < 3; ++i) {
    const Vec2 n = f.rest_frame.transpose() * g.normal[i];
    const double c = g.length[i] / (2 * f.rest_area);
    M.col(i) = c * Vec3(n.x() * n.x(), n.y() * n.y(), n.x() * n.y());
  }
  const Mat2 S2 = f.rest_frame.transpose() * S * f.rest_frame;
  const Vec3 s(S2(0, 0), S2(1, 1), 0.5 * (S2(0, 1) + S2(1, 0)));
  const Eigen::FullPivLU<Mat3> lu(M);
  if (!lu.isInvertible()) return Vec3::Zero();
  const Vec3 d = lu.solve(s);
  return d.allFinite() ? d : Vec3::Zero();
}

namespace {

// Mean of value(face, side) over the live faces of edge e (0 for an edge without any).
template <typename Value>
double mean_over_edge_faces(const Mesh& mesh, int e, Value value) {
  const Edge& ed = mesh.edges[e];
  double sum = 0;
  int count = 0;
  for (int side = 0; side < 2; ++side) {
    if (!live_face(mesh, ed.f[side])) continue;
    ++count;
    sum += value(ed.f[side]);
  }
  return count > 0 ? sum / count : 0.0;
}

}  // namespace

void update_edge_rest_angles_from_Sp(Mesh& mesh, const std::vector<int>& edges) {
  // Each face's offsets solve a 3x3 system; a face is reached from up to three of the edges, so solve it once.
  std::unordered_map<int, Vec3> offsets;
  auto face_offsets = [&](int f) -> const Vec3& {
    auto it = offsets.find(f);
    if (it == offsets.end())
      it = offsets.emplace(f, face_offsets_from_bending_strain(mesh, f, mesh.faces[f].Sp)).first;
    return it->second;
  };
  for (int e : edges_or_all(mesh, edges)) {
    if (mesh.edges[e].dead) continue;
    const double offset = mean_over_edge_faces(mesh, e, [&](int f) {
      const Face& face = mesh.faces[f];
      const int slot = edge_slot(face, e);
      return (slot == kNone || face.Sp.isZero(0)) ? 0.0 : face_offsets(f)[slot];
    });
    mesh.edges[e].rest_theta = mesh.rest_dihedral(e) + offset;
  }
}

void update_edge_damage_from_faces(Mesh& mesh, const std::vector<int>& edges) {
  for (int e : edges_or_all(mesh, edges)) {
    if (mesh.edges[e].dead) continue;
    mesh.edges[e].damage = mean_over_edge_faces(mesh, e, [&](int f) { return mesh.faces[f].damage; });
  }
}

Mat3 face_plastic_stretch_3d(const Face& face, const Mat2& Fp2) {
  if (Fp2.isIdentity(0)) return Mat3::Identity();
  return face.rest_frame * Fp2 * face.rest_frame.transpose() + face.rest_normal * face.rest_normal.transpose();
}

}  // namespace arcsim
