#include "physics/block_cholesky.hpp"

#include <amd.h>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <stdexcept>

#include "physics/block_system.hpp"

namespace arcsim {

namespace {
using PanelBlock = Eigen::Map<Mat3, 0, Eigen::OuterStride<>>;
using ConstPanelBlock = Eigen::Map<const Mat3, 0, Eigen::OuterStride<>>;

// A block row of a panel is padded to four rows (the fourth always zero), so that the update's unit, one column of
// a 3x3 block, is one 4-wide vector.
constexpr int kRows = 4;

// The update of column j by column k (left-looking): W(i, j) -= L(i, k) L(j, k)' for the rows i of column k from
// position `from` to `to`. `k_panel` is column k's panel (leading dimension k_lead), `m` L(j, k) row by row; the
// block row of column j's `panel` (leading dimension `lead`) that row s of column k updates is where[rows_k[s]].
struct ColumnUpdate {
  const double* k_panel;
  int k_lead;
  int from, to;
  const int* rows_k;
  const int* where;
  double* panel;
  int lead;
};

void update_column_generic(const ColumnUpdate& u, const double (&m)[9]) {
  const double* c0 = u.k_panel;
  const double* c1 = u.k_panel + u.k_lead;
  const double* c2 = u.k_panel + 2 * u.k_lead;
  const int* const rows_k = u.rows_k;
  const int* const where = u.where;
  double* const panel = u.panel;
  const int lead = u.lead;
  for (int s = u.from; s < u.to; ++s) {
    const int q = kRows * s;
    double* w = panel + kRows * where[rows_k[s]];
    for (int b = 0; b < 3; ++b, w += lead)
      for (int a = 0; a < 3; ++a) w[a] -= c0[q + a] * m[3 * b] + c1[q + a] * m[3 * b + 1] + c2[q + a] * m[3 * b + 2];
  }
}

// A diagonal block's Cholesky factor: the reciprocals of its diagonal and its entries below the diagonal.
struct DiagonalFactor {
  double inverse0, inverse1, inverse2, l10, l20, l21;
};

// The blocks of a panel below its diagonal block, W, become X with X L_jj' = W (forward substitution by columns).
void divide_below_generic(double* panel, int lead, const DiagonalFactor& d) {
  for (int r = kRows; r < lead; r += kRows)
    for (int a = 0; a < 3; ++a) {
      double& x0 = panel[r + a];
      double& x1 = panel[r + a + lead];
      double& x2 = panel[r + a + 2 * lead];
      x0 *= d.inverse0;
      x1 = (x1 - d.l10 * x0) * d.inverse1;
      x2 = (x2 - d.l20 * x0 - d.l21 * x1) * d.inverse2;
    }
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2,fma"))) void divide_below_avx2(double* panel, int lead, const DiagonalFactor& d) {
  const __m256d inverse0 = _mm256_set1_pd(d.inverse0), inverse1 = _mm256_set1_pd(d.inverse1),
                inverse2 = _mm256_set1_pd(d.inverse2);
  const __m256d l10 = _mm256_set1_pd(d.l10), l20 = _mm256_set1_pd(d.l20), l21 = _mm256_set1_pd(d.l21);
  for (int r = kRows; r < lead; r += kRows) {
    const __m256d x0 = _mm256_mul_pd(_mm256_loadu_pd(panel + r), inverse0);
    const __m256d x1 = _mm256_mul_pd(_mm256_fnmadd_pd(l10, x0, _mm256_loadu_pd(panel + r + lead)), inverse1);
    const __m256d w2 = _mm256_fnmadd_pd(l20, x0, _mm256_loadu_pd(panel + r + 2 * lead));
    _mm256_storeu_pd(panel + r, x0);
    _mm256_storeu_pd(panel + r + lead, x1);
    _mm256_storeu_pd(panel + r + 2 * lead, _mm256_mul_pd(_mm256_fnmadd_pd(l21, x1, w2), inverse2));
  }
}

// The update with one AVX2 vector per block column and fused multiply-adds (so other rounding than the generic
// kernel's: a machine uses one kernel for all its runs, so its results stay bit-identical).
__attribute__((target("avx2,fma"))) void update_column_avx2(const ColumnUpdate& u, const double (&m)[9]) {
  const double* c0 = u.k_panel;
  const double* c1 = u.k_panel + u.k_lead;
  const double* c2 = u.k_panel + 2 * u.k_lead;
  const __m256d m00 = _mm256_set1_pd(m[0]), m01 = _mm256_set1_pd(m[1]), m02 = _mm256_set1_pd(m[2]);
  const __m256d m10 = _mm256_set1_pd(m[3]), m11 = _mm256_set1_pd(m[4]), m12 = _mm256_set1_pd(m[5]);
  const __m256d m20 = _mm256_set1_pd(m[6]), m21 = _mm256_set1_pd(m[7]), m22 = _mm256_set1_pd(m[8]);
  // In locals: the stores below could otherwise alias u's fields, which would then be reloaded every row.
  const int* const rows_k = u.rows_k;
  const int* const where = u.where;
  double* const panel = u.panel;
  const int lead = u.lead;
  for (int s = u.from; s < u.to; ++s) {
    const int q = kRows * s;
    const __m256d a = _mm256_loadu_pd(c0 + q), b = _mm256_loadu_pd(c1 + q), c = _mm256_loadu_pd(c2 + q);
    double* w = panel + kRows * where[rows_k[s]];
    __m256d x = _mm256_loadu_pd(w);
    x = _mm256_fnmadd_pd(a, m00, x);
    x = _mm256_fnmadd_pd(b, m01, x);
    _mm256_storeu_pd(w, _mm256_fnmadd_pd(c, m02, x));
    w += lead;
    x = _mm256_loadu_pd(w);
    x = _mm256_fnmadd_pd(a, m10, x);
    x = _mm256_fnmadd_pd(b, m11, x);
    _mm256_storeu_pd(w, _mm256_fnmadd_pd(c, m12, x));
    w += lead;
    x = _mm256_loadu_pd(w);
    x = _mm256_fnmadd_pd(a, m20, x);
    x = _mm256_fnmadd_pd(b, m21, x);
    _mm256_storeu_pd(w, _mm256_fnmadd_pd(c, m22, x));
  }
}

bool cpu_has_avx2_fma() { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }
#else
void update_column_avx2(const ColumnUpdate& u, const double (&m)[9]) { update_column_generic(u, m); }
void divide_below_avx2(double* panel, int lead, const DiagonalFactor& d) { divide_below_generic(panel, lead, d); }
bool cpu_has_avx2_fma() { return false; }
#endif

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
    place_[k] = 3 * kRows * col_start_[j] + kRows * t;
    lead_[k] = kRows * (col_start_[j + 1] - col_start_[j]);
    transpose_[k] = a < b;
  }
  std::vector<char> from_a(row_.size(), 0);
  for (int k = 0; k < blocks; ++k) {
    const int a = position[pattern.block_row(k)], b = position[pattern.block_col(k)];
    const int j = std::min(a, b);
    from_a[col_start_[j] + (place_[k] - 3 * kRows * col_start_[j]) / kRows] = 1;
  }
  fill_.clear();
  fill_lead_.clear();
  for (int j = 0; j < n; ++j)
    for (int t = col_start_[j]; t < col_start_[j + 1]; ++t)
      if (!from_a[t]) {
        fill_.push_back(3 * kRows * col_start_[j] + kRows * (t - col_start_[j]));
        fill_lead_.push_back(kRows * (col_start_[j + 1] - col_start_[j]));
      }
  value_.assign(3 * kRows * row_.size(), 0.0);
  avx2_ = kernel_ == Kernel::kFastest && cpu_has_avx2_fma();
  where_.assign(n, 0);
  next_row_.assign(n, 0);
  list_head_.assign(n, -1);
  list_next_.assign(n, -1);
}

bool BlockCholesky::factorize(const BlockSystem& system) {
  const int n = node_count_;
  // A failed factorisation may have left non-finite values in the padding rows, which nothing else rewrites.
  if (failed_row_ >= 0) std::fill(value_.begin(), value_.end(), 0.0);
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
    const int begin = col_start_[j], rows = col_start_[j + 1] - begin, lead = kRows * rows;
    double* panel = &value_[3 * kRows * begin];
    for (int t = 0; t < rows; ++t) where_[row_[begin + t]] = t;
    for (int k = list_head_[j]; k != -1;) {
      const int following = list_next_[k];
      const int p = next_row_[k];
      const int k_begin = col_start_[k], k_rows = col_start_[k + 1] - k_begin, k_lead = kRows * k_rows;
      const double* k_panel = &value_[3 * kRows * k_begin];
      const int local = p - k_begin;
      const double* j_row = k_panel + kRows * local;
      const double m[9] = {j_row[0], j_row[k_lead], j_row[2 * k_lead],
                           j_row[1], j_row[1 + k_lead], j_row[1 + 2 * k_lead],
                           j_row[2], j_row[2 + k_lead], j_row[2 + 2 * k_lead]};
      const ColumnUpdate update{k_panel, k_lead, local, k_rows, &row_[k_begin], where_.data(), panel, lead};
      if (avx2_)
        update_column_avx2(update, m);
      else
        update_column_generic(update, m);
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

    // The blocks below: X L_jj' = W.
    const DiagonalFactor factor{1 / l00, 1 / l11, 1 / l22, l10, l20, l21};
    if (avx2_)
      divide_below_avx2(panel, lead, factor);
    else
      divide_below_generic(panel, lead, factor);
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
    const int begin = col_start_[j], lead = kRows * (col_start_[j + 1] - begin);
    const double* panel = &value_[3 * kRows * begin];
    const Vec3 yj = ConstPanelBlock(panel, Eigen::OuterStride<>(lead))
                        .triangularView<Eigen::Lower>()
                        .solve(Vec3(y.segment<3>(3 * j)));
    y.segment<3>(3 * j) = yj;
    for (int t = 1; t < col_start_[j + 1] - begin; ++t)
      y.segment<3>(3 * row_[begin + t]).noalias() -=
          ConstPanelBlock(panel + kRows * t, Eigen::OuterStride<>(lead)) * yj;
  }
  for (int j = n - 1; j >= 0; --j) {
    const int begin = col_start_[j], lead = kRows * (col_start_[j + 1] - begin);
    const double* panel = &value_[3 * kRows * begin];
    Vec3 s = y.segment<3>(3 * j);
    for (int t = 1; t < col_start_[j + 1] - begin; ++t)
      s.noalias() -= ConstPanelBlock(panel + kRows * t, Eigen::OuterStride<>(lead)).transpose() *
                     y.segment<3>(3 * row_[begin + t]);
    y.segment<3>(3 * j) =
        ConstPanelBlock(panel, Eigen::OuterStride<>(lead)).transpose().triangularView<Eigen::Upper>().solve(s);
  }
  VecX x(3 * n);
  for (int j = 0; j < n; ++j) x.segment<3>(3 * order_[j]) = y.segment<3>(3 * j);
  return x;
}

}  // namespace arcsim
