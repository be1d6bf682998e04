#include "remesh/reprojection.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "physics/bending.hpp"
#include "physics/face_element.hpp"
#include "physics/membrane.hpp"
#include "physics/plate_bending.hpp"
#include "mesh/mesh.hpp"  // dihedral_angle_gradient

namespace arcsim {

namespace {

// A bending element as the node's solve sees it. The hinges that do not contain the node keep their angle
// while it moves: their deviations are computed once (WHY: the solve evaluates its ~12 bending elements up to
// ~170 times per node, and a third of their hinges never change).
struct NodeBending {
  BendingElement el;
  std::array<bool, 3> moves{};   // hinge i has a wing and contains the node
  Vec3 fixed_delta = Vec3::Zero();  // wrapped angle deviations of the hinges that do not move (0 without a wing)
};

// The node's elements, built as the physics builds them (physics/face_element.hpp).
struct Elements {
  std::vector<FaceElement> membrane;
  std::vector<NodeBending> bending;
  double mass = 0;  // kg
};

Elements gather_elements(const Mesh& mesh, const std::vector<Material>& materials, int node) {
  Elements els;
  for (int f : mesh.node_faces(node)) {
    els.membrane.push_back(make_face_element(mesh, materials, f));
    els.mass += face_corner_mass(mesh.faces[f], materials[mesh.faces[f].material]);
  }
  for (int f : bending_faces_of_node(mesh, node)) {
    NodeBending b;
    b.el = make_bending_element(mesh, materials, f);
    for (int i = 0; i < 3; ++i) {
      if (!b.el.has_wing[i]) continue;
      const auto s = plate_hinge_slots(i);
      for (int k : s) b.moves[i] = b.moves[i] || b.el.nodes[k] == node;
      if (!b.moves[i]) {
        const Vec3 &x0 = mesh.nodes[b.el.nodes[s[0]]].x, &x1 = mesh.nodes[b.el.nodes[s[1]]].x,
                   &x2 = mesh.nodes[b.el.nodes[s[2]]].x, &x3 = mesh.nodes[b.el.nodes[s[3]]].x;
        b.fixed_delta[i] = hinge_angle_deviation(x0, x1, x2, x3, b.el.rest_theta[i]);
      }
    }
    els.bending.push_back(b);
  }
  return els;
}

// The load's potential is measured from `origin` (any fixed point): a constant offset, chosen so that the
// line search compares energies of similar size instead of differences lost in the rounding of load . x.
//
// The energy and the node's gradient are plate_bending_terms' and membrane_terms', summed in their order, bit
// for bit (the node's slots of the element gradients accumulate hinge by hinge, as plate_bending_terms adds
// them); only what the node's rows need is computed. The Hessian is the node's share of the Gauss-Newton
// Hessian, 2 sum_ij Q_ij a_i a_j^T with a_i the derivative of edge i's dihedral angle with respect to the node
// (plate_bending_terms' kProjected, without forming the 18 x 18 matrix). Without `with_derivatives` only the
// energy is computed (the line search's trials).
LocalEnergy evaluate(const Mesh& mesh, const Elements& els, int node, const Vec3& x, const Vec3& load,
                     const Vec3& origin, bool with_derivatives) {
  LocalEnergy out;
  auto position = [&](int n) -> const Vec3& { return n == node ? x : mesh.nodes[n].x; };
  for (const FaceElement& el : els.membrane) {
    if (!with_derivatives) {
      out.energy += membrane_terms_energy(position(el.nodes[0]), position(el.nodes[1]), position(el.nodes[2]),
                                          el.Dm_inv, el.area, el.k, 1.0);
      continue;
    }
    const MembraneTerms t = membrane_terms(position(el.nodes[0]), position(el.nodes[1]), position(el.nodes[2]),
                                           el.Dm_inv, el.area, el.k, 1.0, HessianKind::kProjected);
    out.energy += t.energy;
    for (int i = 0; i < 3; ++i)
      if (el.nodes[i] == node) {
        out.gradient += t.gradient.segment<3>(3 * i);
        out.hessian += t.hessian.block<3, 3>(3 * i, 3 * i);
      }
  }
  for (const NodeBending& nb : els.bending) {
    const BendingElement& b = nb.el;
    Vec3 delta = nb.fixed_delta;
    std::array<Vec12, 3> grad;
    for (int i = 0; i < 3; ++i) {
      if (!nb.moves[i]) continue;
      const auto s = plate_hinge_slots(i);
      const Vec3 &x0 = position(b.nodes[s[0]]), &x1 = position(b.nodes[s[1]]), &x2 = position(b.nodes[s[2]]),
                 &x3 = position(b.nodes[s[3]]);
      delta[i] = hinge_angle_deviation(x0, x1, x2, x3, b.rest_theta[i]);
      if (with_derivatives) grad[i] = dihedral_angle_gradient(x0, x1, x2, x3);
    }
    const Vec3 Qd = b.Q * delta;
    out.energy += delta.dot(Qd);
    if (!with_derivatives) continue;
    // The node may fill several slots (a corner and, on a tiny mesh, a wing): the derivative sums them.
    for (int p = 0; p < 6; ++p) {
      if (b.nodes[p] != node || (p >= 3 && !b.has_wing[p - 3])) continue;
      Vec3 slot_gradient = Vec3::Zero();
      for (int i = 0; i < 3; ++i) {
        if (!nb.moves[i]) continue;
        const auto s = plate_hinge_slots(i);
        for (int a = 0; a < 4; ++a)
          if (s[a] == p) slot_gradient += 2 * Qd[i] * grad[i].segment<3>(3 * a);
      }
      out.gradient += slot_gradient;
    }
    std::array<Vec3, 3> a;
    for (int i = 0; i < 3; ++i) {
      a[i].setZero();
      if (!nb.moves[i]) continue;
      const auto s = plate_hinge_slots(i);
      for (int k = 0; k < 4; ++k)
        if (b.nodes[s[k]] == node) a[i] += grad[i].segment<3>(3 * k);
    }
    Mat3 H = Mat3::Zero();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (b.Q(i, j) != 0) H += 2 * b.Q(i, j) * a[i] * a[j].transpose();
    out.hessian += H;
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
