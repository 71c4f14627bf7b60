# Smoke test of autograsp-threads (label layer): small work (--quick), a few frames, one trial of
# each destroy, through the real loader, the mock runtime and the layer. Checks that the run
# succeeds and its JSON has every key docs/threading.md quotes; the figures are the benchmark's
# business, not a test's.
# Inputs: -DTOOL=<autograsp-threads> -DWORK=<scratch folder>
include(${CMAKE_CURRENT_LIST_DIR}/json_checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${TOOL} --quick --frames 20 --trials 1 --json ${WORK}/threads.json
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "autograsp-threads failed (${rc}):\n${out}\n${err}")
endif()
if(NOT out MATCHES "locate p99, slow sync / normal sync")
  message(FATAL_ERROR "no ratio line in the output:\n${out}")
endif()
file(READ ${WORK}/threads.json json)
require_json_keys("${json}" "JSON"
  KEYS provenance frames delay_us hardware_threads locate_normal locate_slow_sync
       locate_p99_ratio destroys)
check_provenance("${json}")
foreach(kind session_during_setup instance_during_setup session_during_build)
  string(JSON trials GET "${json}" destroys ${kind} trials)
  if(NOT trials EQUAL 1)
    message(FATAL_ERROR "${kind}: ${trials} trials ran, expected 1")
  endif()
endforeach()
# The slow run measured what it is for: locates while the main thread was in a sync.
string(JSON during GET "${json}" locate_slow_sync during_sync)
if(during LESS 1)
  message(FATAL_ERROR "none of the slow run's locates overlapped a sync")
endif()
