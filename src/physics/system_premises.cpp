#include "physics/system_premises.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "physics/membrane.hpp"
#include "physics/plate_bending.hpp"
#include "physics/wind.hpp"

namespace arcsim {

namespace {

// Relative tolerance of "negative" for an eigenvalue: projection and round-off leave eigenvalues of the order
// of 1e-16 times the largest one; anything beyond this is a real negative direction.
constexpr double kNegativeTolerance = 1e-9;

template <int N>
double smallest_relative_eigenvalue(const Eigen::Matrix<double, N, N>& K, double* smallest = nullptr) {
  const Eigen::Matrix<double, N, N> symmetric = 0.5 * (K + K.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(symmetric, Eigen::EigenvaluesOnly);
  const auto& values = eig.eigenvalues();
  const double largest = values.cwiseAbs().maxCoeff();
  if (smallest) *smallest = values.minCoeff();
  return largest > 0 ? values.minCoeff() / largest : 0.0;
}

template <size_t N>
std::string node_list(const std::array<int, N>& nodes) {
  std::ostringstream out;
  for (size_t i = 0; i < N; ++i) out << (i ? " " : "") << nodes[i] + 1;
  return out.str();
}

bool any_free(const SystemDofs& dofs, const int* nodes, int count) {
  for (int i = 0; i < count; ++i)
    if (nodes[i] != kNone && dofs.dof(nodes[i]) >= 0) return true;
  return false;
}

}  // namespace

std::string explain_indefinite_system(const Mesh& mesh, const std::vector<FaceElement>& faces,
                                      const std::vector<BendingElement>& bending, const SystemDofs& dofs,
                                      const ExternalLoads& loads, double dt, const BlockSystem& system,
                                      int failed_row) {
  std::ostringstream why;
  why.precision(4);
  const int failed_dof = failed_row >= 0 && failed_row < 3 * dofs.count() ? failed_row / 3 : -1;
  const int failed_node = failed_dof >= 0 ? dofs.node(failed_dof) : -1;
  // Masses (node numbers are 1-based in messages, as in the OBJ file).
  for (int d = 0; d < dofs.count(); ++d) {
    const int n = dofs.node(d);
    if (n < static_cast<int>(loads.pinned.size()) && loads.pinned[n]) continue;
    const double m = mesh.nodes[n].mass;
    if (!(m > 0) || !std::isfinite(m)) {
      why << "node " << n + 1 << " has mass " << m << " kg"
          << (mesh.node_faces(n).empty() ? " (it belongs to no face)" : "");
      return why.str();
    }
  }
  // The element that is stiffest against the masses it moves: dt (dt + beta) lambda_max / min mass. Where that
  // ratio nears 1 / epsilon, the element's round-off exceeds the masses and the factorisation fails although
  // every premise holds.
  // The same among the elements of the node where the factorisation stopped.
  double stiffest_ratio = 0, stiffest_here_ratio = 0;
  std::string stiffest, stiffest_here;
  auto note_stiffness = [&](const char* kind, const auto& nodes, double damping, double largest_eigenvalue,
                            double rest_area) {
    double lightest = kInfinity;
    for (int node : nodes) lightest = std::min(lightest, mesh.nodes[node].mass);
    const double ratio = dt * (dt + damping) * largest_eigenvalue / lightest;
    const bool here = std::find(nodes.begin(), nodes.end(), failed_node) != nodes.end();
    if (!(ratio > stiffest_ratio) && !(here && ratio > stiffest_here_ratio)) return;
    std::ostringstream what;
    what.precision(4);
    what << kind << " element of nodes " << node_list(nodes) << " (";
    if (rest_area >= 0) what << "rest area " << rest_area << " m^2, ";
    what << "lightest node " << lightest << " kg): dt (dt + beta) K / m = " << ratio;
    if (ratio > stiffest_ratio) {
      stiffest_ratio = ratio;
      stiffest = what.str();
    }
    if (here && ratio > stiffest_here_ratio) {
      stiffest_here_ratio = ratio;
      stiffest_here = what.str();
    }
  };
  // Membrane elements.
  for (size_t i = 0; i < faces.size(); ++i) {
    const FaceElement& el = faces[i];
    if (!any_free(dofs, el.nodes.data(), 3)) continue;
    if (!(el.damping >= 0) || !std::isfinite(el.damping) || !el.Dm_inv.allFinite() || !(el.area > 0)) {
      why << "membrane element of nodes " << node_list(el.nodes) << " has damping " << el.damping
          << " s, rest area " << el.area << " m^2" << (el.Dm_inv.allFinite() ? "" : " and a non-finite rest frame");
      return why.str();
    }
    const MembraneTerms t = membrane_terms(mesh.nodes[el.nodes[0]].x, mesh.nodes[el.nodes[1]].x,
                                           mesh.nodes[el.nodes[2]].x, el.Dm_inv, el.area, el.k, 1.0,
                                           HessianKind::kProjected);
    double smallest = 0;
    if (!t.hessian.allFinite() || smallest_relative_eigenvalue<9>(t.hessian, &smallest) < -kNegativeTolerance) {
      why << "membrane element of nodes " << node_list(el.nodes) << " has an indefinite projected Hessian "
          << "(smallest eigenvalue " << smallest << " N/m)";
      return why.str();
    }
    note_stiffness("membrane", el.nodes, el.damping, t.hessian.cwiseAbs().rowwise().sum().maxCoeff(), el.area);
  }
  // Bending elements.
  for (size_t i = 0; i < bending.size(); ++i) {
    const BendingElement& el = bending[i];
    if (!any_free(dofs, el.nodes.data(), 6)) continue;
    if (!(el.damping >= 0) || !std::isfinite(el.damping) || !el.Q.allFinite()) {
      why << "bending element of nodes " << node_list(el.nodes) << " has damping " << el.damping
          << " s or a non-finite stiffness";
      return why.str();
    }
    std::array<Vec3, 6> x;
    for (int k = 0; k < 6; ++k) x[k] = mesh.nodes[el.nodes[k]].x;
    const PlateBendingTerms t = plate_bending_terms(x, el.has_wing, el.rest_theta, el.Q, HessianKind::kProjected);
    double smallest = 0;
    if (!t.hessian.allFinite() || smallest_relative_eigenvalue<18>(t.hessian, &smallest) < -kNegativeTolerance) {
      why << "bending element of nodes " << node_list(el.nodes) << " has an indefinite projected Hessian "
          << "(smallest eigenvalue " << smallest << " N/m)";
      return why.str();
    }
    // The rest area of the element's own face, where the face list holds it at the same index (the full step's
    // cache does; a zone's lists need not), otherwise none is printed.
    const bool same_face = i < faces.size() && faces[i].nodes[0] == el.nodes[0] && faces[i].nodes[1] == el.nodes[1] &&
                           faces[i].nodes[2] == el.nodes[2];
    note_stiffness("bending", el.nodes, el.damping, t.hessian.cwiseAbs().rowwise().sum().maxCoeff(),
                   same_face ? faces[i].area : -1.0);
  }
  // Contacts and handles.
  for (const ContactTerm& c : loads.contacts) {
    if (!any_free(dofs, c.nodes.data(), 4)) continue;
    bool finite = c.normal.allFinite() && std::isfinite(c.force);
    for (double w : c.weights) finite = finite && std::isfinite(w);
    if (!(c.stiffness >= 0) || !(c.friction_damping >= 0) || !finite || !std::isfinite(c.stiffness) ||
        !std::isfinite(c.friction_damping)) {
      why << "contact of nodes " << node_list(c.nodes) << " has stiffness " << c.stiffness
          << " N/m, friction damping " << c.friction_damping << " kg/s" << (finite ? "" : " and non-finite data");
      return why.str();
    }
  }
  for (const HandleSpring& s : loads.springs)
    if (dofs.dof(s.node) >= 0 && !(s.stiffness >= 0 && std::isfinite(s.stiffness))) {
      why << "handle spring of node " << s.node + 1 << " has stiffness " << s.stiffness << " N/m";
      return why.str();
    }
  if (loads.wind.density != 0 || loads.wind.drag != 0)
    for (const FaceElement& el : faces) {
      if (!any_free(dofs, el.nodes.data(), 3)) continue;
      const WindForce w = wind_force(mesh.nodes[el.nodes[0]].x, mesh.nodes[el.nodes[1]].x, mesh.nodes[el.nodes[2]].x,
                                     mesh.nodes[el.nodes[0]].v, mesh.nodes[el.nodes[1]].v, mesh.nodes[el.nodes[2]].v,
                                     loads.wind.velocity, loads.wind.density, loads.wind.drag);
      const Mat9 minus_jacobian = -w.jacobian;
      if (!w.jacobian.allFinite() || smallest_relative_eigenvalue<9>(minus_jacobian) < -kNegativeTolerance) {
        why << "air drag on the face of nodes " << node_list(el.nodes) << " has a Jacobian that is not negative "
            << "semi-definite";
        return why.str();
      }
    }
  // Every premise holds: the assembled blocks themselves.
  double smallest_diagonal = kInfinity, largest_diagonal = 0;
  int smallest_at = -1;
  for (int d = 0; d < dofs.count(); ++d) {
    const Mat3& block = system.blocks[system.pattern->diagonal_block(d)];
    double smallest = 0;
    const double relative = smallest_relative_eigenvalue<3>(block, &smallest);
    if (!block.allFinite() || relative <= 0) {
      why << "the diagonal block of node " << dofs.node(d) + 1 << " is not positive definite (smallest eigenvalue "
          << smallest << " kg) although every element, mass and contact term is";
      return why.str();
    }
    if (block.trace() < smallest_diagonal) {
      smallest_diagonal = block.trace();
      smallest_at = dofs.node(d);
    }
    largest_diagonal = std::max(largest_diagonal, block.trace());
  }
  // Where CHOLMOD stopped: the blocks of that node and its neighbours form a principal submatrix, positive
  // definite whenever the whole matrix is; every term being so, an indefinite one means the assembly put a term
  // in other than as computed (a block dropped, doubled or misplaced), not ill-conditioning.
  if (failed_dof >= 0) {
    const BlockPattern& pattern = *system.pattern;
    std::vector<int> local(dofs.count(), -1), around{failed_dof};
    for (int k = 0; k < pattern.block_count(); ++k) {
      if (pattern.block_row(k) == failed_dof) around.push_back(pattern.block_col(k));
      if (pattern.block_col(k) == failed_dof) around.push_back(pattern.block_row(k));
    }
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end()), around.end());
    for (size_t i = 0; i < around.size(); ++i) local[around[i]] = static_cast<int>(i);
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * around.size(), 3 * around.size());
    for (int k = 0; k < pattern.block_count(); ++k) {
      const int r = local[pattern.block_row(k)], c = local[pattern.block_col(k)];
      if (r < 0 || c < 0) continue;
      A.block<3, 3>(3 * r, 3 * c) = system.blocks[k];
      if (r != c) A.block<3, 3>(3 * c, 3 * r) = system.blocks[k].transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A, Eigen::EigenvaluesOnly);
    const double smallest = eig.eigenvalues().minCoeff();
    const double largest = eig.eigenvalues().cwiseAbs().maxCoeff();
    if (!A.allFinite() || !(smallest > -kNegativeTolerance * largest)) {
      why << "the factorisation stopped at node " << failed_node + 1 << ", whose blocks with its "
          << around.size() - 1 << " neighbours are indefinite (smallest eigenvalue " << smallest
          << " kg) although every element, mass and contact term is positive semi-definite: a term was "
          << "assembled other than as computed (a block dropped, doubled or misplaced)";
      return why.str();
    }
  }
  why << "every premise holds (positive masses, positive semi-definite element, contact and handle terms), so the "
      << "matrix is too ill-conditioned to factorise: its diagonal spans " << largest_diagonal / smallest_diagonal
      << "x (smallest at node " << smallest_at + 1 << ", dt = " << dt << " s); the stiffest against its masses: "
      << stiffest;
  if (failed_node >= 0)
    why << "; the factorisation stopped at node " << failed_node + 1
        << (stiffest_here.empty() ? std::string() : ", whose stiffest: " + stiffest_here);
  why << "; try a smaller time step, or a larger remeshing size_min";
  return why.str();
}

}  // namespace arcsim
