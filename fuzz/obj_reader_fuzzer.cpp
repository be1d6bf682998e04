// libFuzzer target: the OBJ reader and mesh builder (io/obj.hpp). Any input must either build a mesh that
// passes check_mesh or be refused with an InputError; anything else (a crash, a sanitizer report, another
// exception, a hang) is a finding.
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_input_file.hpp"
#include "io/obj.hpp"
#include "math/errors.hpp"
#include "mesh/validate.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = arcsim::fuzz::write_input("input.obj", data, size);
  try {
    const arcsim::Mesh mesh = arcsim::load_obj_mesh(path);
    const std::string problem = arcsim::check_mesh(mesh);
    if (!problem.empty()) {
      std::fprintf(stderr, "accepted an OBJ that builds an invalid mesh: %s\n", problem.c_str());
      std::abort();
    }
  } catch (const arcsim::InputError&) {
    // Refused with a message: the expected outcome for bad input.
  }
  return 0;
}
