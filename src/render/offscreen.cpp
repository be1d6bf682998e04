#include "render/offscreen.hpp"

#include "render/gl_api.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace arcsim {

namespace {

OSMesaContext as_osmesa(void* context) { return static_cast<OSMesaContext>(context); }

}  // namespace

OffscreenContext::OffscreenContext(int width, int height) : width_(width), height_(height) {
  if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide)
    throw std::runtime_error("renderer: image size " + std::to_string(width) + "x" + std::to_string(height) +
                             " is outside 1.." + std::to_string(kMaxSide));
  buffer_.assign(size_t(width) * size_t(height) * 4, 0);
  osmesa_ = gl().OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (!osmesa_)
    throw std::runtime_error("OSMesa: cannot create an off-screen RGBA context with 24-bit depth and 8-bit stencil");
  try {
    make_current();
  } catch (...) {
    gl().OSMesaDestroyContext(as_osmesa(osmesa_));
    throw;
  }
}

OffscreenContext::~OffscreenContext() {
  if (fbo_ && gl().OSMesaMakeCurrent(as_osmesa(osmesa_), buffer_.data(), GL_UNSIGNED_BYTE, width_, height_))
    release_multisample_target();
  gl().OSMesaDestroyContext(as_osmesa(osmesa_));
}

void OffscreenContext::make_current() {
  if (!gl().OSMesaMakeCurrent(as_osmesa(osmesa_), buffer_.data(), GL_UNSIGNED_BYTE, width_, height_))
    throw std::runtime_error("OSMesa: cannot bind the off-screen context to a " + std::to_string(width_) + "x" +
                             std::to_string(height_) + " RGBA buffer");
}

void OffscreenContext::release_multisample_target() {
  gl().BindFramebuffer(GL_FRAMEBUFFER, 0);
  if (fbo_) gl().DeleteFramebuffers(1, &fbo_);
  if (colour_rb_) gl().DeleteRenderbuffers(1, &colour_rb_);
  if (depth_rb_) gl().DeleteRenderbuffers(1, &depth_rb_);
  fbo_ = colour_rb_ = depth_rb_ = 0;
  fbo_samples_ = 0;
}

bool OffscreenContext::begin_frame(int samples) {
  make_current();
  GLint max_samples = 0;
  gl().GetIntegerv(GL_MAX_SAMPLES, &max_samples);
  const int wanted = std::min(samples, int(max_samples));
  if (wanted <= 1) {
    if (fbo_) release_multisample_target();
    gl().BindFramebuffer(GL_FRAMEBUFFER, 0);
    return false;
  }
  if (fbo_ && fbo_samples_ == wanted) {
    gl().BindFramebuffer(GL_FRAMEBUFFER, fbo_);
    return true;
  }
  release_multisample_target();
  gl().GenFramebuffers(1, &fbo_);
  gl().GenRenderbuffers(1, &colour_rb_);
  gl().GenRenderbuffers(1, &depth_rb_);
  gl().BindRenderbuffer(GL_RENDERBUFFER, colour_rb_);
  gl().RenderbufferStorageMultisample(GL_RENDERBUFFER, wanted, GL_RGBA8, width_, height_);
  gl().BindRenderbuffer(GL_RENDERBUFFER, depth_rb_);
  gl().RenderbufferStorageMultisample(GL_RENDERBUFFER, wanted, GL_DEPTH24_STENCIL8, width_, height_);
  gl().BindFramebuffer(GL_FRAMEBUFFER, fbo_);
  gl().FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_rb_);
  gl().FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth_rb_);
  fbo_samples_ = wanted;
  const bool complete = gl().CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  // A failed set-up is not an error for the frame: it falls back to the plain buffer.
  while (gl().GetError() != GL_NO_ERROR) {
  }
  if (!complete) {
    release_multisample_target();
    return false;
  }
  return true;
}

void OffscreenContext::end_frame() {
  if (fbo_) {
    gl().BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    gl().BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    gl().BlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    gl().BindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  gl().Finish();
}

}  // namespace arcsim
