// PNG files through libpng: RGBA8 images, top row first. Used by the demo and its checker.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sdfg::demo {

// Writes width x height RGBA8 pixels (width * height * 4 bytes). False with `error` on failure.
bool writePng(const std::string& path, uint32_t width, uint32_t height,
              const std::vector<uint8_t>& rgba, std::string& error);

// Reads any PNG as RGBA8. False with `error` on a missing or broken file.
bool readPng(const std::string& path, uint32_t& width, uint32_t& height, std::vector<uint8_t>& rgba,
             std::string& error);

}  // namespace sdfg::demo
