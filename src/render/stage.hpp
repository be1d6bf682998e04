// The scene around the sheets: ground plane, lights and planar shadows. Pure geometry, shared by the renderer
// and its tests.
#pragma once

#include <Eigen/Geometry>

#include "math/types.hpp"
#include "render/camera.hpp"

namespace arcsim {

struct Stage {
  Vec3 up = Vec3::UnitZ();        // unit normal of the ground plane
  double ground_level = 0;        // height of the ground plane along `up` (m): points p with up.p = level
  Vec3 ground_center = Vec3::Zero();  // on the ground plane, below the centre of the scene (m)
  double ground_radius = 1;       // half-size of the ground square (m); it fades out towards its border
  double scene_radius = 1;        // half-diagonal of the scene's bounding box (m)
  Vec3 key_light = Vec3::UnitZ(); // unit direction towards the main (shadow-casting) light
  Vec3 fill_light = Vec3::UnitZ();// unit direction towards the weaker light that comes from the viewer's side
};

// Lowest height along `up` of the box's corners (m); for an axis-aligned `up` this is the box's bottom face.
double lowest_level(const Eigen::AlignedBox3d& box, const Vec3& up);

// Main light: from above, somewhat towards the viewer and from the viewer's left, so that shadows fall behind
// and to the right of objects and the sheet's folds are modelled.
Vec3 key_light_direction(const Camera& camera, const Vec3& up);

// Stage for a scene whose extent is `scene_bounds` (empty or non-finite bounds get a unit box). The ground level
// is `ground_level` if finite, else the lowest point of the scene.
Stage make_stage(const Camera& camera, const Vec3& up, const Eigen::AlignedBox3d& scene_bounds, double ground_level);

// Projects points along the direction `toward_light` onto the plane {p : normal.p = level} (homogeneous 4x4,
// column-major like OpenGL). The light must not be parallel to the plane.
Mat4 planar_shadow_matrix(const Vec3& normal, double level, const Vec3& toward_light);

// Checker cell size for the ground (m): about a third of the scene radius, rounded down to 1, 2 or 5 times a
// power of ten so the squares read as real-world units.
double checker_cell_size(double scene_radius);

}  // namespace arcsim
