// Shared by the libFuzzer targets: our readers take paths (they name the file in every error), so each input
// is written to a file in a private temporary folder first. The folder is made once per process and removed
// at exit.
#pragma once

#include <stdlib.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace arcsim::fuzz {

inline const std::filesystem::path& scratch_folder() {
  static const std::filesystem::path folder = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "arcsim-fuzz-XXXXXX").string();
    if (!mkdtemp(pattern.data())) {
      std::perror("arcsim fuzz: mkdtemp");
      std::abort();
    }
    std::filesystem::path made(pattern);
    std::atexit([] { std::error_code ignored; std::filesystem::remove_all(scratch_folder(), ignored); });
    return made;
  }();
  return folder;
}

// Writes `size` bytes to `name` in the scratch folder and returns its path.
inline std::string write_input(const std::string& name, const uint8_t* data, size_t size) {
  const std::filesystem::path path = scratch_folder() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::perror("arcsim fuzz: cannot write the input file");
    std::abort();
  }
  return path.string();
}

}  // namespace arcsim::fuzz
