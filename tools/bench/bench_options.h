// autograsp-bench's command line: the options, their usage text and their parser.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sdf_backends.h"

namespace sdfg::bench {

// Exit code of a run that completed without a backend it was asked for (no Vulkan device).
constexpr int kExitBackendUnavailable = 3;

extern const char* const kUsage;

struct Options {
  std::vector<std::string> meshes;
  bool embedded = false;
  bool embeddedOnly = false;
  bool thinPlateSet = false;
  // --approaching: placements from 1 cm inside to 5 cm outside (eval/approaching.h), and the
  // table split by whether the open hand was already inside.
  bool approaching = false;
  // --scenes: also every method in the scenes of eval/scenes.h (each mesh on a table, objects
  // beside, inside and near others), figures in the JSON's "scenes" and the report.
  bool scenes = false;
  bool clearHand = true;  // --clear-hand: "ours" clears the open hand before closing
  // --variants: also each mesh with its vertices split so (io/mesh_variants.h), rows named
  // "<mesh>/<variant>", solved on the variant and measured against the mesh as loaded.
  std::vector<std::string> variants;
  int placements = 1000;
  uint64_t seed = 1;
  std::vector<std::string> methods;
  float da = 0.1f;
  int resolution = 16;
  unsigned threads = 0;
  float sdfFarBand = 0.0f;  // CpuSdfOptions::exactBand of the cpu builder
  bool exactCheck = true;   // pass GraspScene::exact ("ours" checks its stops on the mesh)
  std::vector<std::string> sdfBackends = {tools::kCpuBackend};
  bool sdfBackendsGiven = false;  // else --scaling compares cpu and vulkan
  std::string json;
  std::string report;
  std::string scalingJson;  // the sweep's figures as JSON
  std::string scalingFrom;  // a sweep's JSON to report instead of sweeping again
  bool scaling = false;
  bool scalingQuick = false;
  std::string reportFrom;  // a results JSON to report on instead of running
};

struct UsageError {
  std::string message;
};

// Fills `o` from the arguments; `help` is set for --help. Returns the first usage error.
std::optional<UsageError> parseOptions(int argc, char** argv, Options& o, bool& help);

}  // namespace sdfg::bench
