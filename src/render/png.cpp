#include "render/png.hpp"

#include <png.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "math/errors.hpp"

namespace arcsim {

void write_png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgba) {
  if (width <= 0 || height <= 0 || rgba.size() != size_t(width) * size_t(height) * 4)
    throw InputError(path + ": image buffer of " + std::to_string(rgba.size()) + " bytes does not match " +
                     std::to_string(width) + "x" + std::to_string(height) + " RGBA");
  std::vector<uint8_t> rgb(size_t(width) * size_t(height) * 3);
  for (size_t i = 0, n = size_t(width) * size_t(height); i < n; ++i) std::memcpy(&rgb[3 * i], &rgba[4 * i], 3);

  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = png_uint_32(width);
  image.height = png_uint_32(height);
  image.format = PNG_FORMAT_RGB;

  const std::string temp = path + ".part";
  FILE* file = std::fopen(temp.c_str(), "wb");
  if (!file) throw InputError(path + ": cannot open for writing (" + std::strerror(errno) + ")");
  const bool encoded = png_image_write_to_stdio(&image, file, 0, rgb.data(), 0, nullptr) != 0;
  const std::string libpng_message = image.message;
  png_image_free(&image);
  const bool closed = std::fclose(file) == 0;
  if (!encoded || !closed) {
    std::remove(temp.c_str());
    throw InputError(path + ": cannot write PNG (" + (encoded ? std::string("write error") : libpng_message) + ")");
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temp.c_str());
    throw InputError(path + ": cannot rename the finished PNG into place (" + reason + ")");
  }
}

Image read_png(const std::string& path) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str()))
    throw InputError(path + ": cannot read PNG (" + image.message + ")");
  image.format = PNG_FORMAT_RGBA;
  Image out;
  out.width = int(image.width);
  out.height = int(image.height);
  out.rgba.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.rgba.data(), 0, nullptr)) {
    const std::string message = image.message;
    png_image_free(&image);
    throw InputError(path + ": cannot decode PNG (" + message + ")");
  }
  return out;
}

}  // namespace arcsim
