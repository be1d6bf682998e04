#include "physics/face_element.hpp"

#include <algorithm>
#include <cmath>

#include "physics/plate_bending.hpp"

namespace arcsim {

double damage_weakening(const Material& material, double damage) {
  return 1.0 / (1.0 + material.weakening * damage);
}

double weakened_bending_stiffness(double kb, const Material& material, double damage) {
  return kb / (1.0 + material.weakening * damage);
}

MembraneStiffness face_membrane_stiffness(const Face& face, const Material& material,
                                          MembraneWeakening weakening) {
  MembraneStiffness k = material.membrane_stiffness(face.thickness);
  if (weakening == MembraneWeakening::kIgnored) return k;
  const double w = damage_weakening(material, face.damage);
  k.k11 *= w, k.k12 *= w, k.k22 *= w, k.k33 *= w;
  return k;
}

Mat2 face_plastic_stretch_2d(const Face& face) {
  if (face.Fp.isIdentity(0)) return Mat2::Identity();
  return face.rest_frame.transpose() * face.Fp * face.rest_frame;
}

Mat2 face_elastic_dm_inv(const Face& face) { return face.Dm_inv * face_plastic_stretch_2d(face); }

double face_corner_mass(const Face& face, const Material& material) {
  return material.area_density(face.thickness) * face.rest_area / 3;
}

Mat3 face_bending_matrix(const Mesh& mesh, const Material& material, int f, const std::array<bool, 3>& has_wing) {
  const Face& face = mesh.faces[f];
  std::array<double, 3> lengths, kb;
  std::array<Vec3, 3> normals;
  for (int i = 0; i < 3; ++i) {
    const Vec3 d = mesh.verts[face.v[(i + 1) % 3]].u - mesh.verts[face.v[i]].u;
    lengths[i] = d.norm();
    normals[i] = lengths[i] > 0 ? Vec3(d.cross(face.rest_normal) / lengths[i]) : Vec3::Zero();
    // Bending about an axis along the edge (its angle in the material frame matters for data-driven
    // materials), weakened by the edge's plastic damage.
    const double angle = std::atan2(face.rest_frame.col(1).dot(d), face.rest_frame.col(0).dot(d));
    kb[i] = weakened_bending_stiffness(material.bending_stiffness(face.thickness, angle), material,
                                       mesh.edges[face.e[i]].damage);
  }
  // Direction-dependent stiffness (data-driven materials) enters as sqrt(kb_i kb_j) in Q.
  const double nu = material.data_driven ? 0.0 : material.poisson_ratio;
  Mat3 Q = plate_bending_matrix(lengths, normals, face.rest_area, 1.0, nu, has_wing);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Q(i, j) *= std::sqrt(kb[i] * kb[j]);
  return Q;
}

std::vector<int> bending_faces_of_node(const Mesh& mesh, int n) {
  std::vector<int> faces = mesh.node_faces(n);
  const size_t own = faces.size();
  for (size_t k = 0; k < own; ++k) {
    const int f = faces[k];
    const int across = mesh.other_face(mesh.faces[f].e[(mesh.corner_of_node(f, n) + 1) % 3], f);
    if (across != kNone) faces.push_back(across);
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

FaceElement make_face_element(const Mesh& mesh, const std::vector<Material>& materials, int f) {
  const Face& face = mesh.faces[f];
  const Material& material = materials[face.material];
  FaceElement el;
  for (int i = 0; i < 3; ++i) el.nodes[i] = mesh.face_node(f, i);
  el.dofs = el.nodes;
  el.blocks.fill(-1);
  el.Dm_inv = face_elastic_dm_inv(face);
  el.area = face.rest_area;
  el.k = face_membrane_stiffness(face, material);
  el.damping = material.damping;
  return el;
}

BendingElement make_bending_element(const Mesh& mesh, const std::vector<Material>& materials, int f) {
  const Face& face = mesh.faces[f];
  const Material& material = materials[face.material];
  BendingElement b;
  for (int i = 0; i < 3; ++i) b.nodes[i] = mesh.face_node(f, i);
  for (int i = 0; i < 3; ++i) {
    const int e = face.e[i];
    const int other = mesh.other_face(e, f);
    b.has_wing[i] = other != kNone;
    b.nodes[3 + i] = other != kNone ? mesh.opposite_node(e, other) : b.nodes[0];
    b.rest_theta[i] = mesh.edges[e].rest_theta;
  }
  b.dofs = b.nodes;
  b.blocks.fill(-1);
  b.Q = face_bending_matrix(mesh, material, f, b.has_wing);
  b.damping = material.damping;
  return b;
}

}  // namespace arcsim
