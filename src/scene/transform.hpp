// Rigid-plus-scale transforms and keyframed motions (ARCSim scene `transform` objects and `motions`).
#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "math/types.hpp"

namespace arcsim {

// x -> translation + scale * rotation * x  (scale, then rotate, then translate).
struct Transform {
  Vec3 translation = Vec3::Zero();
  double scale = 1;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();

  Vec3 apply(const Vec3& x) const { return translation + scale * (rotation * x); }
  Vec3 apply_vector(const Vec3& d) const { return scale * (rotation * d); }
  // Builds the rotation from ARCSim's [angle in degrees, axis x, y, z]. The axis is normalised; a zero axis
  // gives the identity (the scene parser rejects a zero axis with a nonzero angle).
  static Eigen::Quaterniond rotation_from_degrees(double degrees, const Vec3& axis);
};

struct Keyframe {
  double time = 0;                       // s
  Transform transform;                   // pose at `time` (identity when the scene gives none)
  bool has_velocity = false;             // false: tangent from the neighbouring keys
  Vec3 velocity = Vec3::Zero();          // translation rate (m/s)
  double scale_rate = 0;                 // d(scale)/dt (1/s)
  Vec3 angular_velocity = Vec3::Zero();  // rad/s, world axes
};

// Time derivative of a motion's pose parameters.
struct PoseRate {
  Vec3 translation = Vec3::Zero();  // m/s
  double scale = 0;                 // 1/s
  Vec3 angular = Vec3::Zero();      // angular velocity (rad/s, world axes)
};

// A keyframed motion, interpolated with cubic Hermite splines as ARCSim does: translation, scale and the four
// quaternion coefficients each follow a Hermite curve (the quaternion is renormalised after interpolation and
// consecutive keys are taken in the same hemisphere). Keyframe tangents are the given velocities, else central
// differences (zero at the first and last key). Before the first key and after the last the pose is held.
class Motion {
 public:
  std::vector<Keyframe> keys;  // strictly increasing times
  // Precomputes tangents; call after filling `keys` (sorted by time), before pose/rate/velocity.
  void finalize();
  Transform pose(double t) const;
  // Exact time derivative of pose(t) (zero outside the key range).
  PoseRate rate(double t) const;
  // Linear velocity (m/s) of the material point that starts at `x_rest` (the point before the motion is
  // applied): d/dt pose(t).apply(x_rest).
  Vec3 velocity(double t, const Vec3& x_rest) const;

 private:
  struct Tangent {
    Vec3 translation = Vec3::Zero();
    double scale = 0;
    Eigen::Vector4d rotation = Eigen::Vector4d::Zero();  // quaternion coefficients (x, y, z, w) per second
  };
  // Pose parameters at time t and their derivative; outside the key range the derivative is zero.
  void evaluate(double t, Vec3& translation, double& scale, Eigen::Vector4d& quat, Vec3* d_translation,
                double* d_scale, Eigen::Vector4d* d_quat) const;
  std::vector<Tangent> tangents_;
  std::vector<Eigen::Vector4d> quats_;  // key rotations' coefficients, sign-aligned with the previous key
};

}  // namespace arcsim
