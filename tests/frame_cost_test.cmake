# Smoke test of autograsp-frame-cost (label layer): one embedded object, a few frames per phase,
# through the real loader, the mock runtime and the layer. Checks the run succeeds and its JSON
# has every key docs/benchmarks.md quotes and the commit of the code, and that a bad option value
# is a usage error; timings are the benchmark's business, not a test's. The layer and the mock
# runtime moved elsewhere run through --layer-dir and --runtime-json, and a missing one is named.
# With -DPART=vulkan (lavapipe through VK_ICD_FILENAMES): --session vulkan --target buffer, the
# object in the app's Vulkan buffers built on the device; no lavapipe prints SDFG_SKIPPED.
# Inputs: -DTOOL=<autograsp-frame-cost> -DWORK=<scratch folder> -DLAYER_LIB=<the layer's library>
#         -DRUNTIME_LIB=<the mock runtime's library> [-DPART=vulkan]
include(${CMAKE_CURRENT_LIST_DIR}/json_checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

if(PART STREQUAL "vulkan")
  if(NOT EXISTS "$ENV{VK_ICD_FILENAMES}")
    message(STATUS "SDFG_SKIPPED: no lavapipe (VK_ICD_FILENAMES=$ENV{VK_ICD_FILENAMES})")
    return()
  endif()
  execute_process(COMMAND ${TOOL} --session vulkan --target buffer --embedded-only --only mug
    --frames 5 --json ${WORK}/vk.json RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "--session vulkan --target buffer failed (${rc}):\n${out}\n${err}")
  endif()
  if(NOT out MATCHES "\\| mug \\| 1200 \\|" OR NOT out MATCHES "in the app's Vulkan buffers")
    message(FATAL_ERROR "no mug row or no session line:\n${out}")
  endif()
  file(READ ${WORK}/vk.json json)
  require_json_keys("${json}" "JSON" KEYS session target gpu vulkan_device vulkan_device_type)
  string(JSON session GET "${json}" session)
  string(JSON target GET "${json}" target)
  string(JSON device GET "${json}" vulkan_device)
  if(NOT session STREQUAL "vulkan" OR NOT target STREQUAL "buffer" OR NOT device MATCHES "llvmpipe")
    message(FATAL_ERROR "session ${session}, target ${target}, device \"${device}\":\n${json}")
  endif()
  string(JSON ok GET "${json}" meshes 0 ok)
  if(NOT ok)
    message(FATAL_ERROR "the mug run failed: ${json}")
  endif()
  # The grasp's field came from the device: buffer targets have no CPU copy to build from.
  string(JSON backend GET "${json}" meshes 0 grasp_backend)
  string(JSON latency GET "${json}" meshes 0 grab_latency_frames)
  if(NOT backend STREQUAL "vulkan" OR latency LESS 0)
    message(FATAL_ERROR "grasp built by ${backend}, grab latency ${latency}:\n${json}")
  endif()
  set(gpu_builds 0)
  foreach(phase open grab held held_moving held_deforming)
    require_json_keys("${json}" "JSON phase ${phase}" PATH meshes 0 phases ${phase}
      KEYS frames added_p50_ms added_p99_ms added_max_ms cpu_builds gpu_builds)
    string(JSON cpu GET "${json}" meshes 0 phases ${phase} cpu_builds)
    string(JSON gpu GET "${json}" meshes 0 phases ${phase} gpu_builds)
    math(EXPR gpu_builds "${gpu_builds} + ${gpu}")
    if(NOT cpu EQUAL 0)
      message(FATAL_ERROR "${phase}: ${cpu} CPU builds of a buffer target")
    endif()
  endforeach()
  if(gpu_builds LESS 1)
    message(FATAL_ERROR "no GPU build in any phase:\n${json}")
  endif()
  # The deforming phase told the layer of every rewrite.
  string(JSON updates GET "${json}" meshes 0 calls_on xrUpdateGraspTargetVerticesSDFG p99_ms)
  message(STATUS "frame-cost on ${device}: buffer target grasped (latency ${latency} frames, "
                 "${gpu_builds} GPU builds, update call p99 ${updates} ms)")
  return()
endif()

# Headless JSON keys are those of before --session: no session, target or device.
set(headless_absent session target gpu vulkan_device)
execute_process(COMMAND ${TOOL} --embedded-only --only mug --frames 5 --json ${WORK}/fc.json
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "autograsp-frame-cost failed (${rc}):\n${out}\n${err}")
endif()
if(NOT out MATCHES "\\| mug \\| 1200 \\|")
  message(FATAL_ERROR "the table has no row for the mug:\n${out}")
endif()
file(READ ${WORK}/fc.json json)
string(JSON n LENGTH "${json}" meshes)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected 1 mesh in the JSON, got ${n}")
endif()
require_json_keys("${json}" "JSON"
  KEYS frames_per_phase frame_period_ms hardware_threads skipped provenance)
check_provenance("${json}")
foreach(key ${headless_absent})
  string(JSON v ERROR_VARIABLE absent GET "${json}" ${key})
  if(NOT absent)
    message(FATAL_ERROR "a headless run's JSON has ${key}: ${v}")
  endif()
endforeach()
string(JSON ok GET "${json}" meshes 0 ok)
if(NOT ok)
  message(FATAL_ERROR "the mug run failed: ${json}")
endif()
require_json_keys("${json}" "JSON mesh" PATH meshes 0
  KEYS name triangles create_call_ms setup_ms max_vertex_update_call_ms grab_latency_frames
       calls_on)
string(JSON latency GET "${json}" meshes 0 grab_latency_frames)
if(latency LESS 0)
  message(FATAL_ERROR "no grab latency: the grasp never showed")
endif()
# A phase's time added and the layer-off run's own times (the mesh and the outer-hand phases).
set(phase_keys frames added_p50_ms added_p99_ms added_max_ms off_median_ms off_p99_ms off_max_ms)
foreach(phase open grab held held_moving held_deforming)
  require_json_keys("${json}" "JSON phase ${phase}" PATH meshes 0 phases ${phase}
    KEYS ${phase_keys} cpu_builds)
endforeach()
foreach(call xrWaitFrame xrBeginFrame xrSyncActions xrLocateHandJointsEXT xrEndFrame)
  require_json_keys("${json}" "JSON's timing of ${call}" PATH meshes 0 calls_on ${call}
    KEYS p99_ms)
endforeach()
# The outer-hand scenario with a small room: it runs, the outer hand moves the hand while it
# touches (XrGraspHandOffsetSDFG), never with the outer hand switched off, and the JSON is complete.
execute_process(COMMAND ${TOOL} --only outer --room 20 --frames 12 --json ${WORK}/outer.json
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "autograsp-frame-cost --only outer failed (${rc}):\n${out}\n${err}")
endif()
file(READ ${WORK}/outer.json json)
string(JSON n LENGTH "${json}" meshes)
if(NOT n EQUAL 0)
  message(FATAL_ERROR "--only outer measured ${n} objects")
endif()
require_json_keys("${json}" "JSON outer" PATH outer
  KEYS targets in_hand_box ok create_calls_total_ms create_call_max_ms setup_ms calls_on)
string(JSON targets GET "${json}" outer targets)
string(JSON ok GET "${json}" outer ok)
if(NOT targets EQUAL 20 OR NOT ok)
  message(FATAL_ERROR "outer: ${targets} targets (expected 20), ok ${ok}:\n${json}")
endif()
foreach(phase near touching)
  require_json_keys("${json}" "JSON outer phase ${phase}" PATH outer phases ${phase}
    KEYS ${phase_keys} hand_moved_frames outer_hand_off_added_p50_ms outer_hand_off_added_p99_ms
         outer_hand_off_added_max_ms outer_hand_off_hand_moved_frames)
endforeach()
string(JSON moved GET "${json}" outer phases touching hand_moved_frames)
string(JSON movedOff GET "${json}" outer phases touching outer_hand_off_hand_moved_frames)
if(moved EQUAL 0 OR NOT movedOff EQUAL 0)
  message(FATAL_ERROR "touching: the hand moved in ${moved} frames with the outer hand, ${movedOff} without")
endif()
execute_process(COMMAND ${TOOL} --room 4 RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--room")
  message(FATAL_ERROR "--room 4: exit ${rc}, expected 2:\n${err}")
endif()
# The layer and the mock runtime elsewhere, their manifests naming them by relative paths (as
# package-for-device.sh writes them), through --layer-dir and --runtime-json.
get_filename_component(layer_name "${LAYER_LIB}" NAME)
get_filename_component(runtime_name "${RUNTIME_LIB}" NAME)
file(MAKE_DIRECTORY ${WORK}/moved/layer ${WORK}/moved/runtime ${WORK}/broken)
file(CREATE_LINK "${LAYER_LIB}" ${WORK}/moved/layer/${layer_name} SYMBOLIC)
file(CREATE_LINK "${RUNTIME_LIB}" ${WORK}/moved/runtime/${runtime_name} SYMBOLIC)
set(layer_json "{\"file_format_version\": \"1.0.0\", \"api_layer\": {\"name\":
  \"XR_APILAYER_SDFG_autograsp\", \"library_path\": \"./${layer_name}\", \"api_version\": \"1.0\",
  \"implementation_version\": \"1\", \"description\": \"moved\", \"instance_extensions\": [
  {\"name\": \"XR_SDFG_auto_grasp\", \"extension_version\": 3},
  {\"name\": \"XR_EXT_hand_tracking\", \"extension_version\": 4}]}}")
file(WRITE ${WORK}/moved/layer/layer.json "${layer_json}")
file(WRITE ${WORK}/moved/runtime/runtime.json "{\"file_format_version\": \"1.0.0\",
  \"runtime\": {\"name\": \"moved\", \"library_path\": \"./${runtime_name}\"}}")
execute_process(COMMAND ${TOOL} --embedded-only --only mug --frames 3
  --layer-dir ${WORK}/moved/layer --runtime-json ${WORK}/moved/runtime/runtime.json
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "\\| mug \\| 1200 \\| [0-9.]+ ms")
  message(FATAL_ERROR "the moved layer and runtime: exit ${rc}\n${out}\n${err}")
endif()
# A manifest whose library is not there is named, with what to do (exit 2).
string(REPLACE "./${layer_name}" "/nowhere/${layer_name}" broken_json "${layer_json}")
file(WRITE ${WORK}/broken/layer.json "${broken_json}")
execute_process(COMMAND ${TOOL} --only mug --layer-dir ${WORK}/broken
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "/nowhere/${layer_name}, which is not there"
    OR NOT err MATCHES "relative")
  message(FATAL_ERROR "--layer-dir with a missing library: exit ${rc}, expected 2:\n${err}")
endif()
execute_process(COMMAND ${TOOL} --only mug --runtime-json ${WORK}/none.json
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "none.json does not exist")
  message(FATAL_ERROR "--runtime-json missing: exit ${rc}, expected 2:\n${err}")
endif()
# --target buffer needs a Vulkan session (exit 2).
execute_process(COMMAND ${TOOL} --target buffer RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--target buffer: needs --session vulkan")
  message(FATAL_ERROR "--target buffer alone: exit ${rc}, expected 2:\n${err}")
endif()
# A bad option value is a usage error (exit 2) naming the value.
execute_process(COMMAND ${TOOL} --frames 5x RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--frames: \"5x\" is not an integer" OR NOT err MATCHES "usage")
  message(FATAL_ERROR "--frames 5x: exit ${rc}, expected 2 with usage:\n${err}")
endif()
execute_process(COMMAND ${TOOL} --session opengl RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--session: \"opengl\" is not headless or vulkan")
  message(FATAL_ERROR "--session opengl: exit ${rc}, expected 2:\n${err}")
endif()
message(STATUS "frame-cost JSON complete (mug, grab latency ${latency} frames)")
