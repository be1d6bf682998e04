// Files for tests: the repository's meshes/ folder and self-removing temporary folders.
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <string>

namespace arcsim::testing {

// The repository's meshes/ folder (absolute): from the working directory (the Makefile runs tests from the
// root), next to the bin/ folder holding the test binary, or relative to this source file. Empty if not found.
inline std::filesystem::path project_meshes() {
  namespace fs = std::filesystem;
  std::error_code no_throw;
  const fs::path binary = fs::read_symlink("/proc/self/exe", no_throw);
  for (const fs::path& candidate : {fs::path("meshes"), binary.parent_path().parent_path() / "meshes",
                                    fs::path(__FILE__).parent_path() / "../../meshes"})
    if (fs::exists(candidate / "square.obj", no_throw)) return fs::absolute(candidate);
  return {};
}

// A fresh folder under the system temp folder, removed with everything in it when the object goes.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "arcsim-test-XXXXXX").string();
    if (::mkdtemp(pattern.data())) path = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    if (!path.empty()) std::filesystem::remove_all(path, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

}  // namespace arcsim::testing
