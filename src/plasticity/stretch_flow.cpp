#include "plasticity/stretch_flow.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/SVD>

#include "physics/face_element.hpp"
#include "physics/membrane.hpp"
#include "plasticity/plastic_tensors.hpp"

namespace arcsim {

namespace {

Mat2 green_strain(const Mat32& F) { return 0.5 * (F.transpose() * F - Mat2::Identity()); }

double double_contraction(const Mat2& A, const Mat2& B) { return A.cwiseProduct(B).sum(); }

}  // namespace

bool has_stretch_plasticity(const Material& m) { return std::isfinite(m.yield_stress) && m.flow_rate > 0; }

double von_mises_plane_stress(const Mat2& sigma) {
  Mat3 s = Mat3::Zero();
  s.topLeftCorner<2, 2>() = 0.5 * (sigma + sigma.transpose());
  const Mat3 deviator = s - s.trace() / 3 * Mat3::Identity();
  return std::sqrt(1.5) * deviator.norm();
}

double stretch_flow_fraction(const Material& m, double von_mises, double dt) {
  if (!has_stretch_plasticity(m)) return 0;
  const double gamma = dt * m.flow_rate * (von_mises - m.yield_stress);
  if (!(gamma > 0)) return 0;  // also rejects NaN
  return std::min(gamma, 1.0);
}

Mat2 stretch_flow_update(const Mat2& Fp2, const Mat32& F_el, double gamma, double plastic_limit) {
  if (!(gamma > 0)) return Fp2;
  const Eigen::JacobiSVD<Mat32> svd(F_el, Eigen::ComputeFullV);
  const Vec2 s = svd.singularValues();
  // A collapsed or numerically degenerate face has no meaningful principal stretches.
  if (!(s.minCoeff() > 1e-8) || !s.allFinite()) return Fp2;
  const double J = s[0] * s[1];
  const Mat2& V = svd.matrixV();
  Vec2 inverse_factor;
  for (int k = 0; k < 2; ++k) inverse_factor[k] = std::pow(std::cbrt(J) / s[k], gamma);
  Mat2 updated = Fp2 * V * inverse_factor.asDiagonal() * V.transpose();
  if (std::isfinite(plastic_limit)) {
    // The plastic stretch P = Fp2^-1 has the inverted singular values of Fp2; the clamp range is symmetric
    // under inversion, so clamping Fp2's singular values is the same.
    const Eigen::JacobiSVD<Mat2> fp(updated, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Vec2 clamped = fp.singularValues();
    for (int k = 0; k < 2; ++k) clamped[k] = std::clamp(clamped[k], 1.0 / plastic_limit, plastic_limit);
    updated = fp.matrixU() * clamped.asDiagonal() * fp.matrixV().transpose();
  }
  return updated.allFinite() ? updated : Fp2;
}

StretchFlowResult apply_stretch_flow(Mesh& mesh, int face, const Material& m, double dt) {
  StretchFlowResult out;
  Face& f = mesh.faces[face];
  if (!has_stretch_plasticity(m) || !(f.thickness > 0) || !(f.rest_area > 0)) return out;
  const Vec3& x0 = mesh.nodes[mesh.face_node(face, 0)].x;
  const Vec3& x1 = mesh.nodes[mesh.face_node(face, 1)].x;
  const Vec3& x2 = mesh.nodes[mesh.face_node(face, 2)].x;
  const Mat2 Fp_old = face_plastic_stretch_2d(f);
  const Mat32 F_el = membrane_deformation_gradient(x0, x1, x2, f.Dm_inv * Fp_old);
  const MembraneStiffness k = face_membrane_stiffness(f, m);  // as the physics sees it
  const Mat2 G_old = green_strain(F_el);
  const Mat2 S_old = membrane_stress(G_old, k);  // N/m
  out.von_mises = von_mises_plane_stress(S_old / f.thickness);
  out.gamma = stretch_flow_fraction(m, out.von_mises, dt);
  if (out.gamma <= 0) return out;

  const Mat2 Fp_new = stretch_flow_update(Fp_old, F_el, out.gamma, m.plastic_limit);
  const double det_old = Fp_old.determinant(), det_new = Fp_new.determinant();
  if (Fp_new == Fp_old || !(det_old > 0) || !(det_new > 0)) return out;

  // Plastic work at frozen positions and stiffness: the midpoint rule is exact for the linear stress-strain
  // law, so this is the membrane energy the update releases, A (S_old + S_new)/2 : (G_old - G_new).
  const Mat2 G_new = green_strain(F_el * Fp_old.inverse() * Fp_new);
  const Mat2 S_new = membrane_stress(G_new, k);
  out.work = f.rest_area * double_contraction(0.5 * (S_old + S_new), G_old - G_new);

  f.Fp = face_plastic_stretch_3d(f, Fp_new);
  f.thickness *= det_new / det_old;  // = J^(-gamma/3) without clamping; keeps det(P) h constant
  out.changed = true;
  return out;
}

}  // namespace arcsim
