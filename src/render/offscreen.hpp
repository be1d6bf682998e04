// An OSMesa context with its own colour, depth and stencil buffers: the drawing surface of the Renderer.
#pragma once

#include <cstdint>
#include <vector>

namespace arcsim {

class OffscreenContext {
 public:
  // Throws std::runtime_error with a readable message if the size is unusable or OSMesa cannot create or bind a
  // context.
  OffscreenContext(int width, int height);
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  static constexpr int kMaxSide = 16384;

  // Makes this context current on the calling thread and selects the draw target: a multisampled off-screen
  // buffer with up to `samples` samples per pixel, or the plain buffer when samples <= 1 or the implementation
  // cannot multisample. Returns true if the target is multisampled.
  bool begin_frame(int samples);
  // Resolves the multisampled image (if any) into the plain buffer and waits until drawing is complete.
  void end_frame();

  int width() const { return width_; }
  int height() const { return height_; }
  // RGBA rows, bottom-up (OpenGL order), valid after end_frame().
  const std::vector<uint8_t>& pixels() const { return buffer_; }

 private:
  void make_current();
  void release_multisample_target();

  void* osmesa_ = nullptr;          // OSMesaContext
  int width_, height_;
  std::vector<uint8_t> buffer_;     // OSMesa draws (or resolves) into this memory
  unsigned fbo_ = 0, colour_rb_ = 0, depth_rb_ = 0;  // multisampled target, 0 when none
  int fbo_samples_ = 0;
};

}  // namespace arcsim
