// Reading triangle meshes from OBJ and PLY files (ASCII and binary), for tools and tests.
//
// Parsing is done by Assimp (Debian's libassimp-dev): a maintained importer for both formats.
// Every mesh in the file is merged into one, with node transforms applied and vertices shared
// between faces again (Assimp splits OBJ corners apart), so edge topology survives loading.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "mesh.h"
#include "status.h"

namespace sdfg {

struct LoadedMesh {
  TriangleMesh mesh;
  std::string name;             // file name without folder
  size_t droppedDegenerate = 0;  // zero-area triangles the file had; dropped, not an error
};

// Loads `path`. Errors (io_error): missing or unreadable file, unknown format, parse failure,
// no triangles; (invalid_argument): NaN/inf coordinates or out-of-range indices in the file.
Result<LoadedMesh> loadMesh(const std::filesystem::path& path);

}  // namespace sdfg
