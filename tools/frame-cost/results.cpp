#include "results.h"

#include <algorithm>
#include <cmath>
#include <thread>

namespace sdfg::frame_cost {

namespace {

// A phase's time added by the layer, beside the layer-off run's own frame totals.
tools::Json phaseJson(const Percentiles& added, const Percentiles& off) {
  using tools::jsonNumber;
  return {{"frames", added.count},
          {"added_p50_ms", jsonNumber(added.p50)},
          {"added_p99_ms", jsonNumber(added.p99)},
          {"added_max_ms", jsonNumber(added.max)},
          {"off_median_ms", jsonNumber(off.p50)},
          {"off_p99_ms", jsonNumber(off.p99)},
          {"off_max_ms", jsonNumber(off.max)}};
}

// Each OpenXR call's own time with the layer on.
tools::Json callsJson(const std::map<std::string, std::vector<double>>& callMs) {
  using tools::jsonNumber;
  tools::Json calls = tools::Json::object();
  for (const auto& [name, v] : callMs) {
    const Percentiles c = percentiles(v);
    calls[name] = {{"p50_ms", jsonNumber(c.p50)},
                   {"p99_ms", jsonNumber(c.p99)},
                   {"max_ms", jsonNumber(c.max)}};
  }
  return calls;
}

}  // namespace

Percentiles addedOver(const std::vector<double>& frameMs, double offMedianMs) {
  std::vector<double> added;
  added.reserve(frameMs.size());
  for (double v : frameMs) added.push_back(v - offMedianMs);
  return percentiles(std::move(added));
}

tools::Json resultsJson(const std::vector<MeshResult>& results, int phaseFrames,
                        double framePeriodMs, const std::vector<std::string>& skipped,
                        const OuterResult* outer, const SessionInfo* session) {
  using tools::Json;
  using tools::jsonNumber;
  const bool vulkan = session != nullptr && session->session == "vulkan";
  Json out;
  out["tool"] = "autograsp-frame-cost";
  if (vulkan) {
    // Which device made the figures: a GPU's and lavapipe's differ by orders of magnitude.
    out["session"] = session->session;
    out["target"] = session->target;
    out["gpu"] = session->gpu;
    out["vulkan_device"] = session->vulkanDevice;
    out["vulkan_device_type"] = session->vulkanDeviceType;
  }
  out["frames_per_phase"] = phaseFrames;
  out["frame_period_ms"] = jsonNumber(framePeriodMs);
  out["hardware_threads"] = std::thread::hardware_concurrency();
  out["provenance"] = tools::provenanceJson();
  out["skipped"] = skipped;
  Json& meshes = out["meshes"] = Json::array();
  for (const MeshResult& r : results) {
    Json m;
    m["name"] = r.name;
    m["triangles"] = r.triangles;
    m["ok"] = r.ok;
    m["error"] = r.error;
    m["create_call_ms"] = jsonNumber(r.on.createMs);
    m["setup_ms"] = jsonNumber(r.on.setupMs);
    m["max_vertex_update_call_ms"] = jsonNumber(r.on.maxUpdateCallMs);
    m["grab_latency_frames"] = r.on.grabLatencyFrames;
    if (vulkan) {
      m["gpu_prepare_ms"] = jsonNumber(r.on.gpuPrepareMs);
      m["grasp_backend"] = r.on.graspBackend;
      m["gpu_failed"] = r.on.gpuFailed;
    }
    Json& phases = m["phases"] = Json::object();
    for (int p = 0; p < kPhaseCount; ++p) {
      Json& phase = phases[kPhases[p]] = phaseJson(r.added[p], r.offStats[p]);
      phase["cpu_builds"] = r.on.builds[p];
      if (vulkan) phase["gpu_builds"] = r.on.gpuBuilds[p];
    }
    m["calls_on"] = callsJson(r.on.callMs);
    meshes.push_back(std::move(m));
  }
  if (outer != nullptr) {
    const OuterResult& r = *outer;
    Json o;
    o["targets"] = r.targets;
    o["in_hand_box"] = r.inHandBox;
    o["ok"] = r.ok;
    o["error"] = r.error;
    o["create_calls_total_ms"] = jsonNumber(r.on.createTotalMs);
    o["create_call_max_ms"] = jsonNumber(r.on.createMaxMs);
    o["setup_ms"] = jsonNumber(r.on.setupMs);
    if (vulkan) o["target"] = "arrays";  // the outer hand keeps hands out of CPU meshes only
    Json& phases = o["phases"] = Json::object();
    for (int p = 0; p < kOuterPhaseCount; ++p) {
      Json& phase = phases[kOuterPhases[p]] = phaseJson(r.added[p], r.offStats[p]);
      phase["hand_moved_frames"] = r.on.movedFrames[p];
      phase["outer_hand_off_added_p50_ms"] = jsonNumber(r.addedWithoutOuter[p].p50);
      phase["outer_hand_off_added_p99_ms"] = jsonNumber(r.addedWithoutOuter[p].p99);
      phase["outer_hand_off_added_max_ms"] = jsonNumber(r.addedWithoutOuter[p].max);
      phase["outer_hand_off_hand_moved_frames"] = r.onWithoutOuter.movedFrames[p];
    }
    o["calls_on"] = callsJson(r.on.callMs);
    out["outer"] = std::move(o);
  }
  return out;
}

}  // namespace sdfg::frame_cost
