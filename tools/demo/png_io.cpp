#include "png_io.h"

#include <png.h>

#include <cstdio>
#include <cstring>

namespace sdfg::demo {

bool writePng(const std::string& path, uint32_t width, uint32_t height,
              const std::vector<uint8_t>& rgba, std::string& error) {
  if (rgba.size() != size_t(width) * height * 4) {
    error = path + ": pixel buffer does not match " + std::to_string(width) + "x" +
            std::to_string(height);
    return false;
  }
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = width;
  image.height = height;
  image.format = PNG_FORMAT_RGBA;
  if (!png_image_write_to_file(&image, path.c_str(), 0, rgba.data(), 0, nullptr)) {
    error = path + ": " + image.message;
    return false;
  }
  return true;
}

bool readPng(const std::string& path, uint32_t& width, uint32_t& height, std::vector<uint8_t>& rgba,
             std::string& error) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) {
    error = path + ": " + image.message;
    return false;
  }
  image.format = PNG_FORMAT_RGBA;
  width = image.width;
  height = image.height;
  rgba.assign(PNG_IMAGE_SIZE(image), 0);
  if (!png_image_finish_read(&image, nullptr, rgba.data(), 0, nullptr)) {
    error = path + ": " + image.message;
    png_image_free(&image);
    return false;
  }
  return true;
}

}  // namespace sdfg::demo
