# Smoke test of autograsp-outer (label core): the short trajectories (--quick), paced at 90 Hz
# through an engine-level GraspSession with the outer hand off and on. Checks the run succeeds
# and its JSON has every key docs/benchmarks-outer.md quotes and the commit of the code, and that
# a bad option is a usage error; the figures are the benchmark's business (and the quality test's,
# outer_quality, which runs unpaced so they are the same every run).
# Inputs: -DTOOL=<autograsp-outer> -DWORK=<scratch folder>
include(${CMAKE_CURRENT_LIST_DIR}/json_checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${TOOL} --quick --json ${WORK}/outer.json --per-frame
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "autograsp-outer failed (${rc}):\n${out}\n${err}")
endif()
set(names table_slide plate_push_2ms plate_push_3ms plate_push_5ms mug_slide ring_swipe_2ms
  ring_swipe_3ms ring_swipe_5ms plate_edge_2ms plate_edge_3ms plate_edge_5ms table_near_still
  table_pressed_still mug_pressed_still table_rise_03ms table_rise_1ms table_rise_2ms
  boxes_pass_15ms plate_rise_2ms box_brought_1ms jump_clear_50cm jump_inside_50cm
  lost_found_in_mug appear_in_mug rest_noise_then_mug)
foreach(name ${names})
  if(NOT out MATCHES "\\| ${name} \\| [0-9]+ \\| [0-9]")
    message(FATAL_ERROR "the table has no row of figures for ${name}:\n${out}")
  endif()
endforeach()
file(READ ${WORK}/outer.json json)
require_json_keys("${json}" "JSON"
  KEYS tool provenance mode frame_period_ms draw_at_ms quick squeeze hardware_threads targets
       trajectories)
string(JSON mode GET "${json}" mode)
if(NOT mode STREQUAL "paced")
  message(FATAL_ERROR "mode ${mode}, expected paced")
endif()
check_provenance("${json}")
string(JSON n LENGTH "${json}" trajectories)
list(LENGTH names expected)
if(NOT n EQUAL expected)
  message(FATAL_ERROR "expected ${expected} trajectories in the JSON, got ${n}")
endif()
math(EXPR last "${n} - 1")
foreach(i RANGE ${last})
  string(JSON name GET "${json}" trajectories ${i} name)
  string(JSON ok GET "${json}" trajectories ${i} ok)
  if(NOT ok)
    message(FATAL_ERROR "${name} failed: ${json}")
  endif()
  require_json_keys("${json}" "${name}" PATH trajectories ${i}
    KEYS frames penetration_mm capsule_penetration_max_mm tracked_depth_max_mm clear_frames
         off_tracking_while_clear_max_mm off_tracking_while_clear_frames keep_out_clear_frames
         off_tracking_while_clear_of_keep_out_max_mm lost_frames withheld_frames
         withheld_longest_run withheld_while_clear_frames clear_jumps
         clear_jump_off_tracking_max_mm still_frames jitter_max_mm
         jitter_settled_max_mm pass_through outer_active_frames on_time_frames cost_on_ms
         cost_off_ms meets_targets meets_targets_outside_keep_out)
  # Every frame of the outer-on run is in the per-frame record.
  string(JSON frames GET "${json}" trajectories ${i} frames)
  string(JSON recorded LENGTH "${json}" trajectories ${i} per_frame shown_clearance_mm)
  if(NOT recorded EQUAL frames)
    message(FATAL_ERROR "${name}: ${recorded} frames recorded of ${frames}")
  endif()
  # A trajectory that never brings the hand near its object measures nothing.
  string(JSON active GET "${json}" trajectories ${i} outer_active_frames)
  if(active EQUAL 0)
    message(FATAL_ERROR "${name}: the outer hand was never active")
  endif()
endforeach()
# The trajectories of issue 36 measure what they say: a jump onto a clear pose, 20 frames lost.
foreach(i RANGE ${last})
  string(JSON name GET "${json}" trajectories ${i} name)
  string(JSON jumps GET "${json}" trajectories ${i} clear_jumps)
  string(JSON lost GET "${json}" trajectories ${i} lost_frames)
  if(name STREQUAL "jump_clear_50cm" AND NOT jumps EQUAL 1)
    message(FATAL_ERROR "jump_clear_50cm: ${jumps} clear jumps, expected 1")
  endif()
  if(name STREQUAL "lost_found_in_mug" AND NOT lost EQUAL 20)
    message(FATAL_ERROR "lost_found_in_mug: ${lost} frames lost, expected 20")
  endif()
endforeach()
# A bad option is a usage error (exit 2) naming the value.
execute_process(COMMAND ${TOOL} --only nowhere RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "unknown trajectory \"nowhere\"" OR NOT err MATCHES "usage")
  message(FATAL_ERROR "--only nowhere: exit ${rc}, expected 2 with usage:\n${err}")
endif()
execute_process(COMMAND ${TOOL} --draw-at 12 RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "--draw-at")
  message(FATAL_ERROR "--draw-at 12: exit ${rc}, expected 2:\n${err}")
endif()
message(STATUS "autograsp-outer JSON complete (${n} trajectories)")
