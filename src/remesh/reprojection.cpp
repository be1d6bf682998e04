#include "remesh/reprojection.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "physics/bending.hpp"
#include "physics/face_element.hpp"
#include "physics/membrane.hpp"
#include "physics/plate_bending.hpp"

namespace arcsim {

namespace {

// The node's elements, built as the physics builds them (physics/face_element.hpp).
struct Elements {
  std::vector<FaceElement> membrane;
  std::vector<BendingElement> bending;
  double mass = 0;  // kg
};

Elements gather_elements(const Mesh& mesh, const std::vector<Material>& materials, int node) {
  Elements els;
  for (int f : mesh.node_faces(node)) {
    els.membrane.push_back(make_face_element(mesh, materials, f));
    els.mass += face_corner_mass(mesh.faces[f], materials[mesh.faces[f].material]);
  }
  for (int f : bending_faces_of_node(mesh, node)) els.bending.push_back(make_bending_element(mesh, materials, f));
  return els;
}

// The node's share of a bending element's Gauss-Newton Hessian, 2 sum_ij Q_ij a_i a_j^T with a_i the
// derivative of edge i's dihedral angle with respect to the node (the same approximation as
// plate_bending_terms' kProjected, without forming the 18 x 18 matrix).
Mat3 bending_hessian_block(const BendingElement& b, const std::array<Vec3, 6>& xs, int node) {
  std::array<Vec3, 3> a;
  for (int i = 0; i < 3; ++i) {
    a[i].setZero();
    if (!b.has_wing[i]) continue;
    // Hinge of edge i in dihedral_angle's order: corners i, i+1, i+2, then wing i.
    const std::array<int, 4> slots{i, (i + 1) % 3, (i + 2) % 3, 3 + i};
    bool touches = false;
    for (int s : slots) touches = touches || b.nodes[s] == node;
    if (!touches) continue;
    const Vec12 g = dihedral_angle_gradient(xs[slots[0]], xs[slots[1]], xs[slots[2]], xs[slots[3]]);
    for (int k = 0; k < 4; ++k)
      if (b.nodes[slots[k]] == node) a[i] += g.segment<3>(3 * k);
  }
  Mat3 H = Mat3::Zero();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (b.Q(i, j) != 0) H += 2 * b.Q(i, j) * a[i] * a[j].transpose();
  return H;
}

// The load's potential is measured from `origin` (any fixed point): a constant offset, chosen so that the
// line search compares energies of similar size instead of differences lost in the rounding of load . x.
LocalEnergy evaluate(const Mesh& mesh, const Elements& els, int node, const Vec3& x, const Vec3& load,
                     const Vec3& origin, bool with_hessian) {
  LocalEnergy out;
  auto position = [&](int n) -> const Vec3& { return n == node ? x : mesh.nodes[n].x; };
  const HessianKind kind = with_hessian ? HessianKind::kProjected : HessianKind::kNone;
  for (const FaceElement& el : els.membrane) {
    const MembraneTerms t = membrane_terms(position(el.nodes[0]), position(el.nodes[1]), position(el.nodes[2]),
                                           el.Dm_inv, el.area, el.k, 1.0, kind);
    out.energy += t.energy;
    for (int i = 0; i < 3; ++i)
      if (el.nodes[i] == node) {
        out.gradient += t.gradient.segment<3>(3 * i);
        if (with_hessian) out.hessian += t.hessian.block<3, 3>(3 * i, 3 * i);
      }
  }
  for (const BendingElement& b : els.bending) {
    std::array<Vec3, 6> xs;
    for (int i = 0; i < 6; ++i) xs[i] = position(b.nodes[i]);
    const PlateBendingTerms t = plate_bending_terms(xs, b.has_wing, b.rest_theta, b.Q, HessianKind::kNone);
    out.energy += t.energy;
    // The node may fill several slots (a corner and, on a tiny mesh, a wing): the derivative sums them.
    for (int i = 0; i < 6; ++i)
      if (b.nodes[i] == node && (i < 3 || b.has_wing[i - 3])) out.gradient += t.gradient.segment<3>(3 * i);
    if (with_hessian) out.hessian += bending_hessian_block(b, xs, node);
  }
  out.energy += load.dot(x - origin);
  out.gradient += load;
  return out;
}

// A typical rest edge length around the node (m), to scale step limits and tolerances.
double local_length(const Mesh& mesh, int node) {
  double sum = 0;
  int count = 0;
  for (int e : mesh.nodes[node].edges) {
    const Edge& ed = mesh.edges[e];
    sum += (mesh.nodes[ed.n[1]].x - mesh.nodes[ed.n[0]].x).norm();
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

}  // namespace

LocalEnergy node_local_energy(const Mesh& mesh, const std::vector<Material>& materials, int node, const Vec3& x,
                              const ReprojectionParams& params) {
  const Elements els = gather_elements(mesh, materials, node);
  return evaluate(mesh, els, node, x, els.mass * (mesh.nodes[node].a - params.gravity), Vec3::Zero(), true);
}

ReprojectionResult reproject_node(Mesh& mesh, const std::vector<Material>& materials, int node,
                                  const ReprojectionParams& params) {
  ReprojectionResult result;
  const Elements els = gather_elements(mesh, materials, node);
  if (els.membrane.empty()) return result;
  const Vec3 load = els.mass * (mesh.nodes[node].a - params.gravity);
  const double length = local_length(mesh, node);
  if (!(length > 0)) return result;
  const Vec3 start = mesh.nodes[node].x;
  // Trial points keep their motion across the sheet (along the mean world normal of the node's faces) within
  // max_displacement; motion within the sheet cannot carry it through a nearby layer and stays free (it is
  // what removes the in-plane stress a split or collapse leaves).
  Vec3 normal = Vec3::Zero();
  for (int f : mesh.node_faces(node)) normal += mesh.world_normal(f);
  if (normal.norm() > 0) normal.normalize();
  auto within_reach = [&](const Vec3& p) -> Vec3 {
    const Vec3 d = p - start;
    const double across = d.dot(normal);
    if (std::abs(across) <= params.max_displacement) return p;
    return p - (across - std::copysign(params.max_displacement, across)) * normal;
  };
  Vec3 x = start;
  LocalEnergy current = evaluate(mesh, els, node, x, load, start, true);
  result.energy_before = result.energy_after = current.energy;
  if (!std::isfinite(current.energy)) return result;

  for (int it = 0; it < params.max_iterations; ++it) {
    result.iterations = it + 1;
    const Mat3& H = current.hessian;
    const double reg = 1e-10 * std::max(H.trace() / 3, 0.0) + 1e-300;
    Vec3 step = -(H + reg * Mat3::Identity()).ldlt().solve(current.gradient);
    if (!step.allFinite() || step.dot(current.gradient) >= 0) {
      // No usable curvature: a gradient step scaled to the local length.
      const double g = current.gradient.norm();
      if (!(g > 0)) break;
      step = -(0.1 * length / g) * current.gradient;
    }
    // A step longer than the neighbourhood cannot be trusted to a quadratic model.
    const double norm = step.norm();
    if (norm > length) step *= length / norm;
    // Converged when the Newton step is a rounding-level displacement.
    if (step.norm() <= 1e-12 * length) break;
    bool accepted = false;
    double alpha = 1;
    LocalEnergy trial;
    for (int ls = 0; ls < 16; ++ls, alpha *= 0.5) {
      trial = evaluate(mesh, els, node, within_reach(x + alpha * step), load, start, false);
      if (std::isfinite(trial.energy) && trial.energy < current.energy) {
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    const Vec3 moved_by = within_reach(x + alpha * step) - x;
    x += moved_by;
    current = evaluate(mesh, els, node, x, load, start, true);
    if (moved_by.norm() < 1e-13 * length) break;
  }
  result.energy_after = current.energy;
  if (x != start) {
    Node& n = mesh.nodes[node];
    n.x0 += x - start;
    n.x = x;
    result.moved = true;
  }
  return result;
}

}  // namespace arcsim
