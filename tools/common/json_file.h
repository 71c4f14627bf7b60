// The tools' JSON files: the results docs quote and the bench's report reads back. Written and
// read with nlohmann::json (Debian's nlohmann-json3-dev), so strings are escaped and parsed by a
// library rather than by hand. `Json` is the ordered flavour: members stay in the order the tool
// wrote them, and the bench's report takes its columns in that order.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "base/status.h"

namespace sdfg::tools {

using Json = nlohmann::ordered_json;

// A measured number as the tools write it: rounded to 6 significant digits (no figure of theirs
// carries more), null when not finite.
Json jsonNumber(double v);

// The build that writes a file, for its "provenance" member: {"commit": "<full hash>" or
// "unknown", "tree_dirty": true / false, or null when not known} (build_info.h).
Json provenanceJson();
// describeCommit() of a "provenance" member as provenanceJson() wrote it; nothing when `record`
// is not one (null: the file was written before the tools recorded it).
std::optional<std::string> describeProvenance(const Json& record);

// Writes `value` with a two-space indent and a final newline. Invalid UTF-8 in a string (a file
// name in another encoding) is written as U+FFFD instead of failing. Errors: io_error naming the
// file.
std::optional<Error> writeJsonFile(const std::filesystem::path& file, const Json& value);

// Reads and parses `file`. Errors: io_error naming the file and, for a parse error, where.
Result<Json> readJsonFile(const std::filesystem::path& file);

}  // namespace sdfg::tools
