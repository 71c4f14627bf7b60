# Drives autograsp-sdf-scaling like a user, on the CPU builder only (the loader pointed at no
# Vulkan driver, so the run is the same on every machine): --help prints the usage and exits 0,
# bad option values exit 2 naming the value, and a tiny run prints its table under a header that
# names the commit of the code.
# Usage: cmake -DTOOL=<autograsp-sdf-scaling> -DWORK=<scratch dir> -P sdf_scaling_test.cmake
cmake_minimum_required(VERSION 3.25)
if(NOT TOOL OR NOT WORK)
  message(FATAL_ERROR "pass -DTOOL=<executable> -DWORK=<dir>")
endif()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(no_driver "VK_ICD_FILENAMES=${WORK}/no-driver.json" "VK_DRIVER_FILES=${WORK}/no-driver.json")

execute_process(COMMAND "${TOOL}" --help RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "^usage: autograsp-sdf-scaling" OR NOT out MATCHES "--far-band M")
  message(FATAL_ERROR "--help: exit ${rc}\n${out}\n${err}")
endif()

foreach(case "--res;16,1|--res: \"1\" is not 2..128" "--only;both|--only: unknown group \"both\""
    "--runs;five|--runs: \"five\" is not an integer" "--far-band;-1|--far-band: \"-1\" is not a"
    "--bogus|not expected: --bogus" "--meshes|--meshes")
  string(REPLACE "|" ";" parts "${case}")
  list(POP_BACK parts message)
  execute_process(COMMAND "${TOOL}" ${parts} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
  string(FIND "${err}" "${message}" at)
  if(NOT rc EQUAL 2 OR at EQUAL -1 OR NOT err MATCHES "usage: autograsp-sdf-scaling")
    message(FATAL_ERROR "\"${parts}\" exited ${rc}, expected 2 with \"${message}\" and usage:\n${err}")
  endif()
endforeach()

execute_process(COMMAND "${CMAKE_COMMAND}" -E env ${no_driver} "${TOOL}" --quick --runs 1 --res 8
  --only torus RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the CPU-only run exited ${rc}\n${out}\n${err}")
endif()
if(NOT out MATCHES "\n# code at commit ([0-9a-f]+ \\((clean|modified)|unknown )")
  message(FATAL_ERROR "the output does not name the commit of the code:\n${out}")
endif()
string(REGEX MATCHALL "\n\\| torus-[0-9]+ \\| [0-9]+ \\| 8\\^3 \\| [0-9.]+ \\|" rows "${out}")
list(LENGTH rows n)
if(n LESS 3)
  message(FATAL_ERROR "expected a row per torus at 8^3 with a CPU time, found ${n}:\n${out}")
endif()
message(STATUS "autograsp-sdf-scaling CLI checks passed")
