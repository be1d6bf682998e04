#include "fracture/fracture_stress.hpp"

#include <algorithm>
#include <cmath>

#include "physics/face_element.hpp"
#include "physics/membrane.hpp"
#include "plasticity/bend_flow.hpp"
#include "remesh/sizing.hpp"

namespace arcsim {

namespace {

// f applied to the eigenvalues of the symmetric 2x2 matrix A (closed form: no iterative solver, and no
// GCC false positive from Eigen's fixed-size eigen solver).
template <typename Fn>
Mat2 map_symmetric_eigenvalues(const Mat2& A, Fn f) {
  const double mean = 0.5 * (A(0, 0) + A(1, 1));
  const double half_diff = 0.5 * (A(0, 0) - A(1, 1));
  const double off = 0.5 * (A(0, 1) + A(1, 0));
  const double radius = std::hypot(half_diff, off);
  if (radius <= 1e-14 * std::abs(mean)) return f(mean) * Mat2::Identity();
  const double hi = mean + radius, lo = mean - radius;
  Mat2 S;
  S << A(0, 0), off, off, A(1, 1);
  // Spectral projectors P_hi = (S - lo I) / (hi - lo), P_lo = I - P_hi.
  const Mat2 P_hi = (S - lo * Mat2::Identity()) / (hi - lo);
  return f(hi) * P_hi + f(lo) * (Mat2::Identity() - P_hi);
}

double largest_eigenvalue(const Mat2& A) {
  const double mean = 0.5 * (A(0, 0) + A(1, 1));
  return mean + std::hypot(0.5 * (A(0, 0) - A(1, 1)), 0.5 * (A(0, 1) + A(1, 0)));
}

Mat2 symmetric_part(const Mat2& A) { return 0.5 * (A + A.transpose()); }

bool is_breakable(const Face& face, const std::vector<Material>& materials) {
  return !face.dead && materials[face.material].toughness > 0;
}

bool needs_normals(const Mesh& mesh, const std::vector<Material>& materials, const std::vector<int>& faces) {
  for (int f : faces)
    if (is_breakable(mesh.faces[f], materials) && materials[mesh.faces[f].material].fracture_bending_mult > 0 &&
        !has_bending_plasticity(materials[mesh.faces[f].material]))
      return true;
  return false;
}

// FE derivative of a per-corner vector field over face f, in the face's material frame (3x2, 1/m per unit).
Mat32 corner_field_gradient(const Face& face, const Vec3& y0, const Vec3& y1, const Vec3& y2) {
  Mat32 D;
  D.col(0) = y1 - y0;
  D.col(1) = y2 - y0;
  return D * face.Dm_inv;
}

// Plastic rest-angle offset (rad) of each edge of face f: what bending plasticity added to the rest dihedral.
Vec3 plastic_angle_offsets(const Mesh& mesh, int f) {
  Vec3 offsets;
  for (int i = 0; i < 3; ++i) {
    const int e = mesh.faces[f].e[i];
    offsets(i) = mesh.edges[e].is_boundary() ? 0.0 : mesh.edges[e].rest_theta - mesh.rest_dihedral(e);
  }
  return offsets;
}

Mat2 world_curvature(const Mesh& mesh, int f, const std::vector<Vec3>& node_normals) {
  const Face& face = mesh.faces[f];
  const int a = mesh.face_node(f, 0), b = mesh.face_node(f, 1), c = mesh.face_node(f, 2);
  const Mat32 F = membrane_deformation_gradient(mesh.nodes[a].x, mesh.nodes[b].x, mesh.nodes[c].x, face.Dm_inv);
  return symmetric_part(F.transpose() * corner_field_gradient(face, node_normals[a], node_normals[b],
                                                              node_normals[c]));
}

// The rest shape's own curvature: its deformation gradient is the rest frame itself.
Mat2 rest_curvature(const Face& face, const std::vector<Vec3>& vert_normals) {
  const Mat32 dn = corner_field_gradient(face, vert_normals[face.v[0]], vert_normals[face.v[1]],
                                         vert_normals[face.v[2]]);
  return symmetric_part(face.rest_frame.transpose() * dn);
}

// Elastic hinge angle (rad) of each edge of face f: world dihedral minus rest angle (rest dihedral plus plastic
// offset), what the bending elements' energy sees; 0 on a border edge (no hinge, no bending energy).
Vec3 elastic_hinge_angles(const Mesh& mesh, int f) {
  Vec3 angles;
  for (int i = 0; i < 3; ++i) {
    const int e = mesh.faces[f].e[i];
    angles(i) = mesh.edges[e].is_boundary() ? 0.0 : std::remainder(mesh.world_dihedral(e) - mesh.edges[e].rest_theta,
                                                                   2 * M_PI);
  }
  return angles;
}

// Face f's own hinge tensor in rest space (3x3, 1/m): R S R^T with R the face's rest frame.
Mat3 face_hinge_curvature(const Mesh& mesh, int f) {
  const Face& face = mesh.faces[f];
  return face.rest_frame * face_bending_tensor(mesh, f, elastic_hinge_angles(mesh, f)) * face.rest_frame.transpose();
}

// The mean of the hinge tensors of vert v's live faces, weighted by their rest areas (rest space, 1/m).
Mat3 vert_hinge_curvature(const Mesh& mesh, int v) {
  Mat3 sum = Mat3::Zero();
  double area = 0;
  for (int f : mesh.verts[v].faces) {
    if (mesh.faces[f].dead || !(mesh.faces[f].rest_area > 0)) continue;
    sum += mesh.faces[f].rest_area * face_hinge_curvature(mesh, f);
    area += mesh.faces[f].rest_area;
  }
  return area > 0 ? Mat3(sum / area) : Mat3::Zero();
}

// Eq. 8's factor (I + 1/2 alpha h II*) (dimensionless, material frame).
Mat2 bending_stretch(const Mesh& mesh, const Material& material, int f, double alpha,
                     const std::vector<Vec3>& node_normals, const std::vector<Vec3>& vert_normals) {
  const Mat2 II = has_bending_plasticity(material) ? face_hinge_elastic_curvature(mesh, f)
                                                   : face_elastic_curvature(mesh, f, node_normals, vert_normals);
  const Mat2 II_abs = map_symmetric_eigenvalues(II, [](double l) { return std::abs(l); });
  return Mat2::Identity() + 0.5 * alpha * mesh.faces[f].thickness * II_abs;
}

}  // namespace

Mat2 face_elastic_curvature(const Mesh& mesh, int f, const std::vector<Vec3>& node_normals,
                            const std::vector<Vec3>& vert_normals) {
  const Mat2 plastic = face_bending_tensor(mesh, f, plastic_angle_offsets(mesh, f));
  return world_curvature(mesh, f, node_normals) - rest_curvature(mesh.faces[f], vert_normals) - plastic;
}

Mat2 face_hinge_elastic_curvature(const Mesh& mesh, int f) {
  const Face& face = mesh.faces[f];
  Mat3 K = Mat3::Zero();
  for (int i = 0; i < 3; ++i) K += vert_hinge_curvature(mesh, face.v[i]) / 3;
  return face.rest_frame.transpose() * K * face.rest_frame;
}

FaceFractureStress face_fracture_stress(const Mesh& mesh, const std::vector<Material>& materials, int f,
                                        const std::vector<Vec3>& node_normals,
                                        const std::vector<Vec3>& vert_normals) {
  FaceFractureStress out;
  const Face& face = mesh.faces[f];
  if (!is_breakable(face, materials) || !(face.rest_area > 0)) return out;
  const Material& material = materials[face.material];
  const Mat32 F_el = membrane_deformation_gradient(mesh.nodes[mesh.face_node(f, 0)].x,
                                                   mesh.nodes[mesh.face_node(f, 1)].x,
                                                   mesh.nodes[mesh.face_node(f, 2)].x, face_elastic_dm_inv(face));
  const double alpha = material.fracture_bending_mult;
  const Mat32 F_B = alpha > 0 ? Mat32(F_el * bending_stretch(mesh, material, f, alpha, node_normals, vert_normals)) : F_el;
  const Mat2 G = 0.5 * (F_B.transpose() * F_B - Mat2::Identity());
  const Mat2 sigma = membrane_stress(G, face_membrane_stiffness(face, material));
  out.sigma = map_symmetric_eigenvalues(sigma, [](double l) { return std::max(l, 0.0); });
  out.lambda_max = std::max(largest_eigenvalue(sigma), 0.0);
  return out;
}

void update_fracture_stresses(const Mesh& mesh, const std::vector<Material>& materials,
                              const std::vector<int>& faces, std::vector<FaceFractureStress>& out) {
  out.resize(mesh.faces.size());
  std::vector<Vec3> node_normals, vert_normals;
  if (faces.size() == mesh.faces.size() && needs_normals(mesh, materials, faces)) {
    node_normals = world_node_normals(mesh);
    vert_normals = rest_vert_normals(mesh);
  } else if (needs_normals(mesh, materials, faces)) {
    // Only the normals the faces read: their corners' (O(faces), not O(mesh), for a zone's faces).
    std::vector<int> nodes, verts;
    nodes.reserve(3 * faces.size());
    verts.reserve(3 * faces.size());
    for (int f : faces) {
      if (mesh.faces[f].dead) continue;
      for (int i = 0; i < 3; ++i) {
        nodes.push_back(mesh.face_node(f, i));
        verts.push_back(mesh.faces[f].v[i]);
      }
    }
    for (std::vector<int>* list : {&nodes, &verts}) {
      std::sort(list->begin(), list->end());
      list->erase(std::unique(list->begin(), list->end()), list->end());
    }
    update_world_node_normals(mesh, nodes, node_normals);
    update_rest_vert_normals(mesh, verts, vert_normals);
  }
  const int count = static_cast<int>(faces.size());
  // Each face writes only its own slot: the result does not depend on the thread count.
#pragma omp parallel for schedule(static)
  for (int k = 0; k < count; ++k)
    out[faces[k]] = face_fracture_stress(mesh, materials, faces[k], node_normals, vert_normals);
}

std::vector<FaceFractureStress> fracture_stresses(const Mesh& mesh, const std::vector<Material>& materials) {
  std::vector<int> all(mesh.faces.size());
  for (size_t f = 0; f < all.size(); ++f) all[f] = static_cast<int>(f);
  std::vector<FaceFractureStress> out;
  update_fracture_stresses(mesh, materials, all, out);
  return out;
}

double face_toughness(const Face& face, const Material& material) { return material.toughness * face.thickness; }

Mat3 stress_to_rest(const Face& face, const Mat2& sigma) {
  return face.rest_frame * sigma * face.rest_frame.transpose();
}

}  // namespace arcsim
