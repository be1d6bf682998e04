// BlockCholesky against a dense factorisation and against CHOLMOD: solutions, the factor's fill, failed pivots,
// refactorisation on a kept analysis, and CholeskySolver's choice between the two factorisations.
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <random>

#include "physics/block_cholesky.hpp"
#include "physics/block_system.hpp"

namespace arcsim {
namespace {

// A definite system on `pairs`: every off-diagonal block a general 3x3 (not symmetric, so that a block read
// transposed shows), diagonal blocks symmetric and dominant.
struct TestSystem {
  BlockPattern pattern;
  BlockSystem system;
  Eigen::MatrixXd dense;

  TestSystem(int n, const std::vector<std::pair<int, int>>& pairs, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    pattern.build(n, pairs);
    system.reset(pattern);
    dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    std::vector<double> row_sum(n, 0.0);
    for (int k = 0; k < pattern.block_count(); ++k) {
      const int r = pattern.block_row(k), c = pattern.block_col(k);
      if (r == c) continue;
      Mat3 block;
      for (int i = 0; i < 9; ++i) block.data()[i] = u(rng);
      system.blocks[k] = block;
      dense.block<3, 3>(3 * r, 3 * c) = block;
      dense.block<3, 3>(3 * c, 3 * r) = block.transpose();
      row_sum[r] += 3;
      row_sum[c] += 3;
    }
    for (int i = 0; i < n; ++i) {
      Mat3 a;
      for (int j = 0; j < 9; ++j) a.data()[j] = u(rng);
      const Mat3 diagonal = a * a.transpose() + (row_sum[i] + 0.5) * Mat3::Identity();
      system.blocks[pattern.diagonal_block(i)] = diagonal;
      dense.block<3, 3>(3 * i, 3 * i) = diagonal;
    }
    system.rhs = VecX::NullaryExpr(3 * n, [&] { return u(rng); });
  }
};

std::vector<std::pair<int, int>> random_pairs(int n, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::pair<int, int>> pairs;
  for (int k = 0; k < count && n > 1; ++k) pairs.emplace_back(static_cast<int>(rng() % n), static_cast<int>(rng() % n));
  return pairs;
}

// A triangulated grid's edges, as a sheet's membrane terms give them (nodes row by row).
std::vector<std::pair<int, int>> grid_pairs(int cells) {
  std::vector<std::pair<int, int>> pairs;
  const int side = cells + 1;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      const int v = i * side + j;
      if (j + 1 < side) pairs.emplace_back(v, v + 1);
      if (i + 1 < side) pairs.emplace_back(v, v + side);
      if (i + 1 < side && j + 1 < side) pairs.emplace_back(v, v + side + 1);
    }
  return pairs;
}

TEST(BlockCholesky, SolvesLikeADenseFactorisation) {
  struct Case {
    int n;
    std::vector<std::pair<int, int>> pairs;
  };
  const std::vector<Case> cases = {{1, {}},
                                   {2, {{0, 1}}},
                                   {5, {}},  // no coupling at all
                                   {40, random_pairs(40, 120, 3)},
                                   {150, random_pairs(150, 400, 4)},
                                   {121, grid_pairs(10)}};
  for (const auto kernel : {BlockCholesky::Kernel::kFastest, BlockCholesky::Kernel::kGeneric})
    for (size_t c = 0; c < cases.size(); ++c) {
      SCOPED_TRACE("case " + std::to_string(c) + (kernel == BlockCholesky::Kernel::kGeneric ? ", generic" : ""));
      const TestSystem t(cases[c].n, cases[c].pairs, static_cast<unsigned>(c + 7));
      BlockCholesky factor(kernel);
      factor.analyse(t.pattern);
      if (kernel == BlockCholesky::Kernel::kGeneric) {
        EXPECT_FALSE(factor.uses_avx2());
      }
      ASSERT_TRUE(factor.factorize(t.system));
      EXPECT_EQ(factor.failed_row(), -1);
      const VecX x = factor.solve(t.system.rhs);
      const VecX expected = t.dense.llt().solve(t.system.rhs);
      EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm());
      EXPECT_LT((t.dense * x - t.system.rhs).norm(), 1e-12 * t.system.rhs.norm());
    }
}

// The factor's pattern is the elimination graph's: a chain and a star (whose centre AMD eliminates last) fill
// nothing in; a cycle fills one block per elimination but the last two; a grid fills in.
TEST(BlockCholesky, FactorHasTheFillOfTheEliminationGraph) {
  const int n = 30;
  std::vector<std::pair<int, int>> chain, star, cycle;
  for (int i = 0; i + 1 < n; ++i) chain.emplace_back(i, i + 1);
  for (int i = 1; i < n; ++i) star.emplace_back(0, i);
  cycle = chain;
  cycle.emplace_back(n - 1, 0);
  auto blocks_of_factor = [](int nodes, const std::vector<std::pair<int, int>>& pairs) {
    const TestSystem t(nodes, pairs, 1);
    BlockCholesky factor;
    factor.analyse(t.pattern);
    return factor.factor_entries() / 9;
  };
  EXPECT_EQ(blocks_of_factor(n, chain), 2 * n - 1);
  EXPECT_EQ(blocks_of_factor(n, star), 2 * n - 1);
  EXPECT_EQ(blocks_of_factor(n, cycle), 3 * n - 3);
  const TestSystem grid(121, grid_pairs(10), 2);
  BlockCholesky factor;
  factor.analyse(grid.pattern);
  EXPECT_GT(factor.factor_entries() / 9, grid.pattern.block_count());
  EXPECT_GT(factor.factor_flops(), 0);
}

// A failed pivot names the row of A (its own order) where it failed, whichever of a node's three it is, and a
// NaN fails as a non-positive pivot does.
TEST(BlockCholesky, NamesTheRowWhosePivotFailed) {
  const int n = 40;
  std::vector<std::pair<int, int>> chain;
  for (int i = 0; i + 1 < n; ++i) chain.emplace_back(i, i + 1);
  for (int component = 0; component < 3; ++component) {
    TestSystem t(n, chain, 9);
    t.system.blocks[t.pattern.diagonal_block(27)](component, component) = -1e3;
    BlockCholesky factor;
    factor.analyse(t.pattern);
    EXPECT_FALSE(factor.factorize(t.system));
    EXPECT_EQ(factor.failed_row(), 3 * 27 + component);
  }
  // A NaN (here in an off-diagonal block, so that it spreads through the updates before a pivot meets it)
  // fails the factorisation, and leaves nothing behind: the same analysis then factorises a good matrix as a
  // fresh one does.
  for (const auto kernel : {BlockCholesky::Kernel::kFastest, BlockCholesky::Kernel::kGeneric}) {
    const TestSystem good(n, chain, 9);
    TestSystem t = good;
    t.system.blocks[t.pattern.block_index(4, 5)](2, 0) = std::numeric_limits<double>::quiet_NaN();
    BlockCholesky factor(kernel), fresh(kernel);
    factor.analyse(t.pattern);
    EXPECT_FALSE(factor.factorize(t.system));
    EXPECT_GE(factor.failed_row(), 0);
    ASSERT_TRUE(factor.factorize(good.system));
    EXPECT_EQ(factor.failed_row(), -1);
    fresh.analyse(good.pattern);
    ASSERT_TRUE(fresh.factorize(good.system));
    EXPECT_TRUE(factor.solve(good.system.rhs) == fresh.solve(good.system.rhs));
  }
}

// A kept analysis factorises a new matrix on the same pattern as a fresh one does, bit for bit: nothing of the
// previous factor (its fill-in included) leaks into the next.
TEST(BlockCholesky, RefactorisationOnAKeptAnalysisIsFresh) {
  const auto pairs = grid_pairs(8);
  const TestSystem first(81, pairs, 21), second(81, pairs, 22);
  BlockCholesky kept, fresh;
  kept.analyse(first.pattern);
  ASSERT_TRUE(kept.factorize(first.system));
  ASSERT_TRUE(kept.factorize(second.system));
  fresh.analyse(second.pattern);
  ASSERT_TRUE(fresh.factorize(second.system));
  EXPECT_TRUE(kept.solve(second.system.rhs) == fresh.solve(second.system.rhs));
}

// CholeskySolver takes BlockCholesky up to block_max_nodes nodes and CHOLMOD above; both solve the same system
// to round-off, a change of side re-analyses, and a failed pivot is reported the same way.
TEST(CholeskySolver, ChoosesTheFactorisationBySize) {
  const TestSystem t(121, grid_pairs(10), 31);
  const VecX expected = t.dense.llt().solve(t.system.rhs);
  CholeskySolver solver;
  SolverSettings settings;
  settings.block_max_nodes = 121;
  solver.set_settings(settings);
  ASSERT_TRUE(solver.factorize(t.system));
  EXPECT_TRUE(solver.uses_block_factorization());
  const VecX by_blocks = solver.solve(t.system.rhs);
  settings.block_max_nodes = 120;
  solver.set_settings(settings);
  ASSERT_TRUE(solver.factorize(t.system));
  EXPECT_FALSE(solver.uses_block_factorization());
  const VecX by_cholmod = solver.solve(t.system.rhs);
  EXPECT_EQ(solver.analyses(), 2);
  EXPECT_LT((by_blocks - expected).norm(), 1e-12 * expected.norm());
  EXPECT_LT((by_cholmod - expected).norm(), 1e-12 * expected.norm());

  VecX x;
  SolveReport report;
  settings.block_max_nodes = 121;
  solver.set_settings(settings);
  ASSERT_TRUE(solver.solve_system(t.system, x, report));
  EXPECT_TRUE(solver.uses_block_factorization());
  EXPECT_LT(report.residual, 1e-13);
  TestSystem broken(121, grid_pairs(10), 31);
  broken.system.blocks[broken.pattern.diagonal_block(60)](2, 2) = -1e4;
  EXPECT_FALSE(solver.solve_system(broken.system, x, report));
  EXPECT_EQ(solver.failed_row(), 3 * 60 + 2);
}

}  // namespace
}  // namespace arcsim
