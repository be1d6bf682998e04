#include "physics/block_cholesky.hpp"

#include <amd.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "physics/block_system.hpp"

namespace arcsim {

namespace {
using PanelBlock = Eigen::Map<Mat3, 0, Eigen::OuterStride<>>;
using ConstPanelBlock = Eigen::Map<const Mat3, 0, Eigen::OuterStride<>>;

// Two doubles as one SIMD register (GCC/Clang vector extension; SSE2 on x86-64): element-wise arithmetic, the
// same rounding as two scalar operations.
typedef double Pair __attribute__((vector_size(16)));
inline Pair load_pair(const double* p) {
  Pair v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline Pair broadcast(double x) { return Pair{x, x}; }
inline void store_pair(double* p, Pair v) { std::memcpy(p, &v, sizeof v); }
}  // namespace

void BlockCholesky::analyse(const BlockPattern& pattern) {
  const int n = pattern.node_count();
  const int blocks = pattern.block_count();
  node_count_ = n;
  failed_row_ = -1;

  // The node graph as compressed columns (the pattern's own storage: column c's blocks are consecutive, rows >= c
  // ascending, the diagonal first), for AMD, which orders A + A' and ignores the diagonal.
  std::vector<int> graph_start(n + 1), graph_row(blocks);
  for (int c = 0; c < n; ++c) graph_start[c] = pattern.diagonal_block(c);
  graph_start[n] = blocks;
  for (int k = 0; k < blocks; ++k) graph_row[k] = pattern.block_row(k);
  order_.resize(n);
  if (n > 0 && amd_order(n, graph_start.data(), graph_row.data(), order_.data(), nullptr, nullptr) < 0)
    throw std::runtime_error("AMD could not order the node graph of the implicit system");
  std::vector<int> position(n);
  for (int k = 0; k < n; ++k) position[order_[k]] = k;

  // For each permuted row i, the permuted columns j < i of its entries.
  std::vector<int> below_start(n + 1, 0), below_col;
  for (int k = 0; k < blocks; ++k) {
    const int a = position[pattern.block_row(k)], b = position[pattern.block_col(k)];
    if (a != b) ++below_start[std::max(a, b) + 1];
  }
  for (int i = 0; i < n; ++i) below_start[i + 1] += below_start[i];
  below_col.resize(below_start[n]);
  {
    std::vector<int> next(below_start.begin(), below_start.end() - 1);
    for (int k = 0; k < blocks; ++k) {
      const int a = position[pattern.block_row(k)], b = position[pattern.block_col(k)];
      if (a != b) below_col[next[std::max(a, b)]++] = std::min(a, b);
    }
  }

  // Elimination tree (Liu's algorithm with path compression).
  std::vector<int> parent(n, -1), ancestor(n, -1);
  for (int i = 0; i < n; ++i)
    for (int q = below_start[i]; q < below_start[i + 1]; ++q) {
      int r = below_col[q];
      while (ancestor[r] != -1 && ancestor[r] != i) {
        const int up = ancestor[r];
        ancestor[r] = i;
        r = up;
      }
      if (ancestor[r] == -1) {
        ancestor[r] = i;
        parent[r] = i;
      }
    }

  // Row i of L is the union of the tree paths from its entries' columns up to i: count, then list, rows per
  // column (visiting rows in ascending order keeps every column's rows sorted).
  std::vector<int> mark(n, -1), count(n, 1);
  auto walk_row = [&](int i, auto&& visit) {
    mark[i] = i;
    for (int q = below_start[i]; q < below_start[i + 1]; ++q)
      for (int k = below_col[q]; mark[k] != i; k = parent[k]) {
        mark[k] = i;
        visit(k);
      }
  };
  for (int i = 0; i < n; ++i) walk_row(i, [&](int k) { ++count[k]; });
  col_start_.assign(n + 1, 0);
  flops_ = 0;
  for (int j = 0; j < n; ++j) {
    col_start_[j + 1] = col_start_[j] + count[j];
    for (int s = 0; s < 3; ++s) flops_ += static_cast<double>(3 * count[j] - s) * (3 * count[j] - s);
  }
  row_.resize(col_start_[n]);
  std::vector<int> fill(col_start_.begin(), col_start_.end() - 1);
  for (int j = 0; j < n; ++j) row_[fill[j]++] = j;
  std::fill(mark.begin(), mark.end(), -1);
  for (int i = 0; i < n; ++i) walk_row(i, [&](int k) { row_[fill[k]++] = i; });

  // Where each block of A lands in the factor's panels.
  place_.resize(blocks);
  lead_.resize(blocks);
  transpose_.resize(blocks);
  for (int k = 0; k < blocks; ++k) {
    const int a = position[pattern.block_row(k)], b = position[pattern.block_col(k)];
    const int i = std::max(a, b), j = std::min(a, b);
    const auto first = row_.begin() + col_start_[j], last = row_.begin() + col_start_[j + 1];
    const int t = static_cast<int>(std::lower_bound(first, last, i) - first);
    place_[k] = 9 * col_start_[j] + 3 * t;
    lead_[k] = 3 * (col_start_[j + 1] - col_start_[j]);
    transpose_[k] = a < b;
  }
  std::vector<char> from_a(row_.size(), 0);
  for (int k = 0; k < blocks; ++k) {
    const int a = position[pattern.block_row(k)], b = position[pattern.block_col(k)];
    const int j = std::min(a, b);
    from_a[col_start_[j] + (place_[k] - 9 * col_start_[j]) / 3] = 1;
  }
  fill_.clear();
  fill_lead_.clear();
  for (int j = 0; j < n; ++j)
    for (int t = col_start_[j]; t < col_start_[j + 1]; ++t)
      if (!from_a[t]) {
        fill_.push_back(9 * col_start_[j] + 3 * (t - col_start_[j]));
        fill_lead_.push_back(3 * (col_start_[j + 1] - col_start_[j]));
      }
  value_.assign(9 * row_.size(), 0.0);
  where_.assign(n, 0);
  next_row_.assign(n, 0);
  list_head_.assign(n, -1);
  list_next_.assign(n, -1);
}

bool BlockCholesky::factorize(const BlockSystem& system) {
  const int n = node_count_;
  failed_row_ = -1;
  // Every block of L is either one of A's (copied whole) or fill (zeroed).
  for (size_t f = 0; f < fill_.size(); ++f) PanelBlock(&value_[fill_[f]], Eigen::OuterStride<>(fill_lead_[f])).setZero();
  for (size_t k = 0; k < place_.size(); ++k) {
    PanelBlock target(&value_[place_[k]], Eigen::OuterStride<>(lead_[k]));
    if (transpose_[k])
      target = system.blocks[k].transpose();
    else
      target = system.blocks[k];
  }
  std::fill(list_head_.begin(), list_head_.end(), -1);

  // Left-looking: column j gathers the updates of every earlier column k with a block in row j (the columns
  // linked in list_head_[j]), then is factorised. next_row_[k] is where column k's next row to visit lies in row_.
  for (int j = 0; j < n; ++j) {
    const int begin = col_start_[j], rows = col_start_[j + 1] - begin, lead = 3 * rows;
    double* panel = &value_[9 * begin];
    for (int t = 0; t < rows; ++t) where_[row_[begin + t]] = t;
    for (int k = list_head_[j]; k != -1;) {
      const int following = list_next_[k];
      const int p = next_row_[k];
      const int k_begin = col_start_[k], k_rows = col_start_[k + 1] - k_begin, k_lead = 3 * k_rows;
      const double* k_panel = &value_[9 * k_begin];
      const int local = p - k_begin;
      // W(i, j) -= L(i, k) L(j, k)' for every row i of column k from j down. Column b of the update combines
      // L(:, k)'s three columns with row b of L(j, k), contiguous in the panel.
      // Columns j and k are distinct panels: nothing written below is read through c0..c2.
      const double* __restrict c0 = k_panel;
      const double* __restrict c1 = k_panel + k_lead;
      const double* __restrict c2 = k_panel + 2 * k_lead;
      const int j_row = 3 * local;
      const int* rows_k = &row_[k_begin];
      // Row b of L(j, k), each entry in both halves of a pair.
      const Pair m00 = broadcast(c0[j_row]), m01 = broadcast(c1[j_row]), m02 = broadcast(c2[j_row]);
      const Pair m10 = broadcast(c0[j_row + 1]), m11 = broadcast(c1[j_row + 1]), m12 = broadcast(c2[j_row + 1]);
      const Pair m20 = broadcast(c0[j_row + 2]), m21 = broadcast(c1[j_row + 2]), m22 = broadcast(c2[j_row + 2]);
      for (int s = local; s < k_rows; ++s) {
        // Block L(i, k) (rows 0-1 as pairs, row 2 as scalars) times L(j, k)', subtracted from block W(i, j).
        const int q = 3 * s;
        const Pair a = load_pair(c0 + q), b = load_pair(c1 + q), c = load_pair(c2 + q);
        const double a2 = c0[q + 2], b2 = c1[q + 2], c2s = c2[q + 2];
        double* w = panel + 3 * where_[rows_k[s]];
        store_pair(w, load_pair(w) - (a * m00 + b * m01 + c * m02));
        w[2] -= a2 * m00[0] + b2 * m01[0] + c2s * m02[0];
        w += lead;
        store_pair(w, load_pair(w) - (a * m10 + b * m11 + c * m12));
        w[2] -= a2 * m10[0] + b2 * m11[0] + c2s * m12[0];
        w += lead;
        store_pair(w, load_pair(w) - (a * m20 + b * m21 + c * m22));
        w[2] -= a2 * m20[0] + b2 * m21[0] + c2s * m22[0];
      }
      if (local + 1 < k_rows) {
        next_row_[k] = p + 1;
        const int r = row_[p + 1];
        list_next_[k] = list_head_[r];
        list_head_[r] = k;
      }
      k = following;
    }

    // The diagonal block's Cholesky factor (its lower triangle is read).
    PanelBlock diagonal(panel, Eigen::OuterStride<>(lead));
    const double d0 = diagonal(0, 0);
    if (!(d0 > 0)) return failed_row_ = 3 * order_[j], false;
    const double l00 = std::sqrt(d0), l10 = diagonal(1, 0) / l00, l20 = diagonal(2, 0) / l00;
    const double d1 = diagonal(1, 1) - l10 * l10;
    if (!(d1 > 0)) return failed_row_ = 3 * order_[j] + 1, false;
    const double l11 = std::sqrt(d1), l21 = (diagonal(2, 1) - l20 * l10) / l11;
    const double d2 = diagonal(2, 2) - l20 * l20 - l21 * l21;
    if (!(d2 > 0)) return failed_row_ = 3 * order_[j] + 2, false;
    const double l22 = std::sqrt(d2);
    diagonal << l00, 0, 0, l10, l11, 0, l20, l21, l22;

    // The blocks below: X L_jj' = W, row by row.
    for (int r = 3; r < lead; ++r) {
      double& x0 = panel[r];
      double& x1 = panel[r + lead];
      double& x2 = panel[r + 2 * lead];
      x0 /= l00;
      x1 = (x1 - l10 * x0) / l11;
      x2 = (x2 - l20 * x0 - l21 * x1) / l22;
    }
    if (rows > 1) {
      next_row_[j] = begin + 1;
      const int r = row_[begin + 1];
      list_next_[j] = list_head_[r];
      list_head_[r] = j;
    }
  }
  return true;
}

VecX BlockCholesky::solve(const VecX& b) const {
  const int n = node_count_;
  VecX y(3 * n);
  for (int j = 0; j < n; ++j) y.segment<3>(3 * j) = b.segment<3>(3 * order_[j]);
  // L y' = y, then L' x = y'.
  for (int j = 0; j < n; ++j) {
    const int begin = col_start_[j], lead = 3 * (col_start_[j + 1] - begin);
    const double* panel = &value_[9 * begin];
    const Vec3 yj = ConstPanelBlock(panel, Eigen::OuterStride<>(lead))
                        .triangularView<Eigen::Lower>()
                        .solve(Vec3(y.segment<3>(3 * j)));
    y.segment<3>(3 * j) = yj;
    for (int t = 1; t < col_start_[j + 1] - begin; ++t)
      y.segment<3>(3 * row_[begin + t]).noalias() -= ConstPanelBlock(panel + 3 * t, Eigen::OuterStride<>(lead)) * yj;
  }
  for (int j = n - 1; j >= 0; --j) {
    const int begin = col_start_[j], lead = 3 * (col_start_[j + 1] - begin);
    const double* panel = &value_[9 * begin];
    Vec3 s = y.segment<3>(3 * j);
    for (int t = 1; t < col_start_[j + 1] - begin; ++t)
      s.noalias() -= ConstPanelBlock(panel + 3 * t, Eigen::OuterStride<>(lead)).transpose() *
                     y.segment<3>(3 * row_[begin + t]);
    y.segment<3>(3 * j) =
        ConstPanelBlock(panel, Eigen::OuterStride<>(lead)).transpose().triangularView<Eigen::Upper>().solve(s);
  }
  VecX x(3 * n);
  for (int j = 0; j < n; ++j) x.segment<3>(3 * order_[j]) = y.segment<3>(3 * j);
  return x;
}

}  // namespace arcsim
