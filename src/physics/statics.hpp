// Static equilibrium of a cloth under gravity and handle springs: Newton's method with a backtracking line
// search on the total potential energy, using the same element Hessians and sparse Cholesky as the time step.
// Used to check the elastic model against closed-form static solutions and to equilibrate initial states.
#pragma once

#include "physics/cloth_physics.hpp"

namespace arcsim {

struct StaticOptions {
  int max_iterations = 100;
  double force_tolerance = 1e-7;  // stop when |residual force| (N) drops below this times the total weight
};

struct StaticResult {
  int iterations = 0;
  double residual = 0;    // N, infinity norm of the net force on free nodes
  bool converged = false;
};

// Moves mesh node positions to a minimum of elastic + gravitational + spring energy; pinned nodes stay put.
StaticResult solve_static(Mesh& mesh, ElementCache& cache, CholeskySolver& solver, const ExternalLoads& loads,
                          const StaticOptions& options = {});

}  // namespace arcsim
