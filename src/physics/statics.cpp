#include "physics/statics.hpp"

#include <cmath>

#include "io/errors.hpp"

namespace arcsim {

namespace {

double potential_energy(const Mesh& mesh, const ElementCache& cache, const ExternalLoads& loads) {
  double e = internal_energy(mesh, cache);
  for (const Node& n : mesh.nodes) e -= n.mass * loads.gravity.dot(n.x);
  for (const HandleSpring& s : loads.springs) e += 0.5 * s.stiffness * (mesh.nodes[s.node].x - s.target).squaredNorm();
  return e;
}

// Net force on free nodes (N), stacked.
VecX residual_force(const Mesh& mesh, const ElementCache& cache, const ExternalLoads& loads) {
  VecX f = internal_forces(mesh, cache);
  for (size_t i = 0; i < mesh.nodes.size(); ++i) f.segment<3>(3 * i) += mesh.nodes[i].mass * loads.gravity;
  for (const HandleSpring& s : loads.springs)
    f.segment<3>(3 * s.node) -= s.stiffness * (mesh.nodes[s.node].x - s.target);
  if (!loads.pinned.empty())
    for (size_t i = 0; i < mesh.nodes.size(); ++i)
      if (loads.pinned[i]) f.segment<3>(3 * i).setZero();
  return f;
}

}  // namespace

StaticResult solve_static(Mesh& mesh, ElementCache& cache, CholeskySolver& solver, const ExternalLoads& loads,
                          const StaticOptions& options) {
  const int n = static_cast<int>(mesh.nodes.size());
  double weight = 0;
  for (const Node& node : mesh.nodes) weight += node.mass * loads.gravity.norm();
  const double tolerance = options.force_tolerance * std::max(weight, 1e-12);

  StaticResult result;
  std::vector<Vec3> x_start(n);
  for (int it = 0; it < options.max_iterations; ++it) {
    const VecX f = residual_force(mesh, cache, loads);
    result.residual = f.lpNorm<Eigen::Infinity>();
    result.iterations = it;
    if (!std::isfinite(result.residual)) throw NumericalError("static solve: residual force is not finite");
    if (result.residual < tolerance) {
      result.converged = true;
      return result;
    }
    ensure_pattern(cache);
    BlockSystem system;
    system.reset(cache.pattern);
    InternalAssembly how;  // H dx = f
    assemble_internal(mesh, cache, how, system);
    for (const HandleSpring& s : loads.springs) system.add_diagonal(s.node, s.stiffness * Mat3::Identity());
    system.rhs = f;
    for (int i = 0; i < n; ++i) {
      const bool pinned = !loads.pinned.empty() && loads.pinned[i];
      // A small mass-proportional shift keeps the system definite when the structure has free modes; it only
      // damps the Newton step, the converged state is unaffected.
      system.add_diagonal(i, (pinned ? 1.0 : 1e-9) * std::max(mesh.nodes[i].mass, 1e-12) * Mat3::Identity());
    }
    if (!loads.pinned.empty()) {
      for (int k = 0; k < cache.pattern.block_count(); ++k) {
        const int r = cache.pattern.block_row(k), c = cache.pattern.block_col(k);
        if ((loads.pinned[r] || loads.pinned[c]) && r != c) system.blocks[k].setZero();
        if (loads.pinned[r] && r == c) system.blocks[k] = std::max(mesh.nodes[r].mass, 1e-12) * Mat3::Identity();
      }
    }
    if (!solver.factorize(system)) throw NumericalError("static solve: stiffness matrix factorisation failed");
    const VecX dx = solver.solve(system.rhs);
    if (!dx.allFinite()) throw NumericalError("static solve: Newton step is not finite");

    // Backtracking line search on the potential energy.
    const double e0 = potential_energy(mesh, cache, loads);
    for (int i = 0; i < n; ++i) x_start[i] = mesh.nodes[i].x;
    double alpha = 1;
    for (int ls = 0; ls < 30; ++ls) {
      for (int i = 0; i < n; ++i) mesh.nodes[i].x = x_start[i] + alpha * dx.segment<3>(3 * i);
      if (potential_energy(mesh, cache, loads) <= e0 + 1e-12 * std::abs(e0)) break;
      alpha *= 0.5;
    }
  }
  const VecX f = residual_force(mesh, cache, loads);
  result.residual = f.lpNorm<Eigen::Infinity>();
  result.iterations = options.max_iterations;
  result.converged = result.residual < tolerance;
  return result;
}

}  // namespace arcsim
