// How the implicit step's linear systems are solved (scene key `solver`, docs/scene-format.md); read by
// CholeskySolver::solve_system (physics/block_system.hpp).
#pragma once

namespace arcsim {

// Systems of fewer than `pcg_min_nodes` nodes are factorised at every solve and solved directly (exact to
// round-off, as ARCSim solves every system). Larger ones keep their factorisation across solves as the
// preconditioner of a conjugate-gradient solve of the current matrix: the factorisation of a matrix a few steps
// old is so close to the current one that a few iterations, each a pair of triangular solves, replace a
// factorisation. A fresh factorisation (the solve is then direct) is taken when the number of nodes changed, when
// CholeskySolver::refresh() asked for one (the simulation does at each frame's first step), and when the
// iteration does not reach the tolerance within pcg_max_iterations.
// Off by default (measured 2026-12-05, docs/benchmarks.md): on the 16k/64k-face bench sheet a one-step-old
// factorisation left a relative residual of 1e-3..4e-2 after 20 iterations (the clamped membrane geometric
// stiffness switches between steps), so every step paid the iterations and then the factorisation.
struct SolverSettings {
  // Systems of at most this many nodes are factorised by BlockCholesky (3x3 node blocks, no per-supernode
  // overhead), larger ones by CHOLMOD's supernodal factorisation, which wins once its supernodes are wide
  // (docs/benchmarks.md, "Small systems' factorisation").
  int block_max_nodes = 1000;
  int pcg_min_nodes = 2147483647;
  double pcg_tolerance = 1e-6;  // relative residual |A x - b| / |b| (2-norms) at which the iteration stops
  int pcg_max_iterations = 8;
};

}  // namespace arcsim
