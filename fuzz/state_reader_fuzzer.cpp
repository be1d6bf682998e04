// libFuzzer target: the state-file reader (io/state.hpp) behind `arcsim resume`. A state file ends with a
// checksum and its header holds the file size, so almost every mutation would stop at those two checks. The
// target therefore writes the true size into the header and the true checksum at the end before reading, and
// mutations reach the section decoders and the checks against the scene. (Corrupt sizes and checksums are
// covered byte by byte in tests/io/state_errors_test.cpp.)
//
// The state is loaded into a Simulation built once from fuzz/state_scene/scene.json (a cloth with two
// materials, an obstacle and a handle: every section has content). A refused file must leave the Simulation
// untouched; an accepted one must hold a valid mesh.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "fuzz_input_file.hpp"
#include "io/scene_parser.hpp"
#include "io/state.hpp"
#include "math/errors.hpp"
#include "mesh/validate.hpp"
#include "sim/simulation.hpp"

namespace {

std::unique_ptr<arcsim::Simulation> simulation;

constexpr size_t kSizeOffset = 16;  // magic (8) + version (4) + section count (4)
constexpr size_t kChecksumBytes = 8;

void put_u64(std::vector<uint8_t>& bytes, size_t at, uint64_t value) {
  for (int i = 0; i < 8; ++i) bytes[at + i] = static_cast<uint8_t>(value >> (8 * i));
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* scene = std::getenv("ARCSIM_FUZZ_STATE_SCENE");
  const std::string path = scene ? scene : "fuzz/state_scene/scene.json";
  try {
    simulation = std::make_unique<arcsim::Simulation>(arcsim::load_scene(path));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "state fuzzer: cannot build the simulation from %s (run from the repository root, or "
                         "set ARCSIM_FUZZ_STATE_SCENE): %s\n", path.c_str(), e.what());
    std::exit(1);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  if (bytes.size() >= kSizeOffset + 8 + kChecksumBytes) {
    put_u64(bytes, kSizeOffset, bytes.size());
    const size_t body = bytes.size() - kChecksumBytes;
    // The checksum of the version the (possibly mutated) header names; unknown versions are refused before it.
    uint32_t version = 0;
    for (int k = 0; k < 4; ++k) version |= static_cast<uint32_t>(bytes[8 + k]) << (8 * k);
    put_u64(bytes, body, arcsim::state_checksum(reinterpret_cast<const char*>(bytes.data()), body, version));
  }
  const std::string path = arcsim::fuzz::write_input("input.state", bytes.data(), bytes.size());
  try {
    arcsim::load_state(*simulation, path);
  } catch (const arcsim::InputError&) {
    return 0;  // refused with a message: the expected outcome for bad input
  }
  for (const auto& cloth : simulation->cloths) {
    arcsim::MeshCheckOptions loader_checks;  // what load_state promises: structure and finiteness
    loader_checks.require_positive_rest_area = false;
    loader_checks.require_current_rest_data = false;
    const std::string problem = arcsim::check_mesh(cloth.mesh, loader_checks);
    if (!problem.empty()) {
      std::fprintf(stderr, "accepted a state file whose mesh is invalid: %s\n", problem.c_str());
      std::abort();
    }
  }
  return 0;
}
