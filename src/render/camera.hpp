// A pinhole camera for the off-screen renderer, the matrices it defines, and automatic framing of a scene.
//
// Conventions: world units are metres; pixel coordinates are continuous with (0, 0) at the top-left corner of
// the image, x to the right and y downwards, so pixel (i, j) of an image covers [i, i+1) x [j, j+1).
#pragma once

#include <Eigen/Geometry>

#include "math/types.hpp"

namespace arcsim {

using Mat4 = Eigen::Matrix4d;

struct Camera {
  Vec3 eye = Vec3(0, -3, 1.5);   // m
  Vec3 target = Vec3::Zero();    // m, the point seen at the image centre
  Vec3 up = Vec3::UnitZ();       // world direction that appears upwards in the image (need not be exact)
  double fov_y_deg = 35;         // vertical field of view (degrees)
};

// World "up" for a scene: opposite to gravity, or +z when gravity is zero or not finite.
Vec3 up_from_gravity(const Vec3& gravity);

// The camera's orthonormal frame: right, true up (in the image plane) and back (from target towards the eye).
// Degenerate cameras (eye == target, up parallel to the view direction) get a well-defined fallback frame.
struct CameraFrame {
  Vec3 right, up, back;
};
CameraFrame camera_frame(const Camera& camera);

// World -> eye coordinates (OpenGL convention: the camera looks down -z). Column-major, usable by glLoadMatrixd.
Mat4 view_matrix(const Camera& camera);

// Perspective projection for an image of the given aspect ratio (width / height); near/far in metres.
Mat4 projection_matrix(const Camera& camera, double aspect, double z_near, double z_far);

// Where a world point appears in a width x height image rendered with this camera (see the pixel convention
// above). Points at or behind the eye plane get infinite coordinates.
Vec2 project_to_pixel(const Camera& camera, int width, int height, const Vec3& p);

// Orthonormal horizontal axes for a given up direction: `front` points towards the default viewer (-y for z-up
// scenes, +z for y-up scenes) and `side` = up x front points to the viewer's right.
struct HorizontalAxes {
  Vec3 front, side;
};
HorizontalAxes horizontal_axes(const Vec3& up);

struct FramingOptions {
  double azimuth_deg = 32;    // rotation of the viewer about `up`, from the front axis towards the side axis
  double elevation_deg = 24;  // angle of the viewer above the horizontal plane
  double fov_y_deg = 35;
  double fill = 0.9;          // fraction of the half-width / half-height the bounds may use (margin)
};

// A camera that looks at the centre of `bounds` from a 3/4 elevated direction and is far enough away that all 8
// corners of the box fall inside an image of the given aspect ratio (width / height). Empty or non-finite bounds
// are replaced by a unit box at the origin; flat or tiny boxes are padded so the camera stays well-defined.
Camera frame_camera(const Eigen::AlignedBox3d& bounds, double aspect, const Vec3& up = Vec3::UnitZ(),
                    const FramingOptions& options = FramingOptions());

}  // namespace arcsim
