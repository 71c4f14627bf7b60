// Which code a tool was built from, so that every results file and report can say which commit
// made its figures. Recorded at build time: tools/common/build_info.cmake runs on every build and
// regenerates the values only when they change (the git commit of the source tree, and whether
// tracked files differed from it; untracked files do not count).
#pragma once

#include <optional>
#include <string>

namespace sdfg::tools {

// The full commit hash of the source tree at build time, or "unknown" (a source tarball, or no
// git on the build machine).
const char* buildCommit();

enum class TreeState {
  clean,    // the tracked files were those of buildCommit()
  dirty,    // some tracked file was modified (or staged) at build time
  unknown,  // no commit known
};
TreeState buildTreeState();

// One line for a report: "<hash> (clean)", "<hash> (modified: tracked files differed from the
// commit)" or "unknown (not built from a git checkout)". `dirty` empty: not known.
std::string describeCommit(const std::string& commit, std::optional<bool> dirty);
// describeCommit() of this build.
std::string describeBuild();

}  // namespace sdfg::tools
