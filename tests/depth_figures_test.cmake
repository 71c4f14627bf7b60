# The depth scene's grasp figures (autograsp-depth-figures, docs/depth.md), deterministic for the
# seed: 40 reaches per object and kind, and every figure held to what it was at the commit that
# set these bounds (a few hundredths of a millimetre over it), so a change that worsens one fails.
# The issue's targets are 95 % made and a penetration p99 of 2 mm; the mug's reaches from above
# miss the first (the fingers that wrap behind it stop on the solid assumed behind what is seen).
# Inputs: -DTOOL=<autograsp-depth-figures> -DWORK=<scratch folder>
include(${CMAKE_CURRENT_LIST_DIR}/json_checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${TOOL} --placements 40 --json ${WORK}/depth.json
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "autograsp-depth-figures failed (${rc}):\n${out}\n${err}")
endif()
message(STATUS "\n${out}")
file(READ ${WORK}/depth.json json)
require_json_keys("${json}" "JSON" KEYS tool provenance placements seed rows)
check_provenance("${json}")

# object reach made-at-least p99-at-most max-at-most median-at-most
set(bounds
  "mug above 25 1.75 1.85 1.05"
  "mug side 40 1.80 2.00 1.10"
  "torus above 40 0.65 2.85 0.25"
  "thin-plate above 40 0.90 1.00 0.25")
string(JSON count LENGTH "${json}" rows)
foreach(b ${bounds})
  separate_arguments(b)
  list(GET b 0 object)
  list(GET b 1 reach)
  list(GET b 2 made_min)
  list(GET b 3 p99_max)
  list(GET b 4 max_max)
  list(GET b 5 median_max)
  set(found FALSE)
  math(EXPR last "${count} - 1")
  foreach(i RANGE ${last})
    string(JSON o GET "${json}" rows ${i} object)
    string(JSON r GET "${json}" rows ${i} reach)
    if(NOT (o STREQUAL object AND r STREQUAL reach))
      continue()
    endif()
    set(found TRUE)
    string(JSON reaches GET "${json}" rows ${i} reaches)
    string(JSON made GET "${json}" rows ${i} made)
    string(JSON p99 GET "${json}" rows ${i} penetration_p99_mm)
    string(JSON max GET "${json}" rows ${i} penetration_max_mm)
    string(JSON median GET "${json}" rows ${i} residual_median_mm)
    if(NOT reaches EQUAL 40 OR made LESS made_min OR p99 GREATER p99_max OR max GREATER max_max
        OR median GREATER median_max)
      message(FATAL_ERROR "${object}, ${reach}: ${made} of ${reaches} made (at least ${made_min}), "
        "penetration p99 ${p99} mm (at most ${p99_max}), max ${max} mm (at most ${max_max}), "
        "residual median ${median} mm (at most ${median_max})")
    endif()
  endforeach()
  if(NOT found)
    message(FATAL_ERROR "no row for ${object}, ${reach}:\n${out}")
  endif()
endforeach()
