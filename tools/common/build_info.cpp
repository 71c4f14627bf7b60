#include "build_info.h"

namespace sdfg::tools {

std::string describeCommit(const std::string& commit, std::optional<bool> dirty) {
  if (commit.empty() || commit == "unknown") return "unknown (not built from a git checkout)";
  if (!dirty) return commit + " (whether tracked files were modified is not known)";
  return commit + (*dirty ? " (modified: tracked files differed from the commit)" : " (clean)");
}

std::string describeBuild() {
  const TreeState state = buildTreeState();
  return describeCommit(buildCommit(), state == TreeState::unknown
                                           ? std::nullopt
                                           : std::optional<bool>(state == TreeState::dirty));
}

}  // namespace sdfg::tools
