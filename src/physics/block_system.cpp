#include "physics/block_system.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include "math/counting_sort.hpp"

namespace arcsim {

namespace {
std::atomic<uint64_t> next_pattern_id{1};

double seconds_between(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
}  // namespace

void sort_unique_pairs(std::vector<std::pair<int, int>>& pairs, int key_count) {
  counting_sort_unique(pairs, 0, static_cast<size_t>(std::max(key_count, 0)), [](const auto& p) { return p.first; });
}

void BlockPattern::build(int node_count, std::vector<std::pair<int, int>> pairs) {
  // Held as (col, row) with row >= col, so that sorting them gives column-major order: by column, then row.
  for (auto& p : pairs)
    if (p.first > p.second) std::swap(p.first, p.second);
  for (int i = 0; i < node_count; ++i) pairs.emplace_back(i, i);
  sort_unique_pairs(pairs, node_count);

  // The same structure as before (a remesh that changed nothing, contacts that came and went): keep the id, so
  // that the solver reuses its symbolic analysis.
  if (id_ != 0 && node_count == node_count_ && pairs.size() == block_row_.size()) {
    bool same = true;
    for (size_t k = 0; k < pairs.size() && same; ++k)
      same = pairs[k].first == block_col_[k] && pairs[k].second == block_row_[k];
    if (same) return;
  }
  node_count_ = node_count;

  block_row_.resize(pairs.size());
  block_col_.resize(pairs.size());
  col_start_.assign(node_count + 1, 0);
  for (size_t k = 0; k < pairs.size(); ++k) {
    block_row_[k] = pairs[k].second;
    block_col_[k] = pairs[k].first;
    ++col_start_[pairs[k].first + 1];
  }
  for (int c = 0; c < node_count; ++c) col_start_[c + 1] += col_start_[c];

  layout_ready_ = false;
  id_ = next_pattern_id++;
}

void BlockPattern::prepare_layout() const {
  if (layout_ready_) return;
  // Scalar CSC of the upper triangle (CHOLMOD transposes a lower one twice before factorising it, an upper one
  // once). Block k, stored as (row R, column C) with R >= C, appears there transposed at (C, R): scalar column
  // 3R+b holds, for each block of node row R in column order, rows 3C..3C+2 (or 3R..3R+b for the diagonal block,
  // which comes last).
  const int node_count = node_count_;
  const int n = 3 * node_count;
  std::vector<int> row_start(node_count + 1, 0);
  for (int r : block_row_) ++row_start[r + 1];
  for (int r = 0; r < node_count; ++r) row_start[r + 1] += row_start[r];
  std::vector<int> row_blocks(block_row_.size());
  {
    std::vector<int> next(row_start.begin(), row_start.end() - 1);
    for (size_t k = 0; k < block_row_.size(); ++k) row_blocks[next[block_row_[k]]++] = static_cast<int>(k);
  }
  std::vector<int> outer(n + 1, 0);
  for (int r = 0; r < node_count; ++r) {
    const int blocks_in_row = row_start[r + 1] - row_start[r];  // includes the diagonal block
    for (int b = 0; b < 3; ++b) outer[3 * r + b + 1] = 3 * (blocks_in_row - 1) + (b + 1);
  }
  for (int j = 0; j < n; ++j) outer[j + 1] += outer[j];
  const int nnz = outer[n];
  std::vector<int> inner(nnz);
  value_offset_.assign(3 * block_row_.size(), 0);
  for (int r = 0; r < node_count; ++r) {
    for (int b = 0; b < 3; ++b) {
      int pos = outer[3 * r + b];
      for (int i = row_start[r]; i < row_start[r + 1]; ++i) {
        const int k = row_blocks[i], c = block_col_[k];
        value_offset_[3 * k + b] = pos;
        const int last = (c == r) ? b : 2;
        for (int a = 0; a <= last; ++a) inner[pos++] = 3 * c + a;
      }
    }
  }
  csc_.resize(n, n);
  csc_.resizeNonZeros(nnz);
  std::copy(outer.begin(), outer.end(), csc_.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), csc_.innerIndexPtr());
  std::fill(csc_.valuePtr(), csc_.valuePtr() + nnz, 0.0);
  layout_ready_ = true;
}

int BlockPattern::block_index(int i, int j) const {
  if (i < j) std::swap(i, j);
  const auto begin = block_row_.begin() + col_start_[j], end = block_row_.begin() + col_start_[j + 1];
  const auto it = std::lower_bound(begin, end, i);
  return (it != end && *it == i) ? static_cast<int>(it - block_row_.begin()) : -1;
}

void BlockSystem::reset(const BlockPattern& p) {
  pattern = &p;
  blocks.assign(p.block_count(), Mat3::Zero());
  rhs = VecX::Zero(3 * p.node_count());
}

VecX BlockSystem::multiply(const VecX& x) const {
  VecX y = VecX::Zero(x.size());
  for (int k = 0; k < pattern->block_count(); ++k) {
    const int r = pattern->block_row(k), c = pattern->block_col(k);
    y.segment<3>(3 * r) += blocks[k] * x.segment<3>(3 * c);
    if (r != c) y.segment<3>(3 * c) += blocks[k].transpose() * x.segment<3>(3 * r);
  }
  return y;
}

void BlockSystem::to_csc(Eigen::SparseMatrix<double>& out) const {
  pattern->prepare_layout();
  if (out.rows() != pattern->csc_structure().rows() || out.nonZeros() != pattern->csc_structure().nonZeros())
    out = pattern->csc_structure();
  double* values = out.valuePtr();
  for (int k = 0; k < pattern->block_count(); ++k) {
    const bool diagonal = pattern->block_row(k) == pattern->block_col(k);
    for (int b = 0; b < 3; ++b) {
      const int offset = pattern->block_value_offset(k, b);
      const int last = diagonal ? b : 2;
      for (int a = 0; a <= last; ++a) values[offset + a] = blocks[k](b, a);
    }
  }
}

void BlockSystem::scatter_upper(const std::vector<int>& place, double* out) const {
  for (int k = 0; k < pattern->block_count(); ++k) {
    const bool diagonal = pattern->block_row(k) == pattern->block_col(k);
    for (int b = 0; b < 3; ++b) {
      const int offset = pattern->block_value_offset(k, b);
      const int last = diagonal ? b : 2;
      for (int a = 0; a <= last; ++a) out[place[offset + a]] = blocks[k](b, a);
    }
  }
}

const int* SupernodalLLT::permutation() const {
  return m_cholmodFactor ? static_cast<const int*>(m_cholmodFactor->Perm) : nullptr;
}

void SupernodalLLT::factorize_permuted_lower(cholmod_sparse& lower) {
  // As Eigen's factorize does, minus the transpose cholmod_factorize_p would make of an upper matrix.
  cholmod_common& common = cholmod();
  common.status = CHOLMOD_OK;
  cholmod_super_numeric(&lower, nullptr, m_shiftOffset, m_cholmodFactor, &common);
  m_info = m_cholmodFactor->minor == m_cholmodFactor->n ? Eigen::Success : Eigen::NumericalIssue;
  m_factorizationIsOk = true;
}

int SupernodalLLT::failed_row() const {
  const cholmod_factor* L = m_cholmodFactor;
  if (!L || L->minor >= L->n) return -1;
  // minor is the column of the permuted matrix whose pivot failed; Perm maps it back.
  const int* perm = static_cast<const int*>(L->Perm);
  return static_cast<int>(perm ? perm[L->minor] : L->minor);
}

CholeskySolver::CholeskySolver() = default;
CholeskySolver::~CholeskySolver() = default;

CholeskySolver::CholeskySolver(CholeskySolver&& other) noexcept { *this = std::move(other); }

CholeskySolver& CholeskySolver::operator=(CholeskySolver&& other) noexcept {
  llt_ = std::move(other.llt_);
  block_ = std::move(other.block_);
  matrix_.swap(other.matrix_);
  lower_start_.swap(other.lower_start_);
  lower_row_.swap(other.lower_row_);
  lower_place_.swap(other.lower_place_);
  lower_value_.swap(other.lower_value_);
  analysed_pattern_ = other.analysed_pattern_;
  factor_current_ = other.factor_current_;
  settings_ = other.settings_;
  analyses_ = other.analyses_;
  factorizations_ = other.factorizations_;
  other.analysed_pattern_ = 0;
  other.factor_current_ = false;
  return *this;
}

bool CholeskySolver::factorize(const BlockSystem& system) {
  const uint64_t id = system.pattern->id();
  if (system.pattern->node_count() <= settings_.block_max_nodes) {
    if (!block_ || analysed_pattern_ != id) {
      llt_.reset();
      block_ = std::make_unique<BlockCholesky>();
      block_->analyse(*system.pattern);
      analysed_pattern_ = id;
      ++analyses_;
    }
    ++factorizations_;
    factor_current_ = block_->factorize(system);
    return factor_current_;
  }
  system.pattern->prepare_layout();
  if (!llt_ || analysed_pattern_ != id) {
    block_.reset();
    matrix_ = system.pattern->csc_structure();
    system.to_csc(matrix_);
    llt_ = std::make_unique<SupernodalLLT>();
    // AMD only. CHOLMOD's default also tries METIS when AMD's fill is high (from ~20k faces on), and keeps the
    // ordering with the smaller factor: on our sheets METIS's was never smaller (64k faces: 3.15e7 against
    // AMD's 3.10e7 entries, the same flops), but trying it took 60% of the analysis (1.3 s against 0.54 s),
    // paid again at every remesh. Below that size CHOLMOD tries AMD alone anyway: the same factor as before.
    cholmod_common& common = llt_->cholmod();
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_AMD;
    llt_->analyzePattern(matrix_);
    analysed_pattern_ = id;
    ++analyses_;
    prepare_permuted_layout();
  }
  return factorize_matrix(system);
}

void CholeskySolver::prepare_permuted_layout() {
  const int n = static_cast<int>(matrix_.rows());
  const int* perm = llt_->permutation();
  std::vector<int> inverse(n);
  for (int k = 0; k < n; ++k) inverse[perm ? perm[k] : k] = k;
  // Entry (i, j) of A's upper triangle is entry (max, min) of P A P''s lower one. Two counting passes, by row
  // and then (stably) by column, leave each column's entries in ascending row order, as CHOLMOD's transpose
  // yields them (sorting each column took as long as CHOLMOD's AMD ordering in flag.json).
  const int nnz = static_cast<int>(matrix_.nonZeros());
  const int* outer = matrix_.outerIndexPtr();
  const int* inner = matrix_.innerIndexPtr();
  std::vector<int> target_row(nnz), target_col(nnz);  // permuted row and column per value index
  std::vector<int> row_start(n + 1, 0);
  lower_start_.assign(n + 1, 0);
  for (int j = 0; j < n; ++j)
    for (int q = outer[j]; q < outer[j + 1]; ++q) {
      const int a = inverse[inner[q]], b = inverse[j];
      target_row[q] = std::max(a, b);
      target_col[q] = std::min(a, b);
      ++row_start[target_row[q] + 1];
      ++lower_start_[target_col[q] + 1];
    }
  for (int c = 0; c < n; ++c) {
    row_start[c + 1] += row_start[c];
    lower_start_[c + 1] += lower_start_[c];
  }
  std::vector<int> by_row(nnz);
  for (int q = 0; q < nnz; ++q) by_row[row_start[target_row[q]]++] = q;
  lower_row_.resize(nnz);
  lower_place_.resize(nnz);
  lower_value_.assign(nnz, 0.0);
  std::vector<int> next(lower_start_.begin(), lower_start_.end() - 1);
  for (int q : by_row) {
    const int pos = next[target_col[q]]++;
    lower_row_[pos] = target_row[q];
    lower_place_[q] = pos;
  }
}

bool CholeskySolver::factorize_matrix(const BlockSystem& system) {
  system.scatter_upper(lower_place_, lower_value_.data());
  cholmod_sparse lower{};
  lower.nrow = lower.ncol = lower_start_.size() - 1;
  lower.nzmax = lower_value_.size();
  lower.p = lower_start_.data();
  lower.i = lower_row_.data();
  lower.x = lower_value_.data();
  lower.stype = -1;
  lower.itype = CHOLMOD_INT;
  lower.xtype = CHOLMOD_REAL;
  lower.dtype = CHOLMOD_DOUBLE;
  lower.sorted = 1;
  lower.packed = 1;
  // CHOLMOD's supernodal numeric phase opens an OpenMP team of a compiled-in size (4 threads in Debian's build)
  // for every supernode, whatever the machine or --threads; its parallel part only copies entries into distinct
  // places (the arithmetic is in the serial BLAS). On 2 cores those teams oversubscribed and their barriers cost
  // more than the factorisation (sphere.json to 1.2 s: 7.3 s -> 4.8 s with dynamic teams), and dynamic teams
  // still cost a load-average query, an affinity query and a futex per supernode (~420 per step of
  // paper-tearing.json, 145 000 system calls in its first 200 steps). With no active parallel level allowed,
  // every such region runs on the calling thread at once. The factor does not depend on the team size.
  const int levels_before = omp_get_max_active_levels();
  omp_set_max_active_levels(0);
  llt_->factorize_permuted_lower(lower);
  omp_set_max_active_levels(levels_before);
  ++factorizations_;
  factor_current_ = llt_->info() == Eigen::Success;
  return factor_current_;
}

VecX CholeskySolver::solve(const VecX& rhs) { return block_ ? block_->solve(rhs) : VecX(llt_->solve(rhs)); }

bool CholeskySolver::conjugate_gradients(const BlockSystem& system, VecX& x, int& iterations) {
  // Preconditioned conjugate gradients (the textbook recurrence), x_0 = 0, so that its first iterate is the
  // kept factor's direct solve, scaled. Serial Eigen reductions: the same sums whatever the thread count.
  const VecX& b = system.rhs;
  const double target = settings_.pcg_tolerance * b.norm();
  x = VecX::Zero(b.size());
  VecX r = b;
  if (r.norm() <= target) return true;
  VecX z = solve(r);
  VecX p = z;
  double rz = r.dot(z);
  for (iterations = 1; iterations <= settings_.pcg_max_iterations; ++iterations) {
    const VecX Ap = system.multiply(p);
    const double curvature = p.dot(Ap);
    if (!(curvature > 0) || !(rz > 0)) return false;
    const double alpha = rz / curvature;
    x += alpha * p;
    r -= alpha * Ap;
    if (r.norm() <= target) return x.allFinite();
    if (iterations == settings_.pcg_max_iterations) break;
    z = solve(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return false;
}

bool CholeskySolver::solve_system(const BlockSystem& system, VecX& x, SolveReport& report) {
  report = SolveReport();
  const bool iterative = system.pattern->node_count() >= settings_.pcg_min_nodes;
  bool solved = false;
  auto t0 = std::chrono::steady_clock::now();
  // Any definite preconditioner of the right size serves, whatever its pattern: a kept factorisation also serves
  // after contacts came or went (flag.json changes its pattern every third step so), the iteration deciding
  // whether it is still close enough.
  const long factor_rows = block_ ? 3L * block_->node_count() : llt_ ? static_cast<long>(llt_->rows()) : -1;
  if (iterative && factor_current_ && factor_rows == system.rhs.size())
    solved = conjugate_gradients(system, x, report.iterations);
  if (!solved) {
    const auto t1 = std::chrono::steady_clock::now();
    report.solve_seconds += seconds_between(t0, t1);
    report.factorized = true;
    if (!factorize(system)) return false;
    t0 = std::chrono::steady_clock::now();
    report.factor_seconds = seconds_between(t1, t0);
    x = solve(system.rhs);
  }
  report.solve_seconds += seconds_between(t0, std::chrono::steady_clock::now());
  const double b_norm = system.rhs.norm();
  report.residual = b_norm > 0 ? (system.multiply(x) - system.rhs).norm() / b_norm : 0.0;
  return true;
}

}  // namespace arcsim
