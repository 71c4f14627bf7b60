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

// A number as the tools write it, null when not finite. A double is kept exactly (nlohmann writes
// the shortest text that reads back to the same double), so a report made from the JSON shows
// the same figures as the run's own (rounding to 6 digits first and to 3 in a table could differ
// in the last digit). A float is written as the shortest text that reads back to the same float:
// 0.1f as 0.1, not as its double 0.10000000149011612.
Json jsonNumber(double v);
Json jsonNumber(float v);

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
