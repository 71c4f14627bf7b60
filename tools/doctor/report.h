// autograsp-doctor's output: the Report for people (plain text, the verdict first) or for
// scripts (one JSON object; keys in docs/layer.md, "Is it on?").
#pragma once

#include <string>

#include "doctor.h"

namespace sdfg::doctor {

std::string reportText(const Report& report);
std::string reportJson(const Report& report);

}  // namespace sdfg::doctor
