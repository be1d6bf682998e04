#include "plasticity/bend_flow.hpp"

#include <cmath>

#include "physics/bending.hpp"
#include "physics/face_element.hpp"

namespace arcsim {

namespace {

// Bending moment per unit length (N) of the isotropic plate energy density kb/2 [(1 - nu) S:S + nu tr(S)^2]
// used by physics/plate_bending: M = kb [(1 - nu) S + nu tr(S) P], P the projector on the tangent plane.
Mat3 plate_moment(const Mat3& S, double kb, double nu, const Mat3& tangent_projector) {
  return kb * ((1 - nu) * S + nu * S.trace() * tangent_projector);
}

}  // namespace

bool has_bending_plasticity(const Material& m) { return std::isfinite(m.yield_curv); }

Mat3 face_elastic_bending_strain(const Mesh& mesh, int face) {
  const Face& f = mesh.faces[face];
  Mat3 S = Mat3::Zero();
  if (!(f.rest_area > 0)) return S;
  for (int i = 0; i < 3; ++i) {
    const Edge& e = mesh.edges[f.e[i]];
    if (e.is_boundary()) continue;
    const Vec3 d = mesh.verts[f.v[(i + 1) % 3]].u - mesh.verts[f.v[i]].u;
    const double length = d.norm();
    if (!(length > 0)) continue;
    const Vec3 n = d.cross(f.rest_normal) / length;
    const double deviation = wrap_angle(mesh.world_dihedral(f.e[i]) - e.rest_theta);
    S += deviation * length / (2 * f.rest_area) * n * n.transpose();
  }
  return S;
}

Mat3 bend_flow_increment(const Mat3& S_el, double yield_curv) {
  const double norm = S_el.norm();
  if (!(norm > yield_curv)) return Mat3::Zero();
  return S_el / norm * (norm - yield_curv);
}

BendFlowResult apply_bend_flow(Mesh& mesh, int face, const Material& m) {
  BendFlowResult out;
  if (!has_bending_plasticity(m)) return out;
  Face& f = mesh.faces[face];
  const Mat3 S_el = face_elastic_bending_strain(mesh, face);
  const Mat3 increment = bend_flow_increment(S_el, m.yield_curv);
  if (increment.isZero(0) || !increment.allFinite()) return out;

  // Plastic work at frozen positions and stiffness: A (M_old + M_new)/2 : (S_old - S_new), the face's plate
  // energy the update releases (exact for the quadratic energy). Direction-dependent (data-driven) stiffness
  // is averaged over the material axes.
  const double kb = weakened_bending_stiffness(
      0.5 * (m.bending_stiffness(f.thickness, 0) + m.bending_stiffness(f.thickness, M_PI / 2)), m, f.damage);
  const double nu = m.data_driven ? 0.0 : m.poisson_ratio;
  const Mat3 P = Mat3::Identity() - f.rest_normal * f.rest_normal.transpose();
  const Mat3 S_after = S_el - increment;
  const Mat3 mean_moment = 0.5 * (plate_moment(S_el, kb, nu, P) + plate_moment(S_after, kb, nu, P));
  out.work = f.rest_area * mean_moment.cwiseProduct(increment).sum();

  out.excess = S_el.norm() / m.yield_curv - 1;
  f.Sp += increment;
  f.damage += out.excess;
  out.changed = true;
  return out;
}

}  // namespace arcsim
