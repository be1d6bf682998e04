// The inelastic projection of one impact zone (Harmon et al. 2008, as in ARCSim): move the zone's nodes as
// little as possible in the mass-weighted sense,
//   minimise sum_i m_i |x_i - x*_i|^2   subject to   n_k . sum_i w_ki x_i >= thickness  for every impact k,
// with NLopt. The problem is a convex QP; it is solved in units of the thickness so that tolerances are
// relative to the gap being enforced.
#pragma once

#include <array>
#include <vector>

#include "math/types.hpp"
#include "mesh/mesh.hpp"

namespace arcsim {

struct ZoneConstraint {
  std::array<int, 4> vars{kNone, kNone, kNone, kNone};  // zone-local node index; kNone: fixed or unused
  std::array<double, 4> weights{0, 0, 0, 0};
  Vec3 normal = Vec3::UnitY();
  double fixed_offset = 0;  // n . sum of w x over the fixed (immovable) nodes (m)
};

struct ZoneProblem {
  std::vector<Vec3> target;   // x*, the positions before the projection (m)
  std::vector<double> mass;   // kg, all > 0
  std::vector<ZoneConstraint> constraints;
  double thickness = 1e-4;    // required gap (m)
};

enum class ZoneMethod {
  kAutomatic,            // SLSQP for small zones, the sparse augmented Lagrangian for larger ones
  kSlsqp,                // NLOPT_LD_SLSQP (dense quasi-Newton QP: cost grows with the cube of the zone size)
  kAugmentedLagrangian,  // NLOPT_AUGLAG with NLOPT_LD_LBFGS inside (NLopt hands it dense constraint
                         // gradients: cost grows with constraints x variables per evaluation)
  kSparseAugmentedLagrangian  // our multiplier/penalty updates around NLOPT_LD_LBFGS on the augmented
                              // Lagrangian, evaluated sparsely (cost grows with the zone size)
};

// Zones with more variables than this use the sparse augmented Lagrangian under kAutomatic. Measured on
// random chain zones (one VF-like constraint per node plus some against fixed geometry), -O2, ms per zone,
// SLSQP / NLopt AUGLAG / sparse AL:  4 nodes 0.04 / 0.08 / 0.04,  8 nodes 0.40 / 0.27 / 0.15,
// 16 nodes 3.2 / 0.8 / 0.4,  40 nodes 79 / 3.7 / 2.5,  100 nodes 1200 / 28 / 4.8,  400 nodes - / 316 / 27.
// All reach the gap to 0.1%. SLSQP needs ~10x fewer evaluations but its dense quasi-Newton updates dominate
// beyond a few nodes; NLopt's AUGLAG evaluates dense constraint Jacobians (constraints x variables).
constexpr int kSlsqpMaxVariables = 12;

// A projection that moves some node farther than this many times the deepest violation at the target (or the
// thickness, if larger) is ill-conditioned: its constraints nearly contradict each other, and only a node
// with a small weight in some constraint can meet them, by moving thickness / weight. Measured: healthy zones
// of the conf/ and ARCSim scenes move at most 15x (1-2x typically); the contradictory zones of
// conf/metal-crumple-remesh.json (a sheet node pressed onto a sphere vertex, with pairs around that vertex
// giving opposite normals) moved 39x to 1200x, up to 27 cm in one 1 ms step, and the stretched faces then
// released up to 4.5e8 J of plastic work.
constexpr double kMaxZoneMoveRatio = 25;

struct ZoneResult {
  bool solved = false;    // every constraint holds to within half the thickness, and not ill-conditioned
  bool ill_conditioned = false;  // the move ratio exceeds kMaxZoneMoveRatio: do not apply the result
  double worst_gap = 0;   // smallest constraint gap at the result (m)
  double move_ratio = 0;  // largest node move / required_move
  int evaluations = 0;    // objective evaluations
  double work = 0;        // work units spent (evaluations x zone_evaluation_work)
  bool out_of_budget = false;  // stopped by its work limit before it converged
};

// The work of one evaluation of a zone's objective and constraints (or of its augmented Lagrangian), in the
// collision budget's work units (impact_zones.hpp): one per constraint and one per variable, the terms an
// evaluation and the optimiser's update touch. Deterministic, unlike wall time.
inline double zone_evaluation_work(int nodes, size_t constraints) {
  return static_cast<double>(constraints) + 3.0 * nodes;
}

// The deepest violation of the problem's constraints at the target positions, or the thickness if larger (m).
double required_move(const ZoneProblem& problem);

// The largest distance of a node of x from its target (m).
double largest_move(const ZoneProblem& problem, const std::vector<Vec3>& x);

// Smallest gap n . sum w x + fixed_offset over the constraints at positions x (m); +inf without constraints.
double worst_zone_gap(const ZoneProblem& problem, const std::vector<Vec3>& x);

// Solves starting from `x` (same size as problem.target) and writes the result back to `x`. Never throws; a
// failed optimisation leaves its best point in `x` and reports solved = false; an ill-conditioned one leaves
// `x` as it was. The optimiser stops once it has spent `work_limit` work units (zone_evaluation_work per
// evaluation; kAugmentedLagrangian may take one evaluation more); then out_of_budget unless it had solved it.
ZoneResult solve_impact_zone(const ZoneProblem& problem, std::vector<Vec3>& x,
                             ZoneMethod method = ZoneMethod::kAutomatic, double work_limit = kInfinity);

}  // namespace arcsim
