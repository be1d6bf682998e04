#include "render/gl_api.hpp"

#include <dlfcn.h>

#include <string>

#include "math/errors.hpp"

namespace arcsim {

namespace {

// The run-time library first (package libosmesa6), then the development link.
constexpr const char* kLibraryNames[] = {"libOSMesa.so.8", "libOSMesa.so"};

void* open_library() {
  std::string errors;
  for (const char* name : kLibraryNames) {
    if (void* handle = dlopen(name, RTLD_NOW | RTLD_LOCAL)) return handle;
    const char* why = dlerror();
    errors += std::string(errors.empty() ? "" : "; ") + (why ? why : name);
  }
  throw EnvironmentError("renderer: cannot load OSMesa (" + errors + "); install Debian's libosmesa6");
}

GlApi load() {
  void* library = open_library();
  GlApi api;
  auto find = [&](const char* symbol) {
    void* address = dlsym(library, symbol);
    if (!address) throw EnvironmentError(std::string("renderer: libOSMesa has no ") + symbol);
    return address;
  };
#define ARCSIM_LOAD_OSMESA(name) \
  api.OSMesa##name = reinterpret_cast<decltype(api.OSMesa##name)>(find("OSMesa" #name));
  ARCSIM_OSMESA_FUNCTIONS(ARCSIM_LOAD_OSMESA)
#undef ARCSIM_LOAD_OSMESA
  // Core functions are exported; extension ones (framebuffer objects) may only be reachable through
  // OSMesaGetProcAddress.
  auto find_gl = [&](const char* symbol) {
    if (void* address = dlsym(library, symbol)) return address;
    if (auto address = api.OSMesaGetProcAddress(symbol)) return reinterpret_cast<void*>(address);
    throw EnvironmentError(std::string("renderer: libOSMesa has no ") + symbol);
  };
#define ARCSIM_LOAD_GL(name) api.name = reinterpret_cast<decltype(api.name)>(find_gl("gl" #name));
  ARCSIM_GL_FUNCTIONS(ARCSIM_LOAD_GL)
#undef ARCSIM_LOAD_GL
  return api;
}

}  // namespace

const GlApi& gl() {
  static const GlApi api = load();
  return api;
}

}  // namespace arcsim
