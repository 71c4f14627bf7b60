// Configuration of the layer, read once per instance: built-in defaults, then the file
// $XDG_CONFIG_HOME/sdfg-autograsp/config (default ~/.config/sdfg-autograsp/config; on Windows
// %APPDATA%\sdfg-autograsp\config; platform.h; lines
// "key = value", '#' comments), then environment variables SDFG_AUTOGRASP_<KEY> (key in upper
// case), which win. Keys and meanings: docs/layer.md. Bad values are logged and ignored.
#pragma once

#include <string>

#include "log.h"

namespace sdfg::layer {

struct Config {
  LogLevel logLevel = LogLevel::warn;  // log_level
  std::string solver = "default";      // solver: default, paper, ours, or a core strategy name
  float grabThreshold = 0.7f;          // grab_threshold: squeeze that starts a grab
  float releaseRatio = 0.8f;           // release_ratio: a grab ends below threshold * ratio
  unsigned resolution = 16;            // resolution: grid nodes per axis, 2..128
  float curlStep = 0.02f;              // curl_step: solver step along each finger curve
  bool exactCheck = true;              // exact_check: "ours" checks stops on the exact mesh
  // build_time_limit_ms: a CPU grab-box build running longer is given up (the hand stays open
  // until released, with one log line); 1..600000.
  unsigned buildTimeLimitMs = 1000;
  // sdf_far_band: CPU builds keep nodes within this many node spacings (of the configured box)
  // of the surface exact and may give farther ones a certified lower bound (CpuSdfOptions); 0:
  // every node exact.
  float sdfFarBand = 2.0f;
  bool synthesis = true;  // synthesis: offer XR_EXT_hand_tracking from controllers
  // attach_alone: for an app that makes synthesized hand trackers but has attached no action
  // sets by its first frame, attach the layer's set alone so the controllers drive the hands.
  // Off by default: an app that attaches later is then refused (an action set can be attached
  // once per session), and the layer never turns an app's success into a failure.
  bool attachAlone = false;
  // gpu: where Vulkan sessions build the SDFs of array targets. auto: on the app's device unless
  // it is a CPU implementation (lavapipe, SwiftShader), where the CPU builder is faster and the
  // two would compete for the same cores; on: on the device; off: on the CPU. Targets in the app's
  // Vulkan buffers build on the device unless off.
  enum class Gpu { automatic, on, off };
  Gpu gpu = Gpu::automatic;
  bool extraQueue = true;  // extra_queue: add a queue to Vulkan2 apps' devices when one is spare
  // test_gpu_fault: none, lost_at_submit, lost_at_poll (tests only: a simulated device loss),
  // never_ready (the GPU path never finishes preparing, as if the driver compiled forever),
  // stuck_reads_once (the first removal of a buffer target finds the GPU still reading it)
  std::string testGpuFault = "none";
  // test_layer_fault (the layer's test build only: test_fault.h): none, or the point after a
  // successful call down where the layer throws, to check that it gives back what the runtime
  // made. Always none in the shipped library.
  std::string testLayerFault = "none";
  std::string configPath;  // the file that was read, empty when none
  // Never inside (docs/layer.md, "The hand's clearance"): clear_hand, clear_bound (metres),
  // approach, approach_range (metres), approach_max_angle (degrees), offset_blend_time (s).
  bool clearHand = true;
  float clearBound = 0.03f;
  bool approach = false;
  float approachRange = 0.03f;
  float approachMaxAngle = 30.0f;
  float offsetBlendTime = 0.1f;
  // The outer hand (docs/layer.md, "The outer hand"): outer_hand, outer_release_distance
  // (metres), outer_blend_time (seconds).
  bool outerHand = true;
  float outerReleaseDistance = 0.10f;
  float outerBlendTime = 0.25f;
  // depth_scene (docs/depth.md): the scene from the depth a Vulkan app submits with
  // XR_KHR_composition_layer_depth. auto: for apps that do not use XR_SDFG_auto_grasp (an app
  // that registers its targets has its scene); on: for every app that submits depth, its
  // registered targets and the depth together; off: never (depth swapchains are created exactly
  // as the app asks).
  enum class DepthScene { automatic, on, off };
  DepthScene depthScene = DepthScene::automatic;
};

Config loadConfig();

// Applies one "key = value" pair; returns false (and leaves `config` unchanged) when the key is
// unknown or the value is out of range.
bool applyConfigValue(Config& config, const std::string& key, const std::string& value);

}  // namespace sdfg::layer
