// The block-sparse system against a dense reference: pattern lookup, element scatter, CSC conversion and the
// CHOLMOD solve, including reuse of the symbolic analysis.
#include <gtest/gtest.h>

#include <random>

#include "physics/block_system.hpp"

namespace arcsim {
namespace {

TEST(BlockSystem, MatchesDenseAssemblyAndSolves) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const int n = 30;
  std::vector<std::array<int, 3>> elements;
  std::vector<std::pair<int, int>> pairs;
  for (int k = 0; k < 60; ++k) {
    std::array<int, 3> e{static_cast<int>(rng() % n), static_cast<int>(rng() % n), static_cast<int>(rng() % n)};
    if (e[0] == e[1] || e[1] == e[2] || e[0] == e[2]) continue;
    elements.push_back(e);
    pairs.emplace_back(e[0], e[1]);
    pairs.emplace_back(e[1], e[2]);
    pairs.emplace_back(e[2], e[0]);
  }
  BlockPattern pattern;
  pattern.build(n, pairs);
  for (const auto& e : elements)
    for (int a : e)
      for (int b : e) EXPECT_GE(pattern.block_index(a, b), 0);
  EXPECT_EQ(pattern.block_index(0, 0) >= 0, true);

  BlockSystem system;
  system.reset(pattern);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (const auto& e : elements) {
    Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Random();
    const Eigen::Matrix<double, 9, 9> K = A * A.transpose();  // symmetric PSD element matrix
    system.add_element<3>(e, element_block_ids<3>(pattern, e), K, 0.5);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) dense.block<3, 3>(3 * e[a], 3 * e[b]) += 0.5 * K.block<3, 3>(3 * a, 3 * b);
  }
  for (int i = 0; i < n; ++i) {
    system.add_diagonal(i, 2.0 * Mat3::Identity());
    dense.block<3, 3>(3 * i, 3 * i) += 2.0 * Mat3::Identity();
  }
  VecX x = VecX::Random(3 * n);
  EXPECT_LT((system.multiply(x) - dense * x).norm(), 1e-10 * (dense * x).norm());

  Eigen::SparseMatrix<double> csc;
  system.to_csc(csc);
  const Eigen::MatrixXd upper = Eigen::MatrixXd(csc);
  EXPECT_LT((upper - Eigen::MatrixXd(dense.triangularView<Eigen::Upper>())).norm(), 1e-12 * dense.norm());

  system.rhs = VecX::Random(3 * n);
  CholeskySolver solver;
  ASSERT_TRUE(solver.factorize(system));
  const VecX sol = solver.solve(system.rhs);
  EXPECT_LT((dense * sol - system.rhs).norm(), 1e-9 * system.rhs.norm());
  // Same pattern: the symbolic analysis is reused.
  ASSERT_TRUE(solver.factorize(system));
  EXPECT_EQ(solver.analyses(), 1);
  // A new pattern triggers a new analysis.
  BlockPattern other;
  other.build(n, pairs);
  BlockSystem system2;
  system2.reset(other);
  for (int i = 0; i < n; ++i) system2.add_diagonal(i, Mat3::Identity());
  ASSERT_TRUE(solver.factorize(system2));
  EXPECT_EQ(solver.analyses(), 2);
  // Rebuilt with the same structure (pairs in another order, repeated): same id, the analysis is reused and the
  // solution is the same. With a pair more, or a node more: a new id.
  const uint64_t id = pattern.id();
  std::vector<std::pair<int, int>> reordered(pairs.rbegin(), pairs.rend());
  reordered.insert(reordered.end(), pairs.begin(), pairs.begin() + 5);
  pattern.build(n, reordered);
  EXPECT_EQ(pattern.id(), id);
  ASSERT_TRUE(solver.factorize(system));
  EXPECT_EQ(solver.analyses(), 3);  // system2's pattern was the last one analysed
  ASSERT_TRUE(solver.factorize(system));
  EXPECT_EQ(solver.analyses(), 3);
  EXPECT_EQ(solver.solve(system.rhs), sol);
  std::vector<std::pair<int, int>> more = pairs;
  int a = 0, b = 1;
  while (pattern.block_index(a, b) >= 0) b == n - 1 ? (++a, b = a + 1) : ++b;
  more.emplace_back(a, b);
  pattern.build(n, more);
  EXPECT_NE(pattern.id(), id);
  const uint64_t id_more = pattern.id();
  pattern.build(n + 1, more);
  EXPECT_NE(pattern.id(), id_more);
}

// An element with one node in two slots (a bending element whose wings coincide, at a valence-3 node) adds
// its cross blocks to that node's diagonal: the assembled matrix is P K P^T, PSD like K. Dropping them left a
// PSD element's contribution indefinite (ARCSim's paper-tearing.json failed its factorisation at frame 665).
TEST(BlockSystem, RepeatedNodeGetsTheCrossBlocks) {
  BlockPattern pattern;
  pattern.build(2, {{0, 1}});
  BlockSystem system;
  system.reset(pattern);
  const std::array<int, 3> e{0, 1, 1};
  // K = v v^T with v moving slot 1 and slot 2 opposite ways: an energy of x_1 - x_2 = 0 for the merged node,
  // so P K P^T has no stiffness on node 1 along v; without the cross blocks it would keep 2 |v_1|^2.
  Eigen::Matrix<double, 9, 1> v = Eigen::Matrix<double, 9, 1>::Zero();
  v.segment<3>(3) = Vec3(1, 0, 0);
  v.segment<3>(6) = Vec3(-1, 0, 0);
  Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Random();
  const Eigen::Matrix<double, 9, 9> K = v * v.transpose() + 0.1 * A * A.transpose();
  system.add_element<3>(e, element_block_ids<3>(pattern, e), K, 1.0);
  Eigen::Matrix<double, 9, 6> P = Eigen::Matrix<double, 9, 6>::Zero();
  P.block<3, 3>(0, 0) = Mat3::Identity();
  P.block<3, 3>(3, 3) = Mat3::Identity();
  P.block<3, 3>(6, 3) = Mat3::Identity();
  const Eigen::Matrix<double, 6, 6> expected = P.transpose() * K * P;
  const VecX x = VecX::Random(6);
  EXPECT_LT((system.multiply(x) - expected * x).norm(), 1e-12 * (expected * x).norm());
}

TEST(BlockSystem, IndefiniteMatrixIsReportedNotSolved) {
  BlockPattern pattern;
  pattern.build(2, {{0, 1}});
  BlockSystem system;
  system.reset(pattern);
  system.add_diagonal(0, Mat3::Identity());
  system.add_diagonal(1, -Mat3::Identity());
  CholeskySolver solver;
  EXPECT_FALSE(solver.factorize(system));
}

// A failed factorisation says at which row of the matrix (in its own order, whatever CHOLMOD's fill-reducing
// permutation) the pivot was not positive: the one negative entry of an otherwise positive chain.
TEST(BlockSystem, FailedFactorisationNamesItsRow) {
  const int n = 40;
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i + 1 < n; ++i) pairs.emplace_back(i, i + 1);
  BlockPattern pattern;
  pattern.build(n, pairs);
  BlockSystem system;
  system.reset(pattern);
  for (int i = 0; i < n; ++i) system.add_diagonal(i, 4.0 * Mat3::Identity());
  for (int i = 0; i + 1 < n; ++i) system.blocks[pattern.block_index(i, i + 1)] = -Mat3::Identity();
  CholeskySolver solver;
  ASSERT_TRUE(solver.factorize(system));
  EXPECT_EQ(solver.failed_row(), -1);
  system.blocks[pattern.diagonal_block(27)](1, 1) = -1.0;
  ASSERT_FALSE(solver.factorize(system));
  EXPECT_EQ(solver.failed_row(), 3 * 27 + 1);
}

// A random definite block system on a random pattern: blocks of A A^T element matrices scaled by `stiffness`,
// plus `mass` on the diagonal. The same seed gives the same pattern and directions whatever the scales.
struct RandomSystem {
  BlockPattern pattern;
  BlockSystem system;
  Eigen::MatrixXd dense;

  RandomSystem(int n, unsigned seed, double stiffness, double mass, double perturbation = 0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<std::array<int, 3>> elements;
    std::vector<std::pair<int, int>> pairs;
    for (int k = 0; k < 4 * n; ++k) {
      std::array<int, 3> e{static_cast<int>(rng() % n), static_cast<int>(rng() % n), static_cast<int>(rng() % n)};
      if (e[0] == e[1] || e[1] == e[2] || e[0] == e[2]) continue;
      elements.push_back(e);
      pairs.emplace_back(e[0], e[1]);
      pairs.emplace_back(e[1], e[2]);
      pairs.emplace_back(e[2], e[0]);
    }
    pattern.build(n, pairs);
    system.reset(pattern);
    dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    std::mt19937 wobble(seed + 1000);
    for (const auto& e : elements) {
      Eigen::Matrix<double, 9, 9> A;
      for (int i = 0; i < 81; ++i) A.data()[i] = u(rng) + perturbation * u(wobble);
      const Eigen::Matrix<double, 9, 9> K = A * A.transpose();
      system.add_element<3>(e, element_block_ids<3>(pattern, e), K, stiffness);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          dense.block<3, 3>(3 * e[a], 3 * e[b]) += stiffness * K.block<3, 3>(3 * a, 3 * b);
    }
    for (int i = 0; i < n; ++i) {
      system.add_diagonal(i, mass * Mat3::Identity());
      dense.block<3, 3>(3 * i, 3 * i) += mass * Mat3::Identity();
    }
    system.rhs = VecX::NullaryExpr(3 * n, [&] { return u(rng); });
  }
};

SolverSettings iterative_settings(double tolerance, int max_iterations) {
  SolverSettings s;
  s.pcg_min_nodes = 0;
  s.pcg_tolerance = tolerance;
  s.pcg_max_iterations = max_iterations;
  return s;
}

TEST(CholeskySolverPcg, SmallSystemsAreFactorisedAtEverySolve) {
  RandomSystem a(40, 3, 1.0, 1.0);
  CholeskySolver solver;  // default settings: 40 nodes is far below pcg_min_nodes
  VecX x;
  SolveReport report;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(solver.solve_system(a.system, x, report));
    EXPECT_TRUE(report.factorized);
    EXPECT_EQ(report.iterations, 0);
    EXPECT_LT(report.residual, 1e-12);
    EXPECT_LT((a.dense * x - a.system.rhs).norm(), 1e-12 * a.system.rhs.norm());
  }
  EXPECT_EQ(solver.factorizations(), 3);
}

TEST(CholeskySolverPcg, ConvergesWithAKeptFactorisationOfANearbyMatrix) {
  CholeskySolver solver;
  solver.set_settings(iterative_settings(1e-10, 30));
  RandomSystem first(60, 7, 1.0, 0.1);
  VecX x;
  SolveReport report;
  ASSERT_TRUE(solver.solve_system(first.system, x, report));
  EXPECT_TRUE(report.factorized);
  // The same matrix again: the kept factor is exact, one iteration.
  ASSERT_TRUE(solver.solve_system(first.system, x, report));
  EXPECT_FALSE(report.factorized);
  EXPECT_EQ(report.iterations, 1);
  // A matrix 2% away (another pattern object, the same size): conjugate gradients to the tolerance, and the
  // answer is the direct solve's to that precision.
  RandomSystem nearby(60, 7, 1.0, 0.1, 0.02);
  ASSERT_TRUE(solver.solve_system(nearby.system, x, report));
  EXPECT_FALSE(report.factorized);
  EXPECT_GT(report.iterations, 1);
  EXPECT_LE(report.iterations, 30);
  EXPECT_LE(report.residual, 1e-10 * 1.0001);
  const VecX exact = nearby.dense.llt().solve(nearby.system.rhs);
  EXPECT_LT((x - exact).norm(), 1e-6 * exact.norm());
  EXPECT_EQ(solver.factorizations(), 1);
}

TEST(CholeskySolverPcg, AStaleFactorisationIsRefreshed) {
  CholeskySolver solver;
  solver.set_settings(iterative_settings(1e-8, 4));
  RandomSystem soft(60, 11, 1.0, 0.01);
  VecX x;
  SolveReport report;
  ASSERT_TRUE(solver.solve_system(soft.system, x, report));
  // Far from the kept factor (other element matrices, 100x stiffer): 4 iterations do not reach 1e-8, so the solve
  // factorises afresh and is direct.
  RandomSystem stiff(60, 12, 100.0, 0.01);
  ASSERT_TRUE(solver.solve_system(stiff.system, x, report));
  EXPECT_TRUE(report.factorized);
  EXPECT_EQ(report.iterations, 4);
  EXPECT_LT(report.residual, 1e-12);
  EXPECT_LT((stiff.dense * x - stiff.system.rhs).norm(), 1e-12 * stiff.system.rhs.norm());
  EXPECT_EQ(solver.factorizations(), 2);
  // The refreshed factor now serves the stiff matrix at once; refresh() forces a factorisation.
  ASSERT_TRUE(solver.solve_system(stiff.system, x, report));
  EXPECT_FALSE(report.factorized);
  solver.refresh();
  ASSERT_TRUE(solver.solve_system(stiff.system, x, report));
  EXPECT_TRUE(report.factorized);
  // Another size: factorised.
  RandomSystem other(50, 13, 1.0, 1.0);
  ASSERT_TRUE(solver.solve_system(other.system, x, report));
  EXPECT_TRUE(report.factorized);
}

TEST(CholeskySolverPcg, AnIndefiniteMatrixStillFailsUnderTheIteration) {
  CholeskySolver solver;
  solver.set_settings(iterative_settings(1e-10, 20));
  RandomSystem good(40, 17, 1.0, 1.0);
  VecX x;
  SolveReport report;
  ASSERT_TRUE(solver.solve_system(good.system, x, report));
  RandomSystem bad(40, 17, 1.0, 1.0);
  for (int i = 0; i < 40; ++i) bad.system.add_diagonal(i, -1e3 * Mat3::Identity());
  EXPECT_FALSE(solver.solve_system(bad.system, x, report));
}

// The solver hands CHOLMOD the permuted lower triangle through a map kept per analysis: its factor must be the
// one CHOLMOD makes from the upper triangle itself (Eigen's wrapper, same ordering), bit for bit, before and
// after the values change on the same pattern, and after a new pattern.
TEST(CholeskySolver, PermutedLayoutGivesCholmodsOwnFactor) {
  std::mt19937 rng(11);
  const int n = 40;
  std::vector<std::pair<int, int>> pairs;
  for (int k = 0; k < 120; ++k) pairs.emplace_back(static_cast<int>(rng() % n), static_cast<int>(rng() % n));
  BlockPattern pattern;
  pattern.build(n, pairs);
  CholeskySolver solver;
  SolverSettings cholmod_only;
  cholmod_only.block_max_nodes = 0;  // this small system would otherwise go to BlockCholesky
  solver.set_settings(cholmod_only);
  for (int round = 0; round < 3; ++round) {
    if (round == 2) {  // a new pattern: a new analysis and a new map
      pairs.emplace_back(0, n - 1);
      pattern.build(n, pairs);
    }
    BlockSystem system;
    system.reset(pattern);
    for (int k = 0; k < pattern.block_count(); ++k) {
      const Mat3 r = Mat3::Random();
      system.blocks[k] = pattern.block_row(k) == pattern.block_col(k) ? Mat3(r * r.transpose() + 8 * Mat3::Identity())
                                                                        : Mat3(0.1 * r);
    }
    system.rhs = VecX::Random(3 * n);
    ASSERT_TRUE(solver.factorize(system));
    const VecX ours = solver.solve(system.rhs);

    Eigen::SparseMatrix<double> upper;
    system.to_csc(upper);
    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Upper> reference;
    reference.cholmod().nmethods = 1;
    reference.cholmod().method[0].ordering = CHOLMOD_AMD;
    reference.compute(upper);
    ASSERT_EQ(reference.info(), Eigen::Success);
    const VecX expected = reference.solve(system.rhs);
    EXPECT_TRUE(ours == expected) << "round " << round << ": " << (ours - expected).norm();
  }
  EXPECT_EQ(solver.analyses(), 2);
}

}  // namespace
}  // namespace arcsim
