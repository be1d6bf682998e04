#include "render/png.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>

#include "math/errors.hpp"

namespace arcsim {
namespace {

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "arcsim-png-" + std::to_string(::getpid()) + "-" + name;
}

bool exists(const std::string& path) { return std::ifstream(path).good(); }

TEST(RenderPng, WrittenImageReadsBackIdentically) {
  const int w = 37, h = 23;  // odd sizes catch row-stride mistakes
  std::vector<uint8_t> rgba(size_t(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &rgba[(size_t(y) * w + x) * 4];
      p[0] = uint8_t(x * 7);
      p[1] = uint8_t(y * 11);
      p[2] = uint8_t((x * y) ^ 0x5a);
      p[3] = 255;
    }
  const std::string path = temp_path("roundtrip.png");
  write_png(path, w, h, rgba);
  EXPECT_FALSE(exists(path + ".part"));
  const Image image = read_png(path);
  EXPECT_EQ(image.width, w);
  EXPECT_EQ(image.height, h);
  EXPECT_EQ(image.rgba, rgba);
  std::remove(path.c_str());
}

TEST(RenderPng, AlphaIsNotStored) {
  const std::vector<uint8_t> rgba = {10, 20, 30, 0, 40, 50, 60, 128};
  const std::string path = temp_path("alpha.png");
  write_png(path, 2, 1, rgba);
  const Image image = read_png(path);
  EXPECT_EQ(image.rgba, (std::vector<uint8_t>{10, 20, 30, 255, 40, 50, 60, 255}));
  std::remove(path.c_str());
}

TEST(RenderPng, ErrorsNameThePath) {
  const std::string missing_dir = temp_path("no-such-dir") + "/frame.png";
  try {
    write_png(missing_dir, 1, 1, {1, 2, 3, 255});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(missing_dir), std::string::npos) << e.what();
  }
  EXPECT_THROW(write_png(temp_path("size.png"), 2, 2, {1, 2, 3, 255}), InputError);
  EXPECT_FALSE(exists(temp_path("size.png")));
  EXPECT_THROW(read_png(temp_path("absent.png")), InputError);
  const std::string garbage = temp_path("garbage.png");
  std::ofstream(garbage) << "not a png at all";
  EXPECT_THROW(read_png(garbage), InputError);
  std::remove(garbage.c_str());
}

}  // namespace
}  // namespace arcsim
