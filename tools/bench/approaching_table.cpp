#include "approaching_table.h"

#include <cmath>
#include <string>

namespace sdfg::bench {
namespace {

std::string mm(double v) {
  if (std::isnan(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

}  // namespace

void printApproachingTable(std::FILE* out, const std::vector<Row>& rows) {
  std::fprintf(out,
               "| mesh | method | grasps | open hand | whole-hand penetration mm p50 / p95 / p99 / "
               "max | hand moved mm median / p95 / max | contacts per grasp | past the bound |\n"
               "|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    if (r.openInside.empty()) continue;
    const char* splits[] = {"all", "inside", "clear"};
    for (int s = 0; s < 3; ++s) {
      std::vector<double> pen, moved;
      long long contacts = 0, past = 0;
      for (size_t i = 0; i < r.openInside.size(); ++i) {
        if (s == 1 && !r.openInside[i]) continue;
        if (s == 2 && r.openInside[i]) continue;
        pen.push_back(r.handPenetrationMm[i]);
        moved.push_back(r.handMovedMm[i]);
        contacts += r.graspContacts[i];
        past += r.pastBound[i];
      }
      const std::string name =
          r.backend == "none" || r.backend == "cpu" ? r.method : r.method + " (" + r.backend + ")";
      std::fprintf(out, "| %s | %s | %zu | %s | %s / %s / %s / %s | %s / %s / %s | %s | %lld |\n",
                   r.mesh.c_str(), name.c_str(), pen.size(), splits[s],
                   mm(percentile(pen, 0.5)).c_str(), mm(percentile(pen, 0.95)).c_str(),
                   mm(percentile(pen, 0.99)).c_str(), mm(percentile(pen, 1.0)).c_str(),
                   mm(percentile(moved, 0.5)).c_str(), mm(percentile(moved, 0.95)).c_str(),
                   mm(percentile(moved, 1.0)).c_str(),
                   pen.empty() ? "-" : mm(double(contacts) / double(pen.size())).c_str(), past);
    }
  }
}

}  // namespace sdfg::bench
