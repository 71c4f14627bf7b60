// autograsp-doctor: says whether the SDF Autograsp layer is live for this user's OpenXR apps, and
// why not when it is not (docs/layer.md, "Is it on?"). Exit status 0 when it is live, 1 when it
// is not, 2 for a bad command line.
#include <cstdio>
#include <string>

#include "doctor.h"
#include "report.h"

namespace {

constexpr const char* kUsage =
    "usage: autograsp-doctor [--json] [--loader PATH]\n"
    "\n"
    "Checks, through the Khronos OpenXR loader as an app sees it, whether the SDF Autograsp\n"
    "layer (XR_APILAYER_SDFG_autograsp) is live: the active runtime, the API layers and their\n"
    "order, the layer's manifest and disable switch, whether hands come from the runtime or\n"
    "from the layer, where a Vulkan session builds its SDFs, and the layer's configuration.\n"
    "\n"
    "  --json         one JSON object on standard output instead of text\n"
    "  --loader PATH  the OpenXR loader library to use (default: the system's, as apps load it)\n"
    "  -h, --help     this text\n"
    "\n"
    "Exit status: 0 the layer is live, 1 it is not (the first line says why), 2 bad usage.\n";

}  // namespace

int main(int argc, char** argv) {
  bool json = false;
  sdfg::doctor::Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--json") {
      json = true;
    } else if (arg == "--loader" && i + 1 < argc) {
      options.loader = argv[++i];
    } else if (arg == "-h" || arg == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else {
      std::fprintf(stderr, "autograsp-doctor: unknown or incomplete option '%s'\n\n%s", arg.c_str(),
                   kUsage);
      return 2;
    }
  }
  const sdfg::doctor::Report report = sdfg::doctor::examine(options);
  const std::string text =
      json ? sdfg::doctor::reportJson(report) : sdfg::doctor::reportText(report);
  std::fputs(text.c_str(), stdout);
  return report.live ? 0 : 1;
}
