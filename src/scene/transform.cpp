#include "scene/transform.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace arcsim {

Eigen::Quaterniond Transform::rotation_from_degrees(double degrees, const Vec3& axis) {
  const double length = axis.norm();
  if (!(length > 0) || !std::isfinite(length) || !std::isfinite(degrees)) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * M_PI / 180, axis / length));
}

namespace {

// Cubic Hermite basis on s in [0, 1] and its derivative with respect to s.
struct HermiteBasis {
  double h00, h10, h01, h11;      // value weights: p0, h*m0, p1, h*m1
  double d00, d10, d01, d11;      // d/ds of the above
  explicit HermiteBasis(double s) {
    const double s2 = s * s, s3 = s2 * s;
    h00 = 2 * s3 - 3 * s2 + 1;
    h10 = s3 - 2 * s2 + s;
    h01 = -2 * s3 + 3 * s2;
    h11 = s3 - s2;
    d00 = 6 * s2 - 6 * s;
    d10 = 3 * s2 - 4 * s + 1;
    d01 = -6 * s2 + 6 * s;
    d11 = 3 * s2 - 2 * s;
  }
  // Value and time derivative of the curve through p0 (tangent m0) and p1 (tangent m1) over an interval of
  // length h seconds. Works for scalars and Eigen vectors alike.
  template <typename T>
  T value(const T& p0, const T& m0, const T& p1, const T& m1, double h) const {
    return h00 * p0 + (h10 * h) * m0 + h01 * p1 + (h11 * h) * m1;
  }
  template <typename T>
  T derivative(const T& p0, const T& m0, const T& p1, const T& m1, double h) const {
    return (d00 / h) * p0 + d10 * m0 + (d01 / h) * p1 + d11 * m1;
  }
};

Eigen::Quaterniond quat_from_coeffs(const Eigen::Vector4d& c) { return Eigen::Quaterniond(c[3], c[0], c[1], c[2]); }

}  // namespace

void Motion::finalize() {
  const size_t n = keys.size();
  quats_.assign(n, Eigen::Vector4d(0, 0, 0, 1));
  for (size_t i = 0; i < n; ++i) {
    Eigen::Vector4d c = keys[i].transform.rotation.normalized().coeffs();
    // q and -q are the same rotation; pick the sign nearer the previous key so the spline takes the short way.
    if (i > 0 && c.dot(quats_[i - 1]) < 0) c = -c;
    quats_[i] = c;
  }
  tangents_.assign(n, Tangent());
  for (size_t i = 0; i < n; ++i) {
    Tangent& m = tangents_[i];
    const Keyframe& k = keys[i];
    if (k.has_velocity) {
      m.translation = k.velocity;
      m.scale = k.scale_rate;
      // dq/dt = 1/2 (0, omega) q for an angular velocity omega in world axes.
      const Eigen::Quaterniond omega(0, k.angular_velocity.x(), k.angular_velocity.y(), k.angular_velocity.z());
      m.rotation = 0.5 * (omega * quat_from_coeffs(quats_[i])).coeffs();
    } else if (i > 0 && i + 1 < n) {
      const double span = keys[i + 1].time - keys[i - 1].time;
      m.translation = (keys[i + 1].transform.translation - keys[i - 1].transform.translation) / span;
      m.scale = (keys[i + 1].transform.scale - keys[i - 1].transform.scale) / span;
      m.rotation = (quats_[i + 1] - quats_[i - 1]) / span;
    }  // first and last key without a velocity: zero tangent
  }
}

void Motion::evaluate(double t, Vec3& translation, double& scale, Eigen::Vector4d& quat, Vec3* d_translation,
                      double* d_scale, Eigen::Vector4d* d_quat) const {
  if (tangents_.size() != keys.size() || quats_.size() != keys.size())
    throw std::logic_error("Motion: finalize() must be called after filling keys");
  if (d_translation) d_translation->setZero();
  if (d_scale) *d_scale = 0;
  if (d_quat) d_quat->setZero();
  if (keys.empty()) {
    translation.setZero();
    scale = 1;
    quat = Eigen::Vector4d(0, 0, 0, 1);
    return;
  }
  const size_t n = keys.size();
  if (n == 1 || !(t >= keys.front().time) || t > keys.back().time) {
    const size_t held = (n == 1 || !(t >= keys.front().time)) ? 0 : n - 1;  // NaN t holds the first key
    translation = keys[held].transform.translation;
    scale = keys[held].transform.scale;
    quat = quats_[held];
    return;
  }
  // Interval [t_i, t_i+1] containing t (the last interval for t == last key time).
  const auto after = std::upper_bound(keys.begin(), keys.end(), t,
                                      [](double time, const Keyframe& k) { return time < k.time; });
  size_t i = static_cast<size_t>(after - keys.begin());
  i = std::min(i == 0 ? 0 : i - 1, n - 2);
  const Keyframe& k0 = keys[i];
  const Keyframe& k1 = keys[i + 1];
  const Tangent& m0 = tangents_[i];
  const Tangent& m1 = tangents_[i + 1];
  const double h = k1.time - k0.time;
  const HermiteBasis b((t - k0.time) / h);
  translation = b.value(k0.transform.translation, m0.translation, k1.transform.translation, m1.translation, h);
  scale = b.value(k0.transform.scale, m0.scale, k1.transform.scale, m1.scale, h);
  quat = b.value(quats_[i], m0.rotation, quats_[i + 1], m1.rotation, h);
  if (d_translation)
    *d_translation =
        b.derivative(k0.transform.translation, m0.translation, k1.transform.translation, m1.translation, h);
  if (d_scale) *d_scale = b.derivative(k0.transform.scale, m0.scale, k1.transform.scale, m1.scale, h);
  if (d_quat) *d_quat = b.derivative(quats_[i], m0.rotation, quats_[i + 1], m1.rotation, h);
}

Transform Motion::pose(double t) const {
  Transform out;
  Eigen::Vector4d quat;
  evaluate(t, out.translation, out.scale, quat, nullptr, nullptr, nullptr);
  const double length = quat.norm();
  // Aligned unit quaternions cannot interpolate through zero unless the tangents are absurd; hold identity then.
  out.rotation = length > 1e-12 ? quat_from_coeffs(quat / length) : Eigen::Quaterniond::Identity();
  return out;
}

PoseRate Motion::rate(double t) const {
  PoseRate out;
  Vec3 translation;
  double scale;
  Eigen::Vector4d quat, d_quat;
  evaluate(t, translation, scale, quat, &out.translation, &out.scale, &d_quat);
  const double length = quat.norm();
  if (!(length > 1e-12)) return out;
  // Derivative of q = p/|p|: the component of dp/dt orthogonal to q, divided by |p|.
  const Eigen::Vector4d q = quat / length;
  const Eigen::Vector4d dq = (d_quat - q * q.dot(d_quat)) / length;
  // For a unit quaternion, omega = 2 dq q^* (a pure quaternion).
  out.angular = 2 * (quat_from_coeffs(dq) * quat_from_coeffs(q).conjugate()).vec();
  return out;
}

Vec3 Motion::velocity(double t, const Vec3& x_rest) const {
  const Transform p = pose(t);
  const PoseRate r = rate(t);
  const Vec3 rotated = p.rotation * x_rest;
  return r.translation + r.scale * rotated + p.scale * r.angular.cross(rotated);
}

}  // namespace arcsim
