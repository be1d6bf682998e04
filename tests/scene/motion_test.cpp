// Keyframed motions: cubic Hermite interpolation of translation, scale and rotation, held outside the keys,
// C1 at keys, velocity equal to the time derivative of the pose, unit rotations taking the short way.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "scene/transform.hpp"

namespace arcsim {
namespace {

Keyframe key(double time, const Vec3& translation, double scale = 1, double degrees = 0,
             const Vec3& axis = Vec3::UnitZ()) {
  Keyframe k;
  k.time = time;
  k.transform.translation = translation;
  k.transform.scale = scale;
  k.transform.rotation = Transform::rotation_from_degrees(degrees, axis);
  return k;
}

// A motion that moves, scales and rotates about changing axes, with one given velocity.
Motion busy_motion() {
  Motion m;
  m.keys.push_back(key(0.0, Vec3(0, 0, 0), 1.0, 0, Vec3::UnitZ()));
  m.keys.push_back(key(0.5, Vec3(1, 0.2, 0), 1.5, 60, Vec3(1, 1, 0)));
  Keyframe k = key(1.5, Vec3(1, 1, -0.5), 0.8, 150, Vec3(0, 1, 1));
  k.has_velocity = true;
  k.velocity = Vec3(0.3, -0.2, 0.1);
  k.scale_rate = -0.4;
  k.angular_velocity = Vec3(0.5, 0.1, -1.0);
  m.keys.push_back(k);
  m.keys.push_back(key(2.0, Vec3(2, 1, 0), 1.0, -120, Vec3(1, 0, 0)));
  m.finalize();
  return m;
}

double rotation_distance(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b);
}

TEST(TransformTest, RotationFromDegreesNormalisesAxis) {
  const Eigen::Quaterniond q = Transform::rotation_from_degrees(90, Vec3(0, 0, 5));
  EXPECT_TRUE((q * Vec3(1, 0, 0)).isApprox(Vec3(0, 1, 0), 1e-12));
  EXPECT_NEAR(q.norm(), 1, 1e-15);
  EXPECT_TRUE(Transform::rotation_from_degrees(0, Vec3::Zero()).isApprox(Eigen::Quaterniond::Identity()));
  Transform t;
  t.translation = Vec3(1, 2, 3);
  t.scale = 2;
  t.rotation = q;
  EXPECT_TRUE(t.apply(Vec3(1, 0, 0)).isApprox(Vec3(1, 4, 3)));  // scale, rotate, then translate
  EXPECT_TRUE(t.apply_vector(Vec3(1, 0, 0)).isApprox(Vec3(0, 2, 0)));
}

TEST(MotionTest, HitsEveryKey) {
  const Motion m = busy_motion();
  for (const Keyframe& k : m.keys) {
    const Transform p = m.pose(k.time);
    EXPECT_TRUE(p.translation.isApprox(k.transform.translation, 1e-12)) << k.time;
    EXPECT_NEAR(p.scale, k.transform.scale, 1e-12);
    EXPECT_LT(rotation_distance(p.rotation, k.transform.rotation), 1e-9) << k.time;
  }
}

TEST(MotionTest, HeldOutsideTheKeysWithZeroVelocity) {
  const Motion m = busy_motion();
  const Transform before = m.pose(-3), after = m.pose(10);
  EXPECT_TRUE(before.translation.isApprox(m.keys.front().transform.translation));
  EXPECT_TRUE(after.translation.isApprox(m.keys.back().transform.translation, 1e-12));
  EXPECT_NEAR(after.scale, 1.0, 1e-12);
  EXPECT_LT(rotation_distance(after.rotation, m.keys.back().transform.rotation), 1e-9);
  EXPECT_TRUE(m.velocity(-3, Vec3(1, 2, 3)).isZero());
  EXPECT_TRUE(m.velocity(10, Vec3(1, 2, 3)).isZero());
}

TEST(MotionTest, HermiteValuesAgainstHandComputedBasis) {
  // Two keys with zero end tangents: x(s) = h01(s) = 3 s^2 - 2 s^3 of the displacement.
  Motion m;
  m.keys = {key(1, Vec3::Zero(), 1), key(3, Vec3(4, 0, 0), 3)};
  m.finalize();
  EXPECT_NEAR(m.pose(1.5).translation.x(), 4 * (3 * 0.0625 - 2 * 0.015625), 1e-12);  // s = 0.25
  EXPECT_NEAR(m.pose(2).translation.x(), 2, 1e-12);
  EXPECT_NEAR(m.pose(2).scale, 2, 1e-12);
  // dx/dt = displacement * (6 s - 6 s^2) / h at s = 0.25, h = 2.
  EXPECT_NEAR(m.rate(1.5).translation.x(), 4 * (6 * 0.25 - 6 * 0.0625) / 2, 1e-12);
  EXPECT_NEAR(m.rate(1).translation.x(), 0, 1e-12);  // zero tangent at the first key
}

TEST(MotionTest, CentralDifferenceTangentsAndGivenVelocities) {
  const Motion m = busy_motion();
  // Interior key without velocity: (p[2] - p[0]) / (t[2] - t[0]).
  const Vec3 expected = (m.keys[2].transform.translation - m.keys[0].transform.translation) / 1.5;
  EXPECT_TRUE(m.rate(0.5).translation.isApprox(expected, 1e-12));
  EXPECT_NEAR(m.rate(0.5).scale, (0.8 - 1.0) / 1.5, 1e-12);
  // Key with a given velocity: the velocity is the tangent, including the angular velocity.
  const PoseRate r = m.rate(1.5);
  EXPECT_TRUE(r.translation.isApprox(Vec3(0.3, -0.2, 0.1), 1e-12));
  EXPECT_NEAR(r.scale, -0.4, 1e-12);
  EXPECT_TRUE(r.angular.isApprox(Vec3(0.5, 0.1, -1.0), 1e-9)) << r.angular.transpose();
  // First and last keys: zero tangents.
  EXPECT_TRUE(m.rate(0).translation.isZero());
  EXPECT_TRUE(m.rate(2).translation.isZero(1e-12));
  EXPECT_TRUE(m.rate(2).angular.isZero(1e-9));
}

TEST(MotionTest, C1AtInteriorKeys) {
  const Motion m = busy_motion();
  const double eps = 1e-7;
  for (double t : {0.5, 1.5}) {
    const Transform left = m.pose(t - eps), right = m.pose(t + eps);
    EXPECT_TRUE(left.translation.isApprox(right.translation, 1e-6));
    const PoseRate a = m.rate(t - eps), b = m.rate(t + eps);
    EXPECT_LT((a.translation - b.translation).norm(), 1e-5) << t;
    EXPECT_NEAR(a.scale, b.scale, 1e-5);
    EXPECT_LT((a.angular - b.angular).norm(), 1e-5) << t;
  }
}

TEST(MotionTest, VelocityIsTheDerivativeOfThePose) {
  const Motion m = busy_motion();
  const Vec3 points[] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.3, -0.7, 0.2)};
  const double h = 1e-6;
  for (double t = 0.013; t < 2.0; t += 0.0917) {
    for (const Vec3& x : points) {
      const Vec3 numeric = (m.pose(t + h).apply(x) - m.pose(t - h).apply(x)) / (2 * h);
      const Vec3 exact = m.velocity(t, x);
      EXPECT_LT((numeric - exact).norm(), 1e-6 * (1 + exact.norm())) << "t = " << t;
    }
    const PoseRate r = m.rate(t);
    EXPECT_NEAR(r.scale, (m.pose(t + h).scale - m.pose(t - h).scale) / (2 * h), 1e-6);
  }
}

TEST(MotionTest, RotationStaysUnitAndTakesTheShortWay) {
  // 170 deg and -170 deg about z are 20 deg apart, but their quaternions have opposite signs.
  Motion m;
  m.keys = {key(0, Vec3::Zero(), 1, 170), key(1, Vec3::Zero(), 1, -170)};
  ASSERT_LT(m.keys[0].transform.rotation.coeffs().dot(m.keys[1].transform.rotation.coeffs()), 0);
  m.finalize();
  for (double t = 0; t <= 1.0; t += 0.05) {
    const Eigen::Quaterniond q = m.pose(t).rotation;
    EXPECT_NEAR(q.norm(), 1, 1e-12);
    // Stays within the 20 deg arc around 180 deg instead of sweeping through 0.
    EXPECT_LT(rotation_distance(q, Transform::rotation_from_degrees(180, Vec3::UnitZ())), 10.5 * M_PI / 180);
  }
  EXPECT_LT(rotation_distance(m.pose(0.5).rotation, Transform::rotation_from_degrees(180, Vec3::UnitZ())), 1e-9);
}

TEST(MotionTest, SingleKeyAndEmptyMotion) {
  Motion one;
  one.keys = {key(2, Vec3(1, 2, 3), 2, 45)};
  one.finalize();
  EXPECT_TRUE(one.pose(0).translation.isApprox(Vec3(1, 2, 3)));
  EXPECT_TRUE(one.pose(5).translation.isApprox(Vec3(1, 2, 3)));
  EXPECT_TRUE(one.velocity(2, Vec3(1, 0, 0)).isZero());
  Motion none;
  none.finalize();
  EXPECT_TRUE(none.pose(1).translation.isZero());
  EXPECT_DOUBLE_EQ(none.pose(1).scale, 1);
  Motion unfinished;
  unfinished.keys = {key(0, Vec3::Zero())};
  EXPECT_THROW(unfinished.pose(0), std::logic_error);
}

}  // namespace
}  // namespace arcsim
