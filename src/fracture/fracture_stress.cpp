#include "fracture/fracture_stress.hpp"

#include <algorithm>
#include <cmath>

#include "physics/face_element.hpp"
#include "physics/membrane.hpp"
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

bool is_breakable(const Face& face, const std::vector<Material>& materials) {
  return !face.dead && materials[face.material].toughness > 0;
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

// Eq. 8's factor (I + 1/2 alpha h II*) (dimensionless, material frame).
Mat2 bending_stretch(const Mesh& mesh, int f, double alpha) {
  const Mat2 II = face_elastic_curvature(mesh, f);
  const Mat2 II_abs = map_symmetric_eigenvalues(II, [](double l) { return std::abs(l); });
  return Mat2::Identity() + 0.5 * alpha * mesh.faces[f].thickness * II_abs;
}

}  // namespace

Mat2 face_elastic_curvature(const Mesh& mesh, int f) {
  return face_bending_tensor(mesh, f, elastic_hinge_angles(mesh, f));
}

FaceFractureStress face_fracture_stress(const Mesh& mesh, const std::vector<Material>& materials, int f) {
  FaceFractureStress out;
  const Face& face = mesh.faces[f];
  if (!is_breakable(face, materials) || !(face.rest_area > 0)) return out;
  const Material& material = materials[face.material];
  const Mat32 F_el = membrane_deformation_gradient(mesh.nodes[mesh.face_node(f, 0)].x,
                                                   mesh.nodes[mesh.face_node(f, 1)].x,
                                                   mesh.nodes[mesh.face_node(f, 2)].x, face_elastic_dm_inv(face));
  const double alpha = material.fracture_bending_mult;
  const Mat32 F_B = alpha > 0 ? Mat32(F_el * bending_stretch(mesh, f, alpha)) : F_el;
  const Mat2 G = 0.5 * (F_B.transpose() * F_B - Mat2::Identity());
  const Mat2 sigma = membrane_stress(G, face_membrane_stiffness(face, material));
  out.sigma = map_symmetric_eigenvalues(sigma, [](double l) { return std::max(l, 0.0); });
  out.lambda_max = std::max(largest_eigenvalue(sigma), 0.0);
  return out;
}

void update_fracture_stresses(const Mesh& mesh, const std::vector<Material>& materials,
                              const std::vector<int>& faces, std::vector<FaceFractureStress>& out) {
  out.resize(mesh.faces.size());
  const int count = static_cast<int>(faces.size());
  // Each face writes only its own slot: the result does not depend on the thread count.
#pragma omp parallel for schedule(static)
  for (int k = 0; k < count; ++k)
    out[faces[k]] = face_fracture_stress(mesh, materials, faces[k]);
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
