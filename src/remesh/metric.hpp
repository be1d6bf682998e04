// Operations on 2x2 symmetric sizing metrics (1/m^2): an edge of rest-space vector e is short enough when
// e^T M e <= 1 (paper §5.1). Metrics live in a face's 2D rest frame (Face::rest_frame columns t1, t2).
#pragma once

#include <vector>

#include "math/types.hpp"

namespace arcsim {

// The smallest-trace metric that is >= every input in the Loewner order (M - M_i positive semi-definite for all
// i), i.e. whose unit ball lies inside every input's: the "tensor max" of Narain et al. 2012. Writing
// M = m I + [[p, q], [q, -p]], M >= M_i exactly when m - m_i >= |(p, q) - (p_i, q_i)|, so the answer is the
// smallest circle enclosing the circles of centre (p_i, q_i) and radius m_i; it is found exactly by trying the
// circles supported by one, two or three inputs. Returns zero for an empty list.
Mat2 metric_max(const std::vector<Mat2>& metrics);

// Symmetric eigen-decomposition helpers: the positive part (negative eigenvalues set to 0) and a function of
// the eigenvalues.
Mat2 metric_positive_part(const Mat2& M);
Mat2 metric_sqrt(const Mat2& M);  // of the positive part
// sign(l) sqrt(|l|) on each eigenvalue l: a negative eigenvalue stays negative, so a sum it enters can cancel.
Mat2 metric_signed_sqrt(const Mat2& M);

// Clamps the eigenvalues of M to [1/size_max^2, 1/size_min^2], then raises the smaller to at least
// aspect_min^2 times the larger (limits anisotropy). Bounds that are not finite and positive are ignored.
Mat2 clamp_metric(const Mat2& M, double size_min, double size_max, double aspect_min);

// Eigenvalues (ascending) of a symmetric 2x2 matrix.
Vec2 metric_eigenvalues(const Mat2& M);

}  // namespace arcsim
