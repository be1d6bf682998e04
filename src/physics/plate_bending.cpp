#include "physics/plate_bending.hpp"

#include "mesh/mesh.hpp"
#include "physics/bending.hpp"

namespace arcsim {

namespace {

// The 3x3 products of the bending Hessian in which one factor has a single nonzero column (a wing slot's G):
// each entry is then one product plus two exact zeros. A nonzero product absorbs the zeros exactly, and a sum of
// zeros does not depend on its order, so these give the very bits Eigen's general 3x3 product gives, whatever
// order it sums in; the zeros are formed (as Eigen forms them) only where the product is itself zero.

// Entries where the single product is zero get the sum of all three terms (zeros), in any order.
template <typename Term>
void resum_zero_entries(Mat3& out, Term term) {
  if (!(out.array() == 0).any()) return;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (out(r, c) == 0) out(r, c) = term(r, 0, c) + term(r, 1, c) + term(r, 2, c);
}

// 2 G Q, G zero outside column `col`: the outer product of 2 G's column and Q's row.
Mat3 twice_single_column_times(const Mat3& G, int col, const Mat3& Q) {
  const Vec3 a = 2 * G.col(col);
  Mat3 out = a * Q.row(col);
  resum_zero_entries(out, [&](int r, int k, int c) { return (2 * G(r, k)) * Q(k, c); });
  return out;
}

// A G^T, G zero outside column `col`: the outer product of A's and G's columns.
Mat3 times_single_column_transpose(const Mat3& A, const Mat3& G, int col) {
  Mat3 out = A.col(col) * G.col(col).transpose();
  resum_zero_entries(out, [&](int r, int k, int c) { return A(r, k) * G(c, k); });
  return out;
}

}  // namespace

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

void plate_bending_terms(const std::array<Vec3, 6>& x, const std::array<bool, 3>& has_wing, const Vec3& rest_theta,
                         const Mat3& Q, HessianKind hessian, PlateBendingTerms& out, const Vec3* known_theta) {
  out.gradient.setZero();
  out.theta.setZero();
  std::array<Vec12, 3> grad;
  Vec3 delta = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    grad[i].setZero();
    if (!has_wing[i]) continue;
    const auto s = plate_hinge_slots(i);
    out.theta[i] = known_theta ? (*known_theta)[i] : dihedral_angle(x[s[0]], x[s[1]], x[s[2]], x[s[3]]);
    delta[i] = wrap_angle(out.theta[i] - rest_theta[i]);  // hinge_angle_deviation, with the angle kept
    grad[i] = dihedral_angle_gradient(x[s[0]], x[s[1]], x[s[2]], x[s[3]]);
  }
  const Vec3 Qd = Q * delta;
  out.energy = delta.dot(Qd);
  for (int i = 0; i < 3; ++i) {
    if (!has_wing[i]) continue;
    const auto s = plate_hinge_slots(i);
    for (int a = 0; a < 4; ++a) out.gradient.segment<3>(3 * s[a]) += 2 * Qd[i] * grad[i].segment<3>(3 * a);
  }
  if (hessian == HessianKind::kNone) return;

  // Gauss-Newton part 2 sum_ij Q_ij grad_i grad_j^T. Slot p's rows of the three gradients form a 3x3 matrix
  // G_p (column i: hinge i's gradient at slot p, zero where slot p is not in hinge i), so that block (p, q) is
  // 2 G_p Q G_q^T: six products G_p Q, then the upper blocks, mirrored (Q is symmetric).
  // Every block is written below when the three wings exist; only a border face's missing rows stay zero.
  if (!(has_wing[0] && has_wing[1] && has_wing[2])) out.hessian.setZero();
  std::array<Mat3, 6> G;
  for (Mat3& g : G) g.setZero();
  for (int i = 0; i < 3; ++i) {
    if (!has_wing[i]) continue;
    const auto s = plate_hinge_slots(i);
    for (int a = 0; a < 4; ++a) G[s[a]].col(i) = grad[i].segment<3>(3 * a);
  }
  // A wing slot p = 3 + i lies in hinge i only: G_p's one nonzero column is i.
  std::array<Mat3, 6> GQ;
  for (int p = 0; p < 3; ++p) GQ[p] = 2 * G[p] * Q;
  for (int p = 3; p < 6; ++p)
    if (has_wing[p - 3]) GQ[p] = twice_single_column_times(G[p], p - 3, Q);
  for (int p = 0; p < 6; ++p) {
    if (p >= 3 && !has_wing[p - 3]) continue;
    for (int q = p; q < 6; ++q) {
      if (q >= 3 && !has_wing[q - 3]) continue;
      const Mat3 block = q < 3 ? Mat3(GQ[p] * G[q].transpose()) : times_single_column_transpose(GQ[p], G[q], q - 3);
      out.hessian.block<3, 3>(3 * p, 3 * q) = block;
      if (q != p) out.hessian.block<3, 3>(3 * q, 3 * p) = block.transpose();
    }
  }
  if (hessian == HessianKind::kExact) {
    // Curvature part 2 sum_i (Q d)_i d2(theta_i).
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
