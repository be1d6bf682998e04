// libFuzzer target: the scene parser (io/scene_parser.hpp). Any input must either parse into a Scene or be
// refused with an InputError. The input is written as scene.json in a scratch folder holding a valid mesh and
// material file, so inputs that name "sheet.obj" or "material.json" get past the file checks into the rest of
// the parser; run from the repository root, the seeds' "meshes/..." and "materials/..." resolve there too.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz_input_file.hpp"
#include "io/scene_parser.hpp"
#include "math/errors.hpp"

namespace {

void write_text(const std::string& name, const std::string& text) {
  arcsim::fuzz::write_input(name, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  write_text("sheet.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  write_text("material.json",
             R"({"thickness": 1e-3, "density": 500, "elastic_modulus": 1e6, "poisson_ratio": 0.3})");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = arcsim::fuzz::write_input("scene.json", data, size);
  try {
    (void)arcsim::load_scene(path);
  } catch (const arcsim::InputError&) {
    // Refused with a message: the expected outcome for bad input.
  }
  return 0;
}
