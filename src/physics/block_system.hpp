// The sparse symmetric linear system of the implicit step, over 3x3 node blocks.
//
// The sparsity pattern depends only on which node pairs interact (faces, hinges, and any extra pairs such as
// contacts), so it is built once per topology and its CHOLMOD symbolic analysis is reused until it changes.
// Element matrices are accumulated into 3x3 blocks in a fixed order (deterministic whatever the thread count),
// then copied, through a map fixed per analysis, into the lower triangle of the permuted matrix P A P' that
// CHOLMOD's supernodal phase factorises (CholeskySolver).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>

#include "math/types.hpp"
#include "physics/block_cholesky.hpp"
#include "physics/solver_settings.hpp"

namespace arcsim {

// Sorts `pairs` as std::sort does (by first, then second) and drops duplicates. Counting sort by first over
// [0, key_count), then each (small) bucket by second: topology changes sort ~50k node pairs per step. Falls back
// to std::sort if a first is out of range.
void sort_unique_pairs(std::vector<std::pair<int, int>>& pairs, int key_count);

class BlockPattern {
 public:
  // Builds the pattern for `node_count` nodes from the node pairs that interact (any order, duplicates fine;
  // diagonal blocks are always present).
  void build(int node_count, std::vector<std::pair<int, int>> pairs);
  int node_count() const { return node_count_; }
  int block_count() const { return static_cast<int>(block_row_.size()); }
  // Index of block (i, j) (either order); -1 if not in the pattern.
  int block_index(int i, int j) const;
  // Index of diagonal block (i, i): build puts it first in its column, as no row of column i is below i.
  int diagonal_block(int i) const { return col_start_[i]; }
  // Identifies the pattern: equal ids mean identical structure (symbolic factorisation can be reused).
  uint64_t id() const { return id_; }

  int block_row(int k) const { return block_row_[k]; }
  int block_col(int k) const { return block_col_[k]; }

  // The layout of the factorised matrix, built on first use after each change of structure: only patterns that
  // are factorised pay for it (a step may rebuild its pattern more than once before it factorises). The
  // compressed-column structure of the upper triangle of the 3n x 3n matrix and, for each block k (stored as
  // (row, col) with row >= col), where its entries go: entry (a, b) of block k, i.e. matrix entry
  // (3*row + a, 3*col + b) = (3*col + b, 3*row + a), is at value index block_value_offset(k, a) + b (b <= a on a
  // diagonal block). The two accessors require prepare_layout().
  void prepare_layout() const;
  const Eigen::SparseMatrix<double>& csc_structure() const { return csc_; }
  int block_value_offset(int k, int b) const { return value_offset_[3 * k + b]; }

 private:
  int node_count_ = 0;
  std::vector<int> col_start_;   // per node column: first block index
  std::vector<int> block_row_;   // per block: row node (>= column node)
  std::vector<int> block_col_;
  // The factorisation layout (prepare_layout).
  mutable bool layout_ready_ = false;
  mutable std::vector<int> value_offset_;
  mutable Eigen::SparseMatrix<double> csc_;
  uint64_t id_ = 0;
};

// A symmetric block matrix on a pattern plus a right-hand side.
struct BlockSystem {
  const BlockPattern* pattern = nullptr;
  std::vector<Mat3> blocks;  // lower blocks (row >= col); diagonal blocks are full symmetric 3x3
  VecX rhs;

  void reset(const BlockPattern& p);
  // Adds an element matrix over rows `nodes` (N nodes, 3N x 3N) scaled by `scale`. Only the lower blocks are
  // read; rows -1 (nodes held fixed) are skipped.
  template <int N>
  void add_element(const std::array<int, N>& nodes, const std::array<int, N * N>& block_ids,
                   const Eigen::Matrix<double, 3 * N, 3 * N>& K, double scale);
  void add_diagonal(int node, const Mat3& K) { blocks[pattern->block_index(node, node)] += K; }
  // y = A x (full symmetric product), for tests and residuals.
  VecX multiply(const VecX& x) const;
  // Fills `out` (with the pattern's structure) with the upper triangle.
  void to_csc(Eigen::SparseMatrix<double>& out) const;
  // Writes the upper triangle's entries elsewhere: the entry to_csc puts at value index q goes to out[place[q]].
  void scatter_upper(const std::vector<int>& place, double* out) const;
};

// Looks up the block ids of all row pairs of an element once per topology (-1 where a row is -1: a node held
// fixed, see physics/system_dofs.hpp).
template <int N>
std::array<int, N * N> element_block_ids(const BlockPattern& p, const std::array<int, N>& rows) {
  // Ids are symmetric, and a diagonal block needs no search: search each a < b once and copy.
  std::array<int, N * N> ids{};
  for (int a = 0; a < N; ++a) {
    ids[a * N + a] = rows[a] < 0 ? -1 : p.diagonal_block(rows[a]);
    for (int b = a + 1; b < N; ++b)
      ids[a * N + b] = ids[b * N + a] = (rows[a] < 0 || rows[b] < 0) ? -1 : p.block_index(rows[a], rows[b]);
  }
  return ids;
}

template <int N>
void BlockSystem::add_element(const std::array<int, N>& nodes, const std::array<int, N * N>& block_ids,
                              const Eigen::Matrix<double, 3 * N, 3 * N>& K, double scale) {
  for (int a = 0; a < N; ++a) {
    for (int b = 0; b < N; ++b) {
      if (nodes[a] < 0 || nodes[b] < 0) continue;
      // Each unordered pair once: take (a, b) where node a is the block's row (>= column). A node in two slots
      // (a bending element whose wings coincide, at a valence-3 node) gets K_ab + K_ba on its diagonal block, as
      // the chain rule says; dropping them left the assembled matrix indefinite (paper-tearing.json, frame 665).
      if (nodes[a] < nodes[b]) continue;
      blocks[block_ids[a * N + b]] += scale * K.template block<3, 3>(3 * a, 3 * b);
    }
  }
}

// CHOLMOD's supernodal LLT that also says where a failed factorisation stopped.
class SupernodalLLT : public Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Upper> {
 public:
  // The matrix row (in the matrix's own order, not CHOLMOD's fill-reducing permutation) whose pivot was not
  // positive in the last factorisation; -1 if it succeeded or none ran.
  int failed_row() const;
  // The fill-reducing permutation of the last analysis: row k of the permuted matrix is row permutation()[k].
  const int* permutation() const;
  // Numeric factorisation from tril(P A P') (P the analysis's permutation), sorted compressed columns: what
  // factorize(A) hands CHOLMOD's supernodal phase after transposing A into that form, so the factor is the same.
  void factorize_permuted_lower(cholmod_sparse& lower);
};

// What one solve_system did.
struct SolveReport {
  bool factorized = false;  // the matrix was factorised (the solve is direct)
  int iterations = 0;       // conjugate-gradient iterations (0 for a direct solve)
  double residual = 0;      // |A x - b| / |b| of the returned x (0 when b = 0)
  double factor_seconds = 0, solve_seconds = 0;  // wall: the factorisation (and analysis); the rest
};

// Sparse Cholesky of a BlockSystem (AMD ordering): BlockCholesky up to SolverSettings::block_max_nodes nodes,
// CHOLMOD's supernodal factorisation above. Reuses the symbolic analysis while the pattern id is unchanged, and
// for large systems the numeric factorisation too (SolverSettings).
class CholeskySolver {
 public:
  CholeskySolver();
  ~CholeskySolver();
  CholeskySolver(CholeskySolver&& other) noexcept;
  CholeskySolver& operator=(CholeskySolver&& other) noexcept;
  // Factorises the system's matrix. Returns false if it is not positive definite or the factorisation failed.
  bool factorize(const BlockSystem& system);
  // Solves with the last factorisation.
  VecX solve(const VecX& rhs);
  // Solves the system as `settings()` say: x = A^-1 b directly after a factorisation, or by preconditioned
  // conjugate gradients with a kept factorisation. Returns false (x undefined) if a factorisation it needed
  // failed (the matrix is not positive definite). Every step is serial and in a fixed order: the result does
  // not depend on the thread count. A conjugate-gradient solve does not prove the matrix definite; one that meets
  // a direction of non-positive curvature falls back to a factorisation, which then fails.
  bool solve_system(const BlockSystem& system, VecX& x, SolveReport& report);
  // The next solve_system factorises (the simulation asks for it at each frame's first step, so that a run
  // resumed from a frame's state takes the same solves as one that ran through).
  void refresh() { factor_current_ = false; }
  const SolverSettings& settings() const { return settings_; }
  void set_settings(const SolverSettings& settings) { settings_ = settings; }
  int analyses() const { return analyses_; }
  int factorizations() const { return factorizations_; }
  // After a failed factorisation: the matrix row (in its own order) whose pivot was not positive (row / 3 is the
  // system's dof); -1 otherwise.
  int failed_row() const { return block_ ? block_->failed_row() : llt_ ? llt_->failed_row() : -1; }
  // Whether the last analysis chose the node-block factorisation (small systems) rather than CHOLMOD's.
  bool uses_block_factorization() const { return block_ != nullptr; }

 private:
  // Lays out tril(P A P') for the pattern just analysed and where each entry of A's upper triangle goes in it.
  void prepare_permuted_layout();
  // Factorises the system's matrix in that layout; false if that failed.
  bool factorize_matrix(const BlockSystem& system);
  // Up to pcg_max_iterations of conjugate gradients preconditioned with the kept factor; false if they did not
  // reach the tolerance (or met non-positive curvature).
  bool conjugate_gradients(const BlockSystem& system, VecX& x, int& iterations);

  // Exactly one of the two holds the analysis of analysed_pattern_ (none before the first factorisation).
  std::unique_ptr<SupernodalLLT> llt_;
  std::unique_ptr<BlockCholesky> block_;
  Eigen::SparseMatrix<double> matrix_;
  // tril(P A P') in compressed columns, refilled at every factorisation through lower_place_ (indexed like the
  // values of matrix_). WHY: CHOLMOD otherwise transposes the whole matrix into this form at every call, a
  // tenth of the factorisation of a small sheet's system.
  std::vector<int> lower_start_, lower_row_, lower_place_;
  std::vector<double> lower_value_;
  uint64_t analysed_pattern_ = 0;
  bool factor_current_ = false;  // llt_ or block_ holds a factorisation of a matrix on analysed_pattern_
  SolverSettings settings_;
  int analyses_ = 0;
  int factorizations_ = 0;
};

}  // namespace arcsim
