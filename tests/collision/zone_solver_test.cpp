// The impact-zone projection (NLopt) against closed forms and against an independent QP solver (Hildreth's
// dual coordinate ascent), with both NLopt methods.
#include <gtest/gtest.h>

#include <chrono>
#include <random>

#include "collision/zone_solver.hpp"

namespace arcsim {
namespace {

constexpr double kGap = 1e-4;  // m

ZoneConstraint make_constraint(std::array<int, 4> vars, std::array<double, 4> w, const Vec3& n, double fixed = 0) {
  ZoneConstraint c;
  c.vars = vars;
  c.weights = w;
  c.normal = n.normalized();
  c.fixed_offset = fixed;
  return c;
}

// Minimises sum m |x - x*|^2 subject to the constraints by coordinate ascent on the dual (exact for this QP in
// the limit; run to convergence).
std::vector<Vec3> hildreth(const ZoneProblem& p) {
  std::vector<Vec3> x = p.target;
  std::vector<double> lambda(p.constraints.size(), 0);
  for (int sweep = 0; sweep < 20000; ++sweep) {
    double change = 0;
    for (size_t k = 0; k < p.constraints.size(); ++k) {
      const ZoneConstraint& c = p.constraints[k];
      double gap = c.fixed_offset, norm = 0;
      for (int i = 0; i < 4; ++i) {
        if (c.vars[i] == kNone) continue;
        gap += c.weights[i] * c.normal.dot(x[c.vars[i]]);
        norm += c.weights[i] * c.weights[i] / p.mass[c.vars[i]];
      }
      const double next = std::max(0.0, lambda[k] + (p.thickness - gap) / norm);
      const double d = next - lambda[k];
      lambda[k] = next;
      for (int i = 0; i < 4; ++i)
        if (c.vars[i] != kNone) x[c.vars[i]] += d * c.weights[i] / p.mass[c.vars[i]] * c.normal;
      change = std::max(change, std::abs(d) * norm);
    }
    if (change < 1e-14 * p.thickness) break;
  }
  return x;
}

// Smallest constraint gap n . sum_i w_i x_i + fixed_offset at positions x (m), computed here from the
// constraints (not by the solver's own worst_zone_gap) so that the solver does not grade itself.
double smallest_gap(const ZoneProblem& p, const std::vector<Vec3>& x) {
  double smallest = kInfinity;
  for (const ZoneConstraint& c : p.constraints) {
    double gap = c.fixed_offset;
    for (int i = 0; i < 4; ++i)
      if (c.vars[i] != kNone) gap += c.weights[i] * c.normal.dot(x[c.vars[i]]);
    smallest = std::min(smallest, gap);
  }
  return smallest;
}

double max_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return d;
}

TEST(ZoneSolver, SingleNodeAgainstFixedPlane) {
  ZoneProblem p;
  p.thickness = kGap;
  p.target = {Vec3(0.1, 0.2, -1e-3)};
  p.mass = {0.01};
  // Gap = z of the node above a fixed point at z = 0.
  p.constraints = {make_constraint({0, kNone, kNone, kNone}, {1, 0, 0, 0}, Vec3::UnitZ())};
  for (ZoneMethod method : {ZoneMethod::kSlsqp, ZoneMethod::kAugmentedLagrangian, ZoneMethod::kSparseAugmentedLagrangian}) {
    std::vector<Vec3> x = p.target;
    const ZoneResult r = solve_impact_zone(p, x, method);
    EXPECT_TRUE(r.solved);
    EXPECT_NEAR(x[0].z(), kGap, 2e-3 * kGap);
    EXPECT_NEAR(x[0].x(), 0.1, 1e-3 * kGap);
    EXPECT_NEAR(x[0].y(), 0.2, 1e-3 * kGap);
  }
}

TEST(ZoneSolver, VertexFaceImpactMatchesClosedForm) {
  // Vertex (mass 1) ends 2e-4 m below a face of three nodes (mass 2 each) at barycentrics (0.2, 0.3, 0.5).
  ZoneProblem p;
  p.thickness = kGap;
  p.target = {Vec3(0.3, 0.4, -2e-4), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  p.mass = {1, 2, 2, 2};
  const std::array<double, 4> w{1, -0.2, -0.3, -0.5};
  p.constraints = {make_constraint({0, 1, 2, 3}, w, Vec3::UnitZ())};
  // One active linear constraint a.x >= h: x = x* + lambda M^-1 a, lambda = (h - a.x*) / (a^T M^-1 a).
  double ama = 0, gap = 0;
  for (int i = 0; i < 4; ++i) ama += w[i] * w[i] / p.mass[i], gap += w[i] * p.target[i].z();
  const double lambda = (kGap - gap) / ama;
  for (ZoneMethod method : {ZoneMethod::kSlsqp, ZoneMethod::kAugmentedLagrangian, ZoneMethod::kSparseAugmentedLagrangian}) {
    std::vector<Vec3> x = p.target;
    ASSERT_TRUE(solve_impact_zone(p, x, method).solved);
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(x[i].z(), p.target[i].z() + lambda * w[i] / p.mass[i], 2e-3 * kGap);
  }
}

TEST(ZoneSolver, SatisfiedConstraintsMoveNothing) {
  ZoneProblem p;
  p.thickness = kGap;
  p.target = {Vec3(0, 0, 1)};
  p.mass = {1};
  p.constraints = {make_constraint({0, kNone, kNone, kNone}, {1, 0, 0, 0}, Vec3::UnitZ())};
  std::vector<Vec3> x = p.target;
  ASSERT_TRUE(solve_impact_zone(p, x).solved);
  EXPECT_LT((x[0] - p.target[0]).norm(), 1e-3 * kGap);
}

// A random zone: a chain of nodes with VF- and EE-like constraints between neighbours and some against fixed
// geometry, all violated at the target.
ZoneProblem random_zone(int nodes, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1), W(0.05, 1);
  ZoneProblem p;
  p.thickness = kGap;
  for (int i = 0; i < nodes; ++i) {
    p.target.push_back(Vec3(U(rng), U(rng), U(rng)) * 0.01);
    p.mass.push_back(W(rng) * 1e-3);
  }
  for (int i = 0; i + 3 < nodes; ++i) {
    const double b0 = W(rng), b1 = W(rng), b2 = W(rng), s = b0 + b1 + b2;
    ZoneConstraint c = make_constraint({i, i + 1, i + 2, i + 3}, {1, -b0 / s, -b1 / s, -b2 / s},
                                       Vec3(U(rng), U(rng), U(rng)));
    // Violated by up to 3 thicknesses at the target.
    double gap = 0;
    for (int k = 0; k < 4; ++k) gap += c.weights[k] * c.normal.dot(p.target[c.vars[k]]);
    c.fixed_offset = -gap + kGap * (1 - 4 * W(rng));
    p.constraints.push_back(c);
  }
  for (int i = 0; i < nodes; i += 3) {
    ZoneConstraint c = make_constraint({i, kNone, kNone, kNone}, {1, 0, 0, 0}, Vec3(U(rng), U(rng), 1));
    c.fixed_offset = -c.normal.dot(p.target[i]) - kGap * W(rng);
    p.constraints.push_back(c);
  }
  return p;
}

TEST(ZoneSolver, RandomZonesMatchIndependentQpSolver) {
  for (int nodes : {4, 12, 24}) {
    const ZoneProblem p = random_zone(nodes, 40 + nodes);
    const std::vector<Vec3> expected = hildreth(p);
    ASSERT_GE(smallest_gap(p, expected), kGap * (1 - 1e-6));
    // The target violates the constraints, so a solver that returned it would fail below.
    ASSERT_LT(smallest_gap(p, p.target), 0.0);
    for (ZoneMethod method : {ZoneMethod::kSlsqp, ZoneMethod::kAugmentedLagrangian, ZoneMethod::kSparseAugmentedLagrangian}) {
      std::vector<Vec3> x = p.target;
      const ZoneResult r = solve_impact_zone(p, x, method);
      EXPECT_TRUE(r.solved) << nodes << " nodes, method " << static_cast<int>(method);
      // The gap recomputed from the returned positions, and the one the solver reports for them.
      const double gap = smallest_gap(p, x);
      EXPECT_GE(gap, kGap * (1 - 2e-3)) << nodes << " nodes, method " << static_cast<int>(method);
      EXPECT_NEAR(r.worst_gap, gap, 1e-9 * kGap) << nodes << " nodes, method " << static_cast<int>(method);
      EXPECT_LT(max_difference(x, expected), 2e-2 * kGap) << nodes << " nodes, method " << static_cast<int>(method);
    }
  }
}

TEST(ZoneSolver, InfeasibleZoneReportsFailure) {
  // The node must be above +h and below -h of the same fixed point.
  ZoneProblem p;
  p.thickness = kGap;
  p.target = {Vec3::Zero()};
  p.mass = {1};
  p.constraints = {make_constraint({0, kNone, kNone, kNone}, {1, 0, 0, 0}, Vec3::UnitZ()),
                   make_constraint({0, kNone, kNone, kNone}, {1, 0, 0, 0}, -Vec3::UnitZ())};
  std::vector<Vec3> x = p.target;
  const ZoneResult r = solve_impact_zone(p, x);
  EXPECT_FALSE(r.solved);
  EXPECT_TRUE(x[0].allFinite());
}

TEST(ZoneSolver, ContradictingConstraintsAreIllConditionedAndNotApplied) {
  // One node held by two nearly opposite planes through the origin (normals +x and -x, tilted 1% up): both
  // hold only ~100 thicknesses up, so the exact answer moves the node ~100x the deepest violation (the
  // thickness). The solver must flag it and leave x at its start.
  ZoneProblem p;
  p.thickness = kGap;
  p.target = {Vec3(0, 0, 0), Vec3(0.01, 0, 0)};
  p.mass = {1, 1};
  const Vec3 plus = Vec3(1, 0, 0.01).normalized(), minus = Vec3(-1, 0, 0.01).normalized();
  p.constraints.push_back(make_constraint({0, kNone, kNone, kNone}, {1, 0, 0, 0}, plus));
  p.constraints.push_back(make_constraint({0, kNone, kNone, kNone}, {1, 0, 0, 0}, minus));
  std::vector<Vec3> x = p.target;
  const ZoneResult r = solve_impact_zone(p, x);
  EXPECT_TRUE(r.ill_conditioned);
  EXPECT_FALSE(r.solved);
  EXPECT_GT(r.move_ratio, kMaxZoneMoveRatio);
  EXPECT_EQ(max_difference(x, p.target), 0.0);
  // The same node against one of the planes only: an ordinary, well-conditioned projection.
  p.constraints.pop_back();
  x = p.target;
  const ZoneResult one = solve_impact_zone(p, x);
  EXPECT_FALSE(one.ill_conditioned);
  EXPECT_TRUE(one.solved);
  EXPECT_LT(one.move_ratio, 1.01);
  EXPECT_NEAR(largest_move(p, x), kGap, 1e-3 * kGap);
}

// The work limit: each method spends at most what it is given (in zone_evaluation_work units), reports running out
// when that stops it short of a solution, and with enough for its whole solve gives the unlimited result exactly.
TEST(ZoneSolver, WorkLimitStopsTheOptimiserAndIsReported) {
  const ZoneProblem p = random_zone(24, 64);
  const double per_evaluation = zone_evaluation_work(24, p.constraints.size());
  for (ZoneMethod method : {ZoneMethod::kSlsqp, ZoneMethod::kAugmentedLagrangian, ZoneMethod::kSparseAugmentedLagrangian}) {
    SCOPED_TRACE(static_cast<int>(method));
    std::vector<Vec3> free = p.target;
    const ZoneResult unlimited = solve_impact_zone(p, free, method);
    ASSERT_TRUE(unlimited.solved);
    EXPECT_FALSE(unlimited.out_of_budget);
    EXPECT_EQ(unlimited.work, unlimited.evaluations * per_evaluation);
    ASSERT_GT(unlimited.evaluations, 12);

    std::vector<Vec3> x = p.target;
    const double limit = 1 * per_evaluation;
    const ZoneResult stopped = solve_impact_zone(p, x, method, limit);
    EXPECT_TRUE(stopped.out_of_budget);
    EXPECT_FALSE(stopped.solved);
    // (NLopt's AUGLAG checks its count only after its inner optimiser returns: one evaluation more.)
    EXPECT_LE(stopped.work, limit + per_evaluation);

    // Too little for a single evaluation: nothing is tried.
    x = p.target;
    const ZoneResult none = solve_impact_zone(p, x, method, 0.5 * per_evaluation);
    EXPECT_TRUE(none.out_of_budget);
    EXPECT_EQ(none.evaluations, 0);
    EXPECT_EQ(max_difference(x, p.target), 0.0);

    x = p.target;
    const ZoneResult enough = solve_impact_zone(p, x, method, 2 * unlimited.work);
    EXPECT_TRUE(enough.solved);
    EXPECT_FALSE(enough.out_of_budget);
    EXPECT_EQ(enough.evaluations, unlimited.evaluations);
    EXPECT_EQ(max_difference(x, free), 0.0);
  }
}

}  // namespace
}  // namespace arcsim
