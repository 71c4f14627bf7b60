#include "test_support.h"

#include <cstdlib>

namespace sdfg::test {

std::optional<std::filesystem::path> sharedMeshesDir() {
  std::filesystem::path dir;
  if (const char* env = std::getenv("SDFG_SHARED_MESHES"); env != nullptr && *env != '\0') {
    dir = env;
  } else {
    dir = std::filesystem::path(SDFG_SHARED_DIR) / "meshes";
  }
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return std::nullopt;
  return dir;
}

std::optional<std::filesystem::path> sharedMesh(const std::string& fileName) {
  const auto dir = sharedMeshesDir();
  if (!dir) return std::nullopt;
  const auto path = *dir / fileName;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
  return path;
}

}  // namespace sdfg::test
