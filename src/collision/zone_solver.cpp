#include "collision/zone_solver.hpp"

#include <algorithm>
#include <cmath>
#include <exception>

#include <nlopt.hpp>

namespace arcsim {

namespace {

// The problem in scaled variables y = (x - x*) / thickness: objective 1/2 sum_i (m_i / m_mean) |y_i|^2,
// constraints c_k(y) = b_k - sum_i w_ki n_k . y_i <= 0 with b_k = (thickness - gap_k(x*)) / thickness.
struct ScaledZone {
  const ZoneProblem* problem = nullptr;
  std::vector<double> relative_mass;  // m_i / m_mean
  std::vector<double> b;
  int evaluations = 0;
  double max_evaluations = kInfinity;  // the work limit's: past it an evaluation stops the optimiser
};

double objective(unsigned n, const double* y, double* grad, void* data) {
  auto* z = static_cast<ScaledZone*>(data);
  // NLopt's evaluation limits are not exact for every method (AUGLAG's inner optimiser runs on past them); this
  // is. NLopt's wrapper turns the exception into a forced stop that keeps the best point so far.
  if (!(z->evaluations < z->max_evaluations)) throw nlopt::forced_stop();
  ++z->evaluations;
  double f = 0;
  for (unsigned j = 0; j < n; ++j) {
    const double m = z->relative_mass[j / 3];
    f += 0.5 * m * y[j] * y[j];
    if (grad) grad[j] = m * y[j];
  }
  return f;
}

void constraints(unsigned m, double* result, unsigned n, const double* y, double* grad, void* data) {
  auto* z = static_cast<ScaledZone*>(data);
  const auto& rows = z->problem->constraints;
  if (grad) std::fill(grad, grad + static_cast<size_t>(m) * n, 0.0);
  for (unsigned k = 0; k < m; ++k) {
    const ZoneConstraint& c = rows[k];
    double value = z->b[k];
    for (int i = 0; i < 4; ++i) {
      if (c.vars[i] == kNone) continue;
      for (int d = 0; d < 3; ++d) {
        const size_t j = 3 * static_cast<size_t>(c.vars[i]) + d;
        value -= c.weights[i] * c.normal[d] * y[j];
        if (grad) grad[k * n + j] -= c.weights[i] * c.normal[d];
      }
    }
    result[k] = value;
  }
}

// Constraint k in scaled variables: c_k(y) = b_k - sum_i w_ki n_k . y_i.
double scaled_constraint(const ScaledZone& z, size_t k, const double* y) {
  const ZoneConstraint& c = z.problem->constraints[k];
  double value = z.b[k];
  for (int i = 0; i < 4; ++i)
    if (c.vars[i] != kNone) value -= c.weights[i] * c.normal.dot(Vec3(y + 3 * c.vars[i]));
  return value;
}

// Augmented Lagrangian of the scaled zone for fixed multipliers and penalty (inequalities, PHR form):
//   L(y) = f(y) + mu/2 sum_k max(0, c_k(y) + lambda_k / mu)^2.
struct AugmentedLagrangian {
  ScaledZone* zone;
  std::vector<double> lambda;
  double mu = 10;
};

double augmented_lagrangian(unsigned n, const double* y, double* grad, void* data) {
  auto* al = static_cast<AugmentedLagrangian*>(data);
  const double f = objective(n, y, grad, al->zone);
  double penalty = 0;
  const auto& rows = al->zone->problem->constraints;
  for (size_t k = 0; k < rows.size(); ++k) {
    const double shifted = scaled_constraint(*al->zone, k, y) + al->lambda[k] / al->mu;
    if (shifted <= 0) continue;
    penalty += 0.5 * al->mu * shifted * shifted;
    if (!grad) continue;
    const ZoneConstraint& c = rows[k];
    for (int i = 0; i < 4; ++i)
      if (c.vars[i] != kNone)
        for (int d = 0; d < 3; ++d) grad[3 * c.vars[i] + d] -= al->mu * shifted * c.weights[i] * c.normal[d];
  }
  return f + penalty;
}

// Outer loop: minimise L with NLopt's L-BFGS, update the multipliers, raise the penalty while the
// violation does not shrink fast enough. Tolerances are in units of the thickness.
// The penalty is capped at a moderate value: the multiplier updates converge for any fixed penalty, whereas
// a penalty driven to 1e8 makes L-BFGS stall within its evaluation budget on large contact zones
// (measured on sphere.json: 170-440 node zones left 0.3 thickness inside, then cascaded into thousands of
// impacts per round). More, cheaper outer rounds replace the large penalties.
constexpr double kMaxPenalty = 1e4;
constexpr int kMaxOuterIterations = 200;
constexpr int kMaxInnerEvaluations = 1000;
// At most zone.max_evaluations evaluations in all.
void sparse_augmented_lagrangian(ScaledZone& zone, std::vector<double>& y) {
  const unsigned n = static_cast<unsigned>(y.size());
  const size_t m = zone.b.size();
  AugmentedLagrangian al{&zone, std::vector<double>(m, 0.0), 10.0};
  double previous_violation = kInfinity;
  for (int outer = 0; outer < kMaxOuterIterations; ++outer) {
    const double left = zone.max_evaluations - zone.evaluations;
    if (!(left >= 1)) return;
    nlopt::opt inner(nlopt::LD_LBFGS, n);
    inner.set_min_objective(augmented_lagrangian, &al);
    // Loose inner tolerances: the multiplier updates correct what an inexact inner solve leaves (tightening
    // to 1e-7 / 1e-14 made resting-contact zones ~8x slower for no gain in the final gaps).
    inner.set_xtol_abs(1e-5);
    inner.set_ftol_rel(1e-10);
    inner.set_maxeval(static_cast<int>(std::min<double>(kMaxInnerEvaluations, left)));
    inner.set_vector_storage(10);
    try {
      double f = 0;
      inner.optimize(y, f);
    } catch (const std::exception&) {
      // L-BFGS stops on round-off near the minimum; its last point is still the best one.
    }
    double violation = 0, slack = 0;
    for (size_t k = 0; k < m; ++k) {
      const double c = scaled_constraint(zone, k, y.data());
      violation = std::max(violation, c);
      al.lambda[k] = std::max(0.0, al.lambda[k] + al.mu * c);
      slack = std::max(slack, al.lambda[k] * std::abs(c));
    }
    if (violation <= 1e-3 && slack <= 1e-4) return;
    if (violation > 0.25 * previous_violation) al.mu = std::min(al.mu * 10, kMaxPenalty);
    previous_violation = violation;
  }
}

double constraint_gap(const ZoneConstraint& c, const std::vector<Vec3>& x) {
  double gap = c.fixed_offset;
  for (int i = 0; i < 4; ++i)
    if (c.vars[i] != kNone) gap += c.weights[i] * c.normal.dot(x[c.vars[i]]);
  return gap;
}

}  // namespace

double required_move(const ZoneProblem& problem) {
  double depth = problem.thickness;
  for (const ZoneConstraint& c : problem.constraints)
    depth = std::max(depth, problem.thickness - constraint_gap(c, problem.target));
  return depth;
}

double largest_move(const ZoneProblem& problem, const std::vector<Vec3>& x) {
  double moved = 0;
  for (size_t i = 0; i < x.size(); ++i) moved = std::max(moved, (x[i] - problem.target[i]).norm());
  return moved;
}

double worst_zone_gap(const ZoneProblem& problem, const std::vector<Vec3>& x) {
  double worst = kInfinity;
  for (const ZoneConstraint& c : problem.constraints) worst = std::min(worst, constraint_gap(c, x));
  return worst;
}

ZoneResult solve_impact_zone(const ZoneProblem& problem, std::vector<Vec3>& x, ZoneMethod method,
                             double work_limit) {
  ZoneResult result;
  const int nodes = static_cast<int>(problem.target.size());
  const double h = problem.thickness;
  if (nodes == 0 || problem.constraints.empty() || !(h > 0)) {
    result.worst_gap = worst_zone_gap(problem, x);
    result.solved = result.worst_gap >= 0.5 * h;
    return result;
  }
  ScaledZone zone;
  zone.problem = &problem;
  double mean_mass = 0;
  for (double m : problem.mass) mean_mass += m / nodes;
  for (double m : problem.mass) zone.relative_mass.push_back(m / mean_mass);
  for (const ZoneConstraint& c : problem.constraints) zone.b.push_back((h - constraint_gap(c, problem.target)) / h);

  const unsigned n = 3 * static_cast<unsigned>(nodes);
  const unsigned m = static_cast<unsigned>(problem.constraints.size());
  std::vector<double> y(n);
  for (int i = 0; i < nodes; ++i)
    for (int d = 0; d < 3; ++d) y[3 * i + d] = (x[i][d] - problem.target[i][d]) / h;

  if (method == ZoneMethod::kAutomatic)
    method = static_cast<int>(n) <= kSlsqpMaxVariables ? ZoneMethod::kSlsqp
                                                       : ZoneMethod::kSparseAugmentedLagrangian;
  // Constraint tolerance in units of the thickness: the gap is enforced to within 0.1%.
  const std::vector<double> tolerance(m, 1e-3);
  const double per_evaluation = zone_evaluation_work(nodes, m);
  zone.max_evaluations = std::floor(work_limit / per_evaluation);
  if (!(zone.max_evaluations >= 1)) {
    result.out_of_budget = true;
    result.worst_gap = worst_zone_gap(problem, x);
    return result;
  }
  try {
    if (method == ZoneMethod::kSlsqp) {
      nlopt::opt opt(nlopt::LD_SLSQP, n);
      opt.set_min_objective(objective, &zone);
      opt.add_inequality_mconstraint(constraints, &zone, tolerance);
      opt.set_xtol_abs(1e-6);
      opt.set_ftol_rel(1e-12);
      opt.set_maxeval(500);
      double f = 0;
      opt.optimize(y, f);
    } else if (method == ZoneMethod::kSparseAugmentedLagrangian) {
      sparse_augmented_lagrangian(zone, y);
    } else {
      nlopt::opt local(nlopt::LD_LBFGS, n);
      local.set_xtol_abs(1e-6);
      local.set_ftol_rel(1e-12);
      local.set_maxeval(2000);
      local.set_vector_storage(10);
      nlopt::opt opt(nlopt::AUGLAG, n);
      opt.set_local_optimizer(local);
      opt.set_min_objective(objective, &zone);
      opt.add_inequality_mconstraint(constraints, &zone, tolerance);
      opt.set_xtol_abs(1e-6);
      opt.set_ftol_rel(1e-12);
      opt.set_maxeval(20000);
      double f = 0;
      opt.optimize(y, f);
    }
  } catch (const std::exception&) {
    // Round-off limits and similar stops still leave NLopt's last point in y; it is checked below.
  }
  std::vector<Vec3> solution(nodes);
  bool finite = true;
  for (int i = 0; i < nodes; ++i) {
    solution[i] = problem.target[i] + h * Vec3(y[3 * i], y[3 * i + 1], y[3 * i + 2]);
    finite = finite && solution[i].allFinite();
  }
  result.evaluations = zone.evaluations;
  result.work = zone.evaluations * per_evaluation;
  if (finite) {
    result.move_ratio = largest_move(problem, solution) / required_move(problem);
    result.ill_conditioned = !(result.move_ratio <= kMaxZoneMoveRatio);
    if (!result.ill_conditioned) x = solution;
  }
  result.worst_gap = worst_zone_gap(problem, x);
  result.solved = finite && !result.ill_conditioned && result.worst_gap >= 0.5 * h;
  result.out_of_budget = !(zone.evaluations < zone.max_evaluations) && !result.solved;
  return result;
}

}  // namespace arcsim
