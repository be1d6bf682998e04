// Sparse Cholesky factorisation over 3x3 node blocks, for small systems.
//
// CHOLMOD's supernodal factorisation is the right tool from a few hundred nodes on. Below that its supernodes are
// a handful of columns wide and its cost is overhead: a BLAS call and an OpenMP region per supernode, for a factor
// of ~10^5 entries. square.json's ~90-node system (267 unknowns, 5.4e5 flops) took 1.4e6 instructions per
// factorisation there. A sheet's system is made of 3x3 blocks per node pair, so this factorisation works on the
// node graph: an AMD ordering of the nodes, the node elimination tree, and a left-looking numeric phase whose
// unit of work is a 3x3 block product, with no per-column dispatch.
#pragma once

#include <vector>

#include "math/types.hpp"

namespace arcsim {

class BlockPattern;
struct BlockSystem;

class BlockCholesky {
 public:
  // The numeric phase's inner kernels: AVX2 with fused multiply-adds where the CPU has them (x86-64), else plain
  // C++. Both are exact to round-off; they round differently, and a machine always takes the same one.
  enum class Kernel { kFastest, kGeneric };
  explicit BlockCholesky(Kernel kernel = Kernel::kFastest) : kernel_(kernel) {}

  // Symbolic phase for a pattern: ordering, elimination tree and the block pattern of the factor. Valid for every
  // system on a pattern of the same id.
  void analyse(const BlockPattern& pattern);
  // Numeric phase: P A P' = L L' with L block lower triangular (3x3 lower-triangular diagonal blocks). Returns
  // false if a pivot was not positive (the matrix is not positive definite); failed_row() then names it.
  bool factorize(const BlockSystem& system);
  // x = A^-1 b with the last successful factorisation.
  VecX solve(const VecX& b) const;
  // The row of A (its own order) whose pivot was not positive in the last factorize; -1 if it succeeded.
  int failed_row() const { return failed_row_; }
  int node_count() const { return node_count_; }
  // Scalar entries of the factor (block entries x 9, diagonal blocks counted whole), and the flops of one
  // numeric phase: what the analysis decided, for tests and benchmarks.
  long factor_entries() const { return 9L * static_cast<long>(row_.size()); }
  // Whether the numeric phase uses the AVX2/FMA kernels (kFastest on a CPU that has them).
  bool uses_avx2() const { return avx2_; }
  double factor_flops() const { return flops_; }

 private:
  int node_count_ = 0;
  std::vector<int> order_;        // permuted position k holds node order_[k]
  // Column j of L (permuted numbering): block rows row_[col_start_[j]] = j < ... (ascending), stored as a
  // column-major panel of 4 * rows x 3 doubles at value_[12 * col_start_[j]], each block's fourth row zero.
  std::vector<int> col_start_, row_;
  // Where A's blocks go: block k of the pattern is added at value_[place_[k]] (column-major, leading dimension
  // lead_[k]), transposed when its permuted row lies above its permuted column.
  std::vector<int> place_, lead_;
  std::vector<char> transpose_;
  // Blocks of L that no block of A lands on (fill-in): offset in value_ and leading dimension, zeroed first.
  std::vector<int> fill_, fill_lead_;
  std::vector<double> value_;
  double flops_ = 0;
  int failed_row_ = -1;
  Kernel kernel_;
  bool avx2_ = false;  // the kernels in use: AVX2 with FMA
  // Scratch of the numeric phase, kept to avoid allocating per factorisation.
  std::vector<int> where_, next_row_, list_head_, list_next_;
};

}  // namespace arcsim
