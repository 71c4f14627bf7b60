// Helpers shared by the unit tests: where the optional shared test meshes are, and how a test
// that needs something missing reports itself as skipped.
#pragma once

#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

namespace sdfg::test {

// ../shared/meshes beside the checkout, or $SDFG_SHARED_MESHES; nothing when absent.
std::optional<std::filesystem::path> sharedMeshesDir();

// Path of one shared mesh file; nothing when the folder or the file is absent.
std::optional<std::filesystem::path> sharedMesh(const std::string& fileName);

}  // namespace sdfg::test

// Ends the current test case as skipped: ctest matches the marker (SKIP_REGULAR_EXPRESSION) and
// reports the test as skipped, never as passed. Catch2 2.x has no SKIP of its own.
#define SDFG_SKIP(reason)                                   \
  do {                                                      \
    std::cout << "SDFG_SKIPPED: " << (reason) << std::endl; \
    return;                                                 \
  } while (false)
