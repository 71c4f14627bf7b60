#include "json_file.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "build_info.h"

namespace sdfg::tools {

Json jsonNumber(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

Json jsonNumber(float v) {
  if (!std::isfinite(v)) return nullptr;
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text - 1, v);  // shortest form
  *end = '\0';
  return std::strtod(text, nullptr);
}

Json provenanceJson() {
  Json out;
  out["commit"] = buildCommit();
  switch (buildTreeState()) {
    case TreeState::clean:
      out["tree_dirty"] = false;
      break;
    case TreeState::dirty:
      out["tree_dirty"] = true;
      break;
    case TreeState::unknown:
      out["tree_dirty"] = nullptr;
      break;
  }
  return out;
}

std::optional<std::string> describeProvenance(const Json& record) {
  if (!record.is_object()) return std::nullopt;
  const auto commit = record.find("commit");
  if (commit == record.end() || !commit->is_string()) return std::nullopt;
  const auto dirty = record.find("tree_dirty");
  return describeCommit(commit->get<std::string>(), dirty != record.end() && dirty->is_boolean()
                                                        ? std::optional<bool>(dirty->get<bool>())
                                                        : std::nullopt);
}

std::optional<Error> writeJsonFile(const std::filesystem::path& file, const Json& value) {
  std::ofstream out(file);
  if (!out) return makeError(Status::io_error, file.string() + ": cannot write");
  out << value.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  out.flush();
  if (!out) return makeError(Status::io_error, file.string() + ": cannot write");
  return std::nullopt;
}

Result<Json> readJsonFile(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) return makeError(Status::io_error, file.string() + ": cannot read");
  std::stringstream text;
  text << in.rdbuf();
  try {
    return Json::parse(text.str());
  } catch (const Json::parse_error& e) {
    return makeError(Status::io_error, file.string() + ": " + e.what());
  }
}

}  // namespace sdfg::tools
