// loadMesh for the Windows test build: mesh files are read with Assimp, which the Windows build
// does not have, so every file is refused with that reason. The Windows runs use the embedded
// shapes (io/shapes.h) only; the tests that need a mesh file are left out of them.
#include "io/mesh_io.h"

namespace sdfg {

Result<LoadedMesh> loadMesh(const std::filesystem::path& path) {
  return makeError(Status::io_error,
                   "mesh file '" + path.string() + "': not read in the Windows build (no Assimp)");
}

}  // namespace sdfg
