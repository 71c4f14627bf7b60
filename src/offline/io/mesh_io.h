// Reading triangle meshes from OBJ and PLY files (ASCII and binary), for tools and tests.
//
// OBJ is parsed by Assimp (Debian's libassimp-dev); PLY by a small strict reader of our own,
// because Assimp 5.2's PLY importer hangs or aborts on truncated files. Every mesh in the file
// is merged into one, with node transforms applied; polygons are split into triangles (ear
// clipping); vertices with bit-identical positions are shared again (Assimp splits OBJ corners
// apart), so edge topology survives loading. Vertices no triangle uses are dropped.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "base/status.h"
#include "mesh/mesh.h"

namespace sdfg {

struct LoadedMesh {
  TriangleMesh mesh;
  std::string name;              // file name without folder
  size_t droppedDegenerate = 0;  // zero-area triangles the file had; dropped, not an error
};

// Loads `path`. Errors (io_error): missing or unreadable file, unknown format, parse failure
// (including a truncated file, and out-of-range indices in an OBJ file, which Assimp rejects
// itself), no triangles; (invalid_argument): NaN/inf coordinates, out-of-range PLY indices.
// Messages start with the file's path. Never throws.
Result<LoadedMesh> loadMesh(const std::filesystem::path& path);

}  // namespace sdfg
