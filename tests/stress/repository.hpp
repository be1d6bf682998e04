// Where the repository's files are, for tests that read conf/, meshes/ or materials/: the working directory,
// beside bin/, or relative to this file. Returns an empty path if `marker` is found in none of them.
#pragma once

#include <filesystem>

namespace arcsim::testing {

inline std::filesystem::path repository_root(const std::filesystem::path& marker) {
  namespace fs = std::filesystem;
  std::error_code no_throw;
  const fs::path binary = fs::read_symlink("/proc/self/exe", no_throw);
  for (const fs::path& candidate : {fs::path("."), binary.parent_path().parent_path(),
                                    fs::path(__FILE__).parent_path() / "../.."})
    if (fs::exists(candidate / marker, no_throw)) return fs::absolute(candidate);
  return {};
}

}  // namespace arcsim::testing
