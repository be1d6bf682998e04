// Off-screen rendering of simulation frames (OSMesa, fixed-function OpenGL) to RGBA images and PNG files.
//
// Typical use (`arcsim replay`): compute the bounds of the whole animation once, frame a camera on them, then
// render every frame with the same camera and options so that the view, ground and lighting stay still:
//
//   RenderOptions options;
//   options.up = up_from_gravity(gravity);
//   options.scene_bounds = union of bounds_of(cloths) and bounds_of(obstacles) over all frames;
//   Camera camera = frame_camera(options.scene_bounds, double(width) / height, options.up);
//   Renderer renderer(width, height);
//   for each frame: render_frame_png(renderer, cloths, obstacles, camera, options, png_path);
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "math/types.hpp"
#include "render/camera.hpp"
#include "render/png.hpp"
#include "render/render_mesh.hpp"
#include "render/stage.hpp"

namespace arcsim {

class OffscreenContext;

struct RenderOptions {
  Vec3 up = Vec3::UnitZ();          // world up (opposite to gravity): orients the ground plane and the lights
  bool ground = true;               // checkered ground plane below the scene, fading out at its border
  bool shadows = true;              // planar shadows of cloths and obstacles on the ground (needs `ground`)
  bool wireframe = false;           // draw every cloth triangle edge over the shading
  bool highlight_edges = true;      // draw RenderMesh::highlight_edges (borders, cracks) as dark lines
  std::optional<double> ground_level;  // height of the ground along `up` (m); default: lowest scene point
  // Extent of the whole animation. Ground size, ground level and clipping planes derive from it, so pass the
  // same box for every frame; an empty box means "this frame's meshes".
  Eigen::AlignedBox3d scene_bounds;
  int samples = 4;                  // multisample antialiasing samples per pixel (1 = off)
};

// Owns an OSMesa context with its colour/depth/stencil buffers; render many frames with one Renderer.
// Not thread-safe; one Renderer per thread.
class Renderer {
 public:
  // Throws std::runtime_error with a readable message if the size is unusable or OSMesa cannot create or bind a
  // context.
  Renderer(int width, int height);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws one image. Cloth front faces (counter-clockwise as seen) are warm light orange, back faces blue-grey;
  // obstacles are neutral grey. Throws InputError if a mesh has an out-of-range index or a non-finite position.
  void render(const std::vector<RenderMesh>& cloths, const std::vector<RenderMesh>& obstacles,
              const Camera& camera, const RenderOptions& options);

  int width() const { return width_; }
  int height() const { return height_; }
  // The last rendered image: width * height RGBA pixels, rows top-down, alpha 255.
  const std::vector<uint8_t>& rgba() const { return rgba_; }

 private:
  std::unique_ptr<OffscreenContext> context_;
  int width_, height_;
  std::vector<uint8_t> rgba_;
};

// Renders one frame and writes it to `png_path` (atomically). Throws InputError on bad meshes or write failure.
void render_frame_png(Renderer& renderer, const std::vector<RenderMesh>& cloths,
                      const std::vector<RenderMesh>& obstacles, const Camera& camera, const RenderOptions& options,
                      const std::string& png_path);

}  // namespace arcsim
