// The OpenGL and OSMesa entry points the renderer uses, loaded from libOSMesa when the first renderer is made.
//
// WHY not linked: libOSMesa pulls in LLVM (llvmpipe), whose start-up costs every process ~60 ms and ~50 MB
// before main, measured on the 2-core AMD guest (a program that only links it: 0.06 s and 53 MB against
// 0.00 s and 1 MB). Only `arcsim replay` renders; `simulate` of a light scene (square.json, ~0.15 s) paid a
// third of its time for it. The table is process-wide like the library's own state: loaded once, never unloaded.
#pragma once

#define GL_GLEXT_PROTOTYPES
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

namespace arcsim {

// X(name) for each glname the renderer calls.
#define ARCSIM_GL_FUNCTIONS(X) \
  X(Begin) \
  X(BindFramebuffer) \
  X(BindRenderbuffer) \
  X(BlendFunc) \
  X(BlitFramebuffer) \
  X(CheckFramebufferStatus) \
  X(Clear) \
  X(ClearColor) \
  X(ClearDepth) \
  X(ClearStencil) \
  X(Color3fv) \
  X(Color4f) \
  X(Color4fv) \
  X(ColorMask) \
  X(DeleteFramebuffers) \
  X(DeleteRenderbuffers) \
  X(DepthFunc) \
  X(DepthMask) \
  X(Disable) \
  X(DisableClientState) \
  X(DrawElements) \
  X(Enable) \
  X(EnableClientState) \
  X(End) \
  X(Finish) \
  X(FramebufferRenderbuffer) \
  X(GenFramebuffers) \
  X(GenRenderbuffers) \
  X(GetError) \
  X(GetIntegerv) \
  X(LightModelfv) \
  X(LightModeli) \
  X(Lightfv) \
  X(LineWidth) \
  X(LoadIdentity) \
  X(LoadMatrixd) \
  X(Materialf) \
  X(Materialfv) \
  X(MatrixMode) \
  X(NormalPointer) \
  X(PolygonOffset) \
  X(RenderbufferStorageMultisample) \
  X(ShadeModel) \
  X(StencilFunc) \
  X(StencilMask) \
  X(StencilOp) \
  X(Vertex2f) \
  X(Vertex3d) \
  X(VertexPointer) \
  X(Viewport)

// X(name) for each OSMesaname the renderer calls.
#define ARCSIM_OSMESA_FUNCTIONS(X) X(CreateContextExt) X(MakeCurrent) X(DestroyContext) X(GetProcAddress)

struct GlApi {
  // decltype names each function's type without referring to the symbol, so nothing links against libOSMesa.
#define ARCSIM_GL_MEMBER(name) decltype(&::gl##name) name = nullptr;
  ARCSIM_GL_FUNCTIONS(ARCSIM_GL_MEMBER)
#undef ARCSIM_GL_MEMBER
#define ARCSIM_OSMESA_MEMBER(name) decltype(&::OSMesa##name) OSMesa##name = nullptr;
  ARCSIM_OSMESA_FUNCTIONS(ARCSIM_OSMESA_MEMBER)
#undef ARCSIM_OSMESA_MEMBER
};

// The table, loaded on the first call (thread-safe). Throws std::runtime_error naming the library and the
// missing entry point if libOSMesa cannot be loaded or lacks one.
const GlApi& gl();

}  // namespace arcsim
