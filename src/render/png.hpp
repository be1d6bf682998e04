// PNG files of 8-bit RGBA images (rows top-down), through libpng's simplified API.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace arcsim {

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4 bytes, rows top-down
};

// Writes an RGB PNG (alpha is dropped: rendered frames are opaque). The file is written under a temporary name
// in the same folder and renamed, so a reader never sees a half-written image. Throws InputError naming the path
// if the size does not match the buffer or the file cannot be written.
void write_png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgba);

// Reads any PNG as 8-bit RGBA. Throws InputError naming the path if it cannot be read or decoded.
Image read_png(const std::string& path);

}  // namespace arcsim
