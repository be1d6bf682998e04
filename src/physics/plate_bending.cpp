#include "physics/plate_bending.hpp"

#include "mesh/mesh.hpp"
#include "physics/bending.hpp"

namespace arcsim {

Mat3 plate_bending_matrix(const std::array<double, 3>& lengths, const std::array<Vec3, 3>& normals, double area,
                          double kb, double nu, const std::array<bool, 3>& has_edge) {
  Mat3 Q = Mat3::Zero();
  if (!(area > 0)) return Q;
  for (int i = 0; i < 3; ++i) {
    if (!has_edge[i]) continue;
    for (int j = 0; j < 3; ++j) {
      if (!has_edge[j]) continue;
      const double ci = lengths[i] / (2 * area), cj = lengths[j] / (2 * area);
      const double dot = normals[i].dot(normals[j]);
      Q(i, j) = 0.5 * area * kb * ci * cj * ((1 - nu) * dot * dot + nu);
    }
  }
  return Q;
}

double hinge_angle_deviation(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, double rest_theta) {
  return wrap_angle(dihedral_angle(x0, x1, x2, x3) - rest_theta);
}

double plate_bending_energy(const std::array<Vec3, 6>& x, const std::array<bool, 3>& has_wing,
                            const Vec3& rest_theta, const Mat3& Q, Vec3* theta) {
  Vec3 delta = Vec3::Zero();
  if (theta) theta->setZero();
  for (int i = 0; i < 3; ++i) {
    if (!has_wing[i]) continue;
    const auto s = plate_hinge_slots(i);
    const double angle = dihedral_angle(x[s[0]], x[s[1]], x[s[2]], x[s[3]]);
    if (theta) (*theta)[i] = angle;
    delta[i] = wrap_angle(angle - rest_theta[i]);  // hinge_angle_deviation, with the angle kept
  }
  return delta.dot(Q * delta);
}

PlateBendingTerms plate_bending_terms(const std::array<Vec3, 6>& x, const std::array<bool, 3>& has_wing,
                                      const Vec3& rest_theta, const Mat3& Q, HessianKind hessian) {
  PlateBendingTerms out;
  plate_bending_terms(x, has_wing, rest_theta, Q, hessian, out);
  return out;
}

namespace {

// Energy, gradient and angles of plate_bending_terms; `grad` gets the three hinges' angle gradients (zero where
// no wing).
void angle_terms(const std::array<Vec3, 6>& x, const std::array<bool, 3>& has_wing, const Vec3& rest_theta,
                 const Mat3& Q, const Vec3* known_theta, double& energy, Vec18& gradient, Vec3& theta,
                 std::array<Vec12, 3>& grad) {
  gradient.setZero();
  theta.setZero();
  Vec3 delta = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    grad[i].setZero();
    if (!has_wing[i]) continue;
    const auto s = plate_hinge_slots(i);
    theta[i] = known_theta ? (*known_theta)[i] : dihedral_angle(x[s[0]], x[s[1]], x[s[2]], x[s[3]]);
    delta[i] = wrap_angle(theta[i] - rest_theta[i]);  // hinge_angle_deviation, with the angle kept
    grad[i] = dihedral_angle_gradient(x[s[0]], x[s[1]], x[s[2]], x[s[3]]);
  }
  const Vec3 Qd = Q * delta;
  energy = delta.dot(Qd);
  for (int i = 0; i < 3; ++i) {
    if (!has_wing[i]) continue;
    const auto s = plate_hinge_slots(i);
    for (int a = 0; a < 4; ++a) gradient.segment<3>(3 * s[a]) += 2 * Qd[i] * grad[i].segment<3>(3 * a);
  }
}

// Gauss-Newton part 2 sum_ij Q_ij grad_i grad_j^T in factored form: the six products G_p Q.
void set_gauss_newton(const std::array<Vec12, 3>& grad, const Mat3& Q, const std::array<bool, 3>& has_wing,
                      PlateBendingGaussNewton& out) {
  out.has_wing = has_wing;
  for (Mat3& g : out.G) g.setZero();
  for (int i = 0; i < 3; ++i) {
    if (!has_wing[i]) continue;
    const auto s = plate_hinge_slots(i);
    for (int a = 0; a < 4; ++a) out.G[s[a]].col(i) = grad[i].segment<3>(3 * a);
  }
  // A wing slot p = 3 + i lies in hinge i only: G_p's one nonzero column is i, so G_p Q is an outer product.
  for (int p = 0; p < 3; ++p) out.GQ[p] = (2 * out.G[p]).lazyProduct(Q);
  for (int p = 3; p < 6; ++p)
    if (has_wing[p - 3]) out.GQ[p].noalias() = (2 * out.G[p].col(p - 3)) * Q.row(p - 3);
}

}  // namespace

Vec18 PlateBendingGaussNewton::times(const Vec18& v) const {
  Vec3 Jv = Vec3::Zero();  // the three angles' rates along v
  for (int p = 0; p < 6; ++p)
    if (slot_used(p)) Jv.noalias() += G[p].transpose() * v.segment<3>(3 * p);
  Vec18 out = Vec18::Zero();
  for (int p = 0; p < 6; ++p)
    if (slot_used(p)) out.segment<3>(3 * p).noalias() = GQ[p] * Jv;
  return out;
}

void plate_bending_factored_terms(const std::array<Vec3, 6>& x, const std::array<bool, 3>& has_wing,
                                  const Vec3& rest_theta, const Mat3& Q, PlateBendingFactoredTerms& out,
                                  const Vec3* known_theta) {
  std::array<Vec12, 3> grad;
  angle_terms(x, has_wing, rest_theta, Q, known_theta, out.energy, out.gradient, out.theta, grad);
  set_gauss_newton(grad, Q, has_wing, out.hessian);
}

void plate_bending_terms(const std::array<Vec3, 6>& x, const std::array<bool, 3>& has_wing, const Vec3& rest_theta,
                         const Mat3& Q, HessianKind hessian, PlateBendingTerms& out, const Vec3* known_theta) {
  std::array<Vec12, 3> grad;
  angle_terms(x, has_wing, rest_theta, Q, known_theta, out.energy, out.gradient, out.theta, grad);
  if (hessian == HessianKind::kNone) return;

  // Block (p, q) is 2 G_p Q G_q^T: the upper blocks from the factored form, mirrored (Q is symmetric).
  // Every block is written below when the three wings exist; only a border face's missing rows stay zero.
  if (!(has_wing[0] && has_wing[1] && has_wing[2])) out.hessian.setZero();
  PlateBendingGaussNewton gn;
  set_gauss_newton(grad, Q, has_wing, gn);
  for (int p = 0; p < 6; ++p) {
    if (!gn.slot_used(p)) continue;
    for (int q = p; q < 6; ++q) {
      if (!gn.slot_used(q)) continue;
      const Mat3 block = gn.block(p, q);
      out.hessian.block<3, 3>(3 * p, 3 * q) = block;
      if (q != p) out.hessian.block<3, 3>(3 * q, 3 * p) = block.transpose();
    }
  }
  if (hessian == HessianKind::kExact) {
    // Curvature part 2 sum_i (Q d)_i d2(theta_i).
    Vec3 delta = Vec3::Zero();
    for (int i = 0; i < 3; ++i)
      if (has_wing[i]) delta[i] = wrap_angle(out.theta[i] - rest_theta[i]);
    const Vec3 Qd = Q * delta;
    for (int i = 0; i < 3; ++i) {
      if (!has_wing[i] || Qd[i] == 0) continue;
      const auto s = plate_hinge_slots(i);
      const Mat12 H = dihedral_angle_hessian(x[s[0]], x[s[1]], x[s[2]], x[s[3]]);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
          out.hessian.block<3, 3>(3 * s[a], 3 * s[b]) += 2 * Qd[i] * H.block<3, 3>(3 * a, 3 * b);
    }
  }
}

}  // namespace arcsim
