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
  // Builds the rotation from ARCSim's [angle in degrees, axis x, y, z].
  static Eigen::Quaterniond rotation_from_degrees(double degrees, const Vec3& axis);
};

struct Keyframe {
  double time = 0;
  Transform transform;
  bool has_velocity = false;
  Transform velocity;  // derivative: translation (m/s), scale rate (1/s, stored as scale - 1), rotation rate
};

// A keyframed motion, interpolated with cubic Hermite splines as ARCSim does: keyframe tangents are the given
// velocities, else central differences (zero at the ends). Before the first key and after the last the pose is
// held.
class Motion {
 public:
  std::vector<Keyframe> keys;
  // Precomputes tangents; call after filling `keys` (sorted by time).
  void finalize();
  Transform pose(double t) const;
  // Linear velocity of the material point that starts at `x_rest` (the point before the motion is applied).
  Vec3 velocity(double t, const Vec3& x_rest) const;

 private:
  struct Tangent {
    Vec3 translation = Vec3::Zero();
    double scale = 0;
    Eigen::Vector4d rotation = Eigen::Vector4d::Zero();  // quaternion coefficients (x, y, z, w)
  };
  std::vector<Tangent> tangents_;
};

}  // namespace arcsim
