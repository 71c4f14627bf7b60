# Smoke test of autograsp-frame-cost (label layer): one embedded object, a few frames per phase,
# through the real loader, the mock runtime and the layer. Checks the run succeeds and its JSON
# has every key docs/benchmarks.md quotes and the commit of the code, and that a bad option value
# is a usage error; timings are the benchmark's business, not a test's.
# Inputs: -DTOOL=<autograsp-frame-cost> -DWORK=<scratch folder>
include(${CMAKE_CURRENT_LIST_DIR}/json_checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
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
# A bad option value is a usage error (exit 2) naming the value.
execute_process(COMMAND ${TOOL} --frames 5x RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--frames: \"5x\" is not an integer" OR NOT err MATCHES "usage")
  message(FATAL_ERROR "--frames 5x: exit ${rc}, expected 2 with usage:\n${err}")
endif()
message(STATUS "frame-cost JSON complete (mug, grab latency ${latency} frames)")
