#include "physics/wind.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "support/eigenvalues.hpp"

namespace arcsim {
namespace {

using testing::symmetric_eigenvalues;

Vec3 total_force(const WindForce& w) {
  return w.force.segment<3>(0) + w.force.segment<3>(3) + w.force.segment<3>(6);
}

// Unit-area right triangle in the xy plane, normal +z.
const Vec3 kX0(0, 0, 0), kX1(2, 0, 0), kX2(0, 1, 0);

TEST(Wind, NormalWindPushesFaceWithQuadraticPressure) {
  const Vec3 zero = Vec3::Zero();
  const double density = 1.2, speed = 3;
  const WindForce w = wind_force(kX0, kX1, kX2, zero, zero, zero, Vec3(0, 0, speed), density, 0.5);
  const Vec3 expected = density * 1.0 * speed * speed * Vec3::UnitZ();
  EXPECT_LT((total_force(w) - expected).norm(), 1e-14);
  for (int a = 0; a < 3; ++a) EXPECT_LT((w.force.segment<3>(3 * a) - expected / 3).norm(), 1e-14);
  // Reversed wind (or the face seen from behind) pushes the other way.
  const WindForce back = wind_force(kX0, kX1, kX2, zero, zero, zero, Vec3(0, 0, -speed), density, 0.5);
  EXPECT_LT((total_force(back) + expected).norm(), 1e-14);
  const WindForce flipped = wind_force(kX0, kX2, kX1, zero, zero, zero, Vec3(0, 0, speed), density, 0.5);
  EXPECT_LT((total_force(flipped) - expected).norm(), 1e-14);
}

TEST(Wind, TangentialWindGivesLinearDrag) {
  const Vec3 zero = Vec3::Zero();
  const double drag = 0.7;
  const Vec3 wind(2, -1, 0);
  const WindForce w = wind_force(kX0, kX1, kX2, zero, zero, zero, wind, 1.2, drag);
  EXPECT_LT((total_force(w) - drag * 1.0 * wind).norm(), 1e-14);
}

TEST(Wind, RelativeVelocityUsesMeanNodeVelocity) {
  const Vec3 wind(1, 2, 3);
  // Nodes moving with the air on average feel nothing.
  const WindForce still = wind_force(kX0, kX1, kX2, wind + Vec3(0.3, 0, 0), wind - Vec3(0.3, 0, 0), wind, wind,
                                     1.2, 0.5);
  EXPECT_LT(still.force.norm(), 1e-14);
  // A face moving through still air is braked.
  const Vec3 v(0.5, -0.2, 2);
  const WindForce moving = wind_force(kX0, kX1, kX2, v, v, v, Vec3::Zero(), 1.2, 0.5);
  EXPECT_LT(total_force(moving).dot(v), 0);
  const Vec3 expected = 1.2 * 1.0 * std::fabs(-2.0) * (-2.0) * Vec3::UnitZ() + 0.5 * 1.0 * Vec3(-0.5, 0.2, 0);
  EXPECT_LT((total_force(moving) - expected).norm(), 1e-14);
}

TEST(Wind, JacobianMatchesCentralDifferences) {
  std::mt19937 gen(31);
  std::uniform_real_distribution<double> uni(-1, 1);
  auto rvec = [&] { return Vec3(uni(gen), uni(gen), uni(gen)); };
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3 x0 = rvec(), x1 = rvec(), x2 = rvec();
    Vec3 v[3] = {rvec(), rvec(), rvec()};
    const Vec3 wind = 3 * rvec();
    const double density = 1 + uni(gen), drag = 1 + uni(gen);
    const WindForce w = wind_force(x0, x1, x2, v[0], v[1], v[2], wind, density, drag);
    Mat9 fd;
    const double step = 1e-6;
    for (int i = 0; i < 9; ++i) {
      Vec3 vp[3] = {v[0], v[1], v[2]}, vm[3] = {v[0], v[1], v[2]};
      vp[i / 3](i % 3) += step;
      vm[i / 3](i % 3) -= step;
      fd.col(i) = (wind_force(x0, x1, x2, vp[0], vp[1], vp[2], wind, density, drag).force -
                   wind_force(x0, x1, x2, vm[0], vm[1], vm[2], wind, density, drag).force) /
                  (2 * step);
    }
    EXPECT_LT((fd - w.jacobian).norm(), 1e-6 * w.jacobian.norm()) << "trial " << trial;
    // Drag only removes energy: the Jacobian is symmetric negative semi-definite.
    EXPECT_LT((w.jacobian - w.jacobian.transpose()).norm(), 1e-14 * w.jacobian.norm());
    const Vec9 ev = symmetric_eigenvalues<9>(w.jacobian);
    EXPECT_LE(ev.maxCoeff(), 1e-12 * w.jacobian.norm());
  }
}

// The step's energy check keeps each face's air force in this compact form instead of recomputing it; it must
// give back the very numbers wind_force gave (bit for bit), degenerate faces included.
TEST(Wind, CompactFormExpandsToTheSameForce) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> uni(-1, 1);
  auto rvec = [&] { return Vec3(uni(gen), uni(gen), uni(gen)); };
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3 x0 = rvec(), x1 = rvec(), x2 = trial % 10 == 0 ? x0 : rvec();
    const WindForce w = wind_force(x0, x1, x2, rvec(), rvec(), rvec(), 3 * rvec(), 1 + uni(gen), 1 + uni(gen));
    const WindForce back = CompactWindForce::of(w).expand();
    for (int i = 0; i < 9; ++i) {
      EXPECT_EQ(back.force[i], w.force[i]) << "trial " << trial;
      for (int j = 0; j < 9; ++j) EXPECT_EQ(back.jacobian(i, j), w.jacobian(i, j)) << "trial " << trial;
    }
  }
}

// The energy check multiplies the Jacobian without expanding it: the same bits as the 9x9 product.
TEST(Wind, CompactJacobianProductIsTheExpandedOne) {
  std::mt19937 gen(9);
  std::uniform_real_distribution<double> uni(-1, 1);
  auto rvec = [&] { return Vec3(uni(gen), uni(gen), uni(gen)); };
  for (int trial = 0; trial < 200; ++trial) {
    const WindForce w = wind_force(rvec(), rvec(), rvec(), rvec(), rvec(), rvec(), 3 * rvec(), 1 + uni(gen), 1 + uni(gen));
    const CompactWindForce c = CompactWindForce::of(w);
    Vec9 u;
    for (int i = 0; i < 9; ++i) u[i] = std::ldexp(uni(gen), static_cast<int>(gen() % 40) - 20);
    const Vec9 expected = w.jacobian * u, got = c.jacobian_times(u);
    for (int i = 0; i < 9; ++i) EXPECT_EQ(got[i], expected[i]) << "trial " << trial << " row " << i;
    EXPECT_EQ(u.dot(got), u.dot(w.jacobian * u)) << "trial " << trial;
  }
}

TEST(Wind, DegenerateFaceGetsNoForce) {
  const Vec3 v(1, 2, 3);
  for (const Vec3& x2 : {Vec3(1, 0, 0), Vec3(0, 0, 0), Vec3(5, 0, 0)}) {
    const WindForce w = wind_force(kX0, kX1, x2, v, v, v, Vec3(4, 5, 6), 1.2, 0.5);
    EXPECT_TRUE(w.force.allFinite());
    EXPECT_TRUE(w.jacobian.allFinite());
    EXPECT_EQ(w.force.norm(), 0);
    EXPECT_EQ(w.jacobian.norm(), 0);
  }
}

TEST(Wind, ZeroDensityAndDragGiveNoForce) {
  const Vec3 zero = Vec3::Zero();
  const WindForce w = wind_force(kX0, kX1, kX2, zero, zero, zero, Vec3(4, 5, 6), 0, 0);
  EXPECT_EQ(w.force.norm(), 0);
  EXPECT_EQ(w.jacobian.norm(), 0);
}

}  // namespace
}  // namespace arcsim
