// Eigenvalues of small symmetric matrices for the positive-semidefiniteness checks of Hessians.
#pragma once

#include <Eigen/Dense>

namespace arcsim::testing {

// Eigenvalues of a symmetric matrix by cyclic Jacobi rotations (Eigen's SelfAdjointEigenSolver on fixed-size
// matrices trips a GCC 12 -Wmaybe-uninitialized false positive at -O2).
template <int N>
Eigen::Matrix<double, N, 1> symmetric_eigenvalues(Eigen::Matrix<double, N, N> A) {
  for (int sweep = 0; sweep < 100; ++sweep) {
    if (A.squaredNorm() - A.diagonal().squaredNorm() <= 1e-32 * A.squaredNorm()) break;
    for (int p = 0; p < N; ++p)
      for (int q = p + 1; q < N; ++q) {
        Eigen::JacobiRotation<double> J;
        if (!J.makeJacobi(A, p, q)) continue;
        A.applyOnTheLeft(p, q, J.adjoint());
        A.applyOnTheRight(p, q, J);
      }
  }
  return A.diagonal();
}

}  // namespace arcsim::testing
