// Aerodynamic force on one face (ARCSim's wind model): with v the wind velocity minus the face's mean node
// velocity, n the world unit normal, v_n = v . n (m/s) and v_t = v - v_n n,
//   face force (N) = density * A_w * |v_n| v_n n + drag * A_w * v_t,
// A_w the world area (m^2). The force is distributed 1/3 per node. `density` is the air density (kg/m^3),
// `drag` the tangential drag coefficient (kg/(m^2 s)). A face with zero world area gets no force.
#pragma once

#include "math/types.hpp"

namespace arcsim {

struct WindForce {
  Vec9 force = Vec9::Zero();     // nodal forces (N), stacked per node
  Mat9 jacobian = Mat9::Zero();  // d force / d (v0, v1, v2) (kg/s); symmetric negative semi-definite
};

// A WindForce held in 12 numbers: wind_force gives every node the same force and every 3x3 block of the
// Jacobian the same matrix, so expand() rebuilds the WindForce it was taken from exactly.
struct CompactWindForce {
  Vec3 node_force = Vec3::Zero();  // N, each node's
  Mat3 block = Mat3::Zero();       // kg/s, each block of the Jacobian
  static CompactWindForce of(const WindForce& w) {
    CompactWindForce c;
    c.node_force = w.force.segment<3>(0);
    c.block = w.jacobian.block<3, 3>(0, 0);
    return c;
  }
  WindForce expand() const {
    WindForce w;
    for (int a = 0; a < 3; ++a) {
      w.force.segment<3>(3 * a) = node_force;
      for (int b = 0; b < 3; ++b) w.jacobian.block<3, 3>(3 * a, 3 * b) = block;
    }
    return w;
  }
  // expand().jacobian * u, without the 9x9 matrix: the three block rows are equal, and each entry is the sum of
  // its nine products taken in column order, as the matrix product sums it (the same bits; the step's energy
  // check evaluates this for every face).
  Vec9 jacobian_times(const Vec9& u) const {
    Vec3 row_sums;
    for (int p = 0; p < 3; ++p) {
      double sum = 0;
      for (int j = 0; j < 9; ++j) sum += block(p, j % 3) * u[j];
      row_sums[p] = sum;
    }
    Vec9 out;
    for (int a = 0; a < 3; ++a) out.segment<3>(3 * a) = row_sums;
    return out;
  }
};

// Force on the face (x0, x1, x2) (m) with node velocities v0, v1, v2 (m/s). The Jacobian is with respect to
// the node velocities at fixed positions, so the implicit solver can treat drag implicitly.
WindForce wind_force(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& v0, const Vec3& v1,
                     const Vec3& v2, const Vec3& wind_velocity, double density, double drag);

}  // namespace arcsim
