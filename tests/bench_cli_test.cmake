# Drives the built autograsp-bench like a user: a short run writes JSON with every key and finite
# numbers; --exact-check off leaves the exact check out of the "ours" rows; a broken mesh file is
# named, skipped, and the rest still runs; bad option values are a usage error (exit 2);
# --sdf-backend vulkan without a device leaves its rows out and exits 3; --scenes writes every
# method's scene figures; --variants adds a row per split-vertex variant of each object.
# With -DPART=vulkan (a Vulkan device, e.g. lavapipe): --sdf-backend cpu,vulkan gives both rows
# with finite figures, and --scaling-quick both columns; no device prints SDFG_SKIPPED.
# Usage: cmake -DBENCH=<autograsp-bench> -DWORK=<scratch dir> [-DPART=vulkan] -P bench_cli_test.cmake
cmake_minimum_required(VERSION 3.25)
if(NOT BENCH OR NOT WORK)
  message(FATAL_ERROR "pass -DBENCH=<executable> -DWORK=<dir>")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/json_checks.cmake)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

# Checks one row of the JSON: every key present, numbers are numbers (or null where allowed).
function(check_row json i expected_grasps)
  foreach(key mesh method sdf_backend)
    string(JSON type ERROR_VARIABLE err TYPE "${json}" rows ${i} ${key})
    if(NOT type STREQUAL "STRING")
      message(FATAL_ERROR "row ${i}: \"${key}\" is ${type} ${err}, expected a string")
    endif()
  endforeach()
  foreach(key triangles grasps early_stops)
    string(JSON type ERROR_VARIABLE err TYPE "${json}" rows ${i} ${key})
    if(NOT type STREQUAL "NUMBER")
      message(FATAL_ERROR "row ${i}: \"${key}\" is ${type} ${err}, expected a number")
    endif()
  endforeach()
  string(JSON grasps GET "${json}" rows ${i} grasps)
  if(NOT grasps EQUAL expected_grasps)
    message(FATAL_ERROR "row ${i}: ${grasps} grasps, expected ${expected_grasps}")
  endif()
  string(JSON backend GET "${json}" rows ${i} sdf_backend)
  # Always measured: solve time, penetration, contacts; SDF build only for the SDF methods.
  set(required "solve_us median" "solve_us p95" "penetration_mm p99" "penetration_mm max"
               "contacts_mean")
  set(optional "tip_residual_mm median" "tip_residual_mm p95")
  if(backend STREQUAL "cpu" OR backend STREQUAL "vulkan")
    list(APPEND required "sdf_build_ms median" "sdf_build_ms p95")
  elseif(backend STREQUAL "none")
    list(APPEND optional "sdf_build_ms median" "sdf_build_ms p95")
  else()
    message(FATAL_ERROR "row ${i}: sdf_backend \"${backend}\" is not cpu, vulkan or none")
  endif()
  foreach(path IN LISTS required optional)
    string(REPLACE " " ";" keys "${path}")
    string(JSON type ERROR_VARIABLE err TYPE "${json}" rows ${i} ${keys})
    if(err)
      message(FATAL_ERROR "row ${i}: missing ${path}: ${err}")
    endif()
    if(path IN_LIST required AND NOT type STREQUAL "NUMBER")
      message(FATAL_ERROR "row ${i}: ${path} is ${type}, expected a finite number")
    endif()
    if(NOT type STREQUAL "NUMBER" AND NOT type STREQUAL "NULL")
      message(FATAL_ERROR "row ${i}: ${path} is ${type}")
    endif()
  endforeach()
endfunction()

# check_row on every row.
function(check_rows json expected_grasps)
  string(JSON rows LENGTH "${json}" rows)
  math(EXPR last "${rows} - 1")
  foreach(i RANGE ${last})
    check_row("${json}" ${i} ${expected_grasps})
  endforeach()
endfunction()

# Every row's backend, as "mesh/method/backend" entries of `out_var`.
function(row_keys json out_var)
  string(JSON rows LENGTH "${json}" rows)
  set(keys "")
  if(rows GREATER 0)
    math(EXPR last "${rows} - 1")
    foreach(i RANGE ${last})
      string(JSON mesh GET "${json}" rows ${i} mesh)
      string(JSON method GET "${json}" rows ${i} method)
      string(JSON backend GET "${json}" rows ${i} sdf_backend)
      list(APPEND keys "${mesh}/${method}/${backend}")
    endforeach()
  endif()
  set(${out_var} "${keys}" PARENT_SCOPE)
endfunction()

if(PART STREQUAL "vulkan")
  # A. Both backends on the same placements: one row per SDF method and backend, finite figures.
  execute_process(COMMAND "${BENCH}" --embedded-only --placements 3 --seed 2 --methods
    paper,physics-mesh --sdf-backend cpu,vulkan --json "${WORK}/vk.json"
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 3 AND err MATCHES "no Vulkan device")
    message(STATUS "SDFG_SKIPPED: no Vulkan device for --sdf-backend vulkan")
    return()
  endif()
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "--sdf-backend cpu,vulkan exited ${rc}\n${out}\n${err}")
  endif()
  file(READ "${WORK}/vk.json" json)
  row_keys("${json}" keys)
  foreach(mesh mug torus thin-plate)
    foreach(key "${mesh}/paper/cpu" "${mesh}/paper/vulkan" "${mesh}/physics-mesh/none")
      if(NOT key IN_LIST keys)
        message(FATAL_ERROR "no row ${key}; rows: ${keys}")
      endif()
    endforeach()
  endforeach()
  list(LENGTH keys n)
  if(NOT n EQUAL 9)
    message(FATAL_ERROR "expected 9 rows (3 objects x paper/cpu, paper/vulkan, physics), got ${keys}")
  endif()
  check_rows("${json}" 3)
  # The text tables tell the rows apart by backend.
  if(NOT out MATCHES "\nsdf build \\(ms\\) +vulkan +[0-9.]+" OR NOT out MATCHES "\npaper +vulkan +[0-9.]+")
    message(FATAL_ERROR "the text tables show no vulkan rows:\n${out}")
  endif()

  # A2. "ours" with the vulkan backend adds buffer-target rows (eval/buffer_scene.h): each mesh
  # alone, then every scene, as "buffer_targets", method "ours/buffers", every placement graded.
  execute_process(COMMAND "${BENCH}" --embedded-only --placements 3 --seed 2 --methods ours
    --sdf-backend vulkan --scenes --json "${WORK}/vk-buffers.json"
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "--methods ours --sdf-backend vulkan --scenes exited ${rc}\n${out}\n${err}")
  endif()
  file(READ "${WORK}/vk-buffers.json" json)
  string(JSON n_buffers LENGTH "${json}" buffer_targets)
  string(JSON n_scenes LENGTH "${json}" scenes)
  math(EXPR expected "${n_scenes} + 3")
  if(NOT n_buffers EQUAL expected)
    message(FATAL_ERROR "expected ${expected} buffer-target rows (3 alone, ${n_scenes} scenes), got ${n_buffers}")
  endif()
  math(EXPR last "${n_buffers} - 1")
  foreach(i RANGE ${last})
    string(JSON scene GET "${json}" buffer_targets ${i} scene)
    string(JSON method GET "${json}" buffer_targets ${i} method)
    string(JSON grasps GET "${json}" buffer_targets ${i} grasps)
    if(NOT method STREQUAL "ours/buffers" OR NOT grasps EQUAL 3)
      message(FATAL_ERROR "buffer row ${i} (${scene}): method ${method}, ${grasps} grasps")
    endif()
  endforeach()
  string(JSON first GET "${json}" buffer_targets 0 scene)
  if(NOT first STREQUAL "mug/alone" OR NOT out MATCHES "\nBuffer targets: ")
    message(FATAL_ERROR "buffer rows: first ${first}, or no table:\n${out}")
  endif()

  # B. The quick sweep prints the CPU and Vulkan columns side by side, with numbers in both.
  execute_process(COMMAND "${BENCH}" --embedded-only --placements 1 --methods paper
    --scaling-quick RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "--scaling-quick exited ${rc}\n${out}\n${err}")
  endif()
  string(FIND "${out}" "| CPU build (ms) | Vulkan build (ms) | CPU / Vulkan |" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "--scaling-quick lacks the CPU and Vulkan columns:\n${out}")
  endif()
  set(num "[0-9][0-9.e+-]*")
  string(REGEX MATCHALL "\n\\| torus-[0-9]+ \\| [0-9,]+ \\| ${num} \\| ${num} \\| ${num} \\| ${num} \\|" sweep "${out}")
  list(LENGTH sweep n)
  if(n LESS 3)
    message(FATAL_ERROR "expected 3 sweep rows with CPU and Vulkan times, found ${n}:\n${out}")
  endif()
  message(STATUS "autograsp-bench Vulkan backend checks passed")
  return()
endif()

# 1. A short run over the embedded objects.
execute_process(COMMAND "${BENCH}" --embedded-only --placements 5 --seed 3 --json "${WORK}/out.json"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "embedded run exited ${rc}\n${out}\n${err}")
endif()
file(READ "${WORK}/out.json" json)
string(JSON placements GET "${json}" placements)
string(JSON seed GET "${json}" seed)
if(NOT placements EQUAL 5 OR NOT seed EQUAL 3)
  message(FATAL_ERROR "placements ${placements} / seed ${seed}, expected 5 / 3")
endif()
string(JSON rows LENGTH "${json}" rows)
if(rows LESS 3)
  message(FATAL_ERROR "only ${rows} rows for three embedded objects")
endif()
check_rows("${json}" 5)
check_provenance("${json}")
if(NOT out MATCHES "Solve time per grasp" OR NOT out MATCHES "Quality")
  message(FATAL_ERROR "tables missing from the output:\n${out}")
endif()

# 1b. --exact-check: on by default ("ours" rows carry the check's time and samples); off runs
# "ours" on the SDF alone, so its rows have none, and the JSON says which it was.
function(ours_check_keys json out_var)
  set(found "")
  string(JSON rows LENGTH "${json}" rows)
  math(EXPR last "${rows} - 1")
  foreach(i RANGE ${last})
    string(JSON method GET "${json}" rows ${i} method)
    if(method STREQUAL "ours")
      string(JSON type ERROR_VARIABLE err TYPE "${json}" rows ${i} check_us)
      if(err)
        set(type "none")
      endif()
      list(APPEND found "${type}")
    endif()
  endforeach()
  set(${out_var} "${found}" PARENT_SCOPE)
endfunction()
string(JSON exact GET "${json}" exact_check)
ours_check_keys("${json}" types)
if(NOT exact STREQUAL "ON" OR NOT types STREQUAL "OBJECT;OBJECT;OBJECT")
  message(FATAL_ERROR "default run: exact_check ${exact}, ours check_us types \"${types}\"")
endif()
execute_process(COMMAND "${BENCH}" --embedded-only --placements 3 --methods ours --exact-check off
  --json "${WORK}/field-only.json" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "--exact-check off exited ${rc}\n${out}\n${err}")
endif()
file(READ "${WORK}/field-only.json" json)
string(JSON exact GET "${json}" exact_check)
ours_check_keys("${json}" types)
if(NOT exact STREQUAL "OFF" OR NOT types STREQUAL "none;none;none"
    OR NOT err MATCHES "--exact-check off")
  message(FATAL_ERROR "--exact-check off: exact_check ${exact}, ours check_us types \"${types}\"")
endif()
check_rows("${json}" 3)

# 1c. --approaching: the open hand may start inside; the table splits the grasps by that, and
# --clear-hand is on or off, nothing else.
execute_process(COMMAND "${BENCH}" --embedded-only --placements 8 --seed 4 --methods ours
  --approaching RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "--approaching exited ${rc}\n${out}\n${err}")
endif()
foreach(split all inside clear)
  if(NOT out MATCHES "\\| mug \\| ours \\| [0-9]+ \\| ${split} \\|")
    message(FATAL_ERROR "--approaching: no '${split}' line for the mug\n${out}")
  endif()
endforeach()
execute_process(COMMAND "${BENCH}" --embedded-only --placements 1 --methods ours --clear-hand maybe
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2)
  message(FATAL_ERROR "--clear-hand maybe: exit ${rc}, expected 2 (usage)\n${err}")
endif()

# 1e. --variants: each object again with its vertices split (soup, flat, seams), one row per
# variant and method named "<object>/<variant>", on the object's placements; the JSON says which.
execute_process(COMMAND "${BENCH}" --embedded-only --placements 3 --seed 2 --methods
  ours,physics-mesh --variants soup,flat,seams --json "${WORK}/variants.json"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "--variants exited ${rc}\n${out}\n${err}")
endif()
file(READ "${WORK}/variants.json" json)
row_keys("${json}" keys)
foreach(mesh mug torus thin-plate)
  foreach(variant "" /soup /flat /seams)
    foreach(key "${mesh}${variant}/ours/cpu" "${mesh}${variant}/physics-mesh/none")
      if(NOT key IN_LIST keys)
        message(FATAL_ERROR "--variants: no row ${key}; rows: ${keys}")
      endif()
    endforeach()
  endforeach()
endforeach()
list(LENGTH keys n)
if(NOT n EQUAL 24)
  message(FATAL_ERROR "--variants: expected 24 rows (3 objects x 4 meshes x 2 methods): ${keys}")
endif()
check_rows("${json}" 3)
string(JSON variants GET "${json}" variants)
if(NOT variants STREQUAL "[ \"soup\", \"flat\", \"seams\" ]")
  message(FATAL_ERROR "--variants: the JSON's \"variants\" is ${variants}")
endif()
# Without --variants the JSON has no such key (the earlier run's out.json).
file(READ "${WORK}/out.json" json)
string(JSON variants ERROR_VARIABLE err GET "${json}" variants)
if(NOT err)
  message(FATAL_ERROR "a run without --variants wrote \"variants\": ${variants}")
endif()

# 1d. --scenes: every method in every embedded scene, with the scene figures in the JSON and the
# table; the names of the scenes of several objects are there.
execute_process(COMMAND "${BENCH}" --embedded-only --placements 3 --seed 2 --scenes
  --json "${WORK}/scenes.json" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "--scenes exited ${rc}\n${out}\n${err}")
endif()
file(READ "${WORK}/scenes.json" json)
string(JSON count LENGTH "${json}" scenes)
# 3 embedded objects on a table + 5 scenes of several objects, 4 methods each.
if(NOT count EQUAL 32)
  message(FATAL_ERROR "--scenes: ${count} scene rows, expected 32\n${err}")
endif()
set(names "")
math(EXPR last "${count} - 1")
foreach(i RANGE ${last})
  string(JSON scene GET "${json}" scenes ${i} scene)
  list(APPEND names "${scene}")
  string(JSON grasps GET "${json}" scenes ${i} grasps)
  if(NOT grasps EQUAL 3)
    message(FATAL_ERROR "--scenes: row ${i} (${scene}) has ${grasps} grasps, expected 3")
  endif()
  foreach(path "other_penetration_mm p99" "other_penetration_mm max" "wrong_object"
               "facing_graspable" "held_nothing" "contacts_mean" "penetration_mm max")
    string(REPLACE " " ";" keys "${path}")
    string(JSON type ERROR_VARIABLE jerr TYPE "${json}" scenes ${i} ${keys})
    if(NOT type STREQUAL "NUMBER")
      message(FATAL_ERROR "--scenes: row ${i} (${scene}): ${path} is ${type} ${jerr}")
    endif()
  endforeach()
endforeach()
foreach(scene mug/table torus/table thin-plate/table mug-beside-mug mug-near-mug ruler-on-table
              spoon-in-mug mug-handle-wall)
  if(NOT scene IN_LIST names)
    message(FATAL_ERROR "--scenes: no rows for ${scene}")
  endif()
  if(NOT out MATCHES "${scene} +ours ")
    message(FATAL_ERROR "--scenes: no table line for ${scene} / ours\n${out}")
  endif()
endforeach()

# 2. A broken file is named and skipped; the good file after it still runs; exit non-zero.
file(WRITE "${WORK}/broken.obj" "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
file(WRITE "${WORK}/cube.obj" "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
  "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
  "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
  "f 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n")
execute_process(COMMAND "${BENCH}" --mesh "${WORK}/broken.obj" --mesh "${WORK}/missing.ply"
  --mesh "${WORK}/cube.obj" --placements 3 --methods paper --json "${WORK}/out2.json"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "a broken mesh file still gave exit code 0\n${err}")
endif()
if(NOT err MATCHES "broken\\.obj" OR NOT err MATCHES "missing\\.ply")
  message(FATAL_ERROR "the failing files are not named on stderr:\n${err}")
endif()
file(READ "${WORK}/out2.json" json)
string(JSON rows LENGTH "${json}" rows)
string(JSON mesh GET "${json}" rows 0 mesh)
if(NOT rows EQUAL 1 OR NOT mesh STREQUAL "cube")
  message(FATAL_ERROR "expected one row for cube after the broken files, got ${rows} (${mesh})")
endif()
check_row("${json}" 0 3)

# 3. Bad option values are usage errors: out of range, not decimal (010 and 0x10 are not read as
# octal or hexadecimal), a negative seed, two values after a single --mesh.
foreach(args "--placements;abc" "--methods;nope" "--resolution;1" "--da;0" "--bogus"
    "--sdf-backend;gpu" "--sdf-backend;," "--exact-check;maybe" "--exact-check"
    "--placements;0x10" "--seed;-1" "--da;nan" "--mesh;a.obj;b.obj" "--json;"
    "--variants;welded")
  execute_process(COMMAND "${BENCH}" ${args} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "usage")
    message(FATAL_ERROR "\"${args}\" exited ${rc}, expected 2 with usage:\n${err}")
  endif()
endforeach()
execute_process(COMMAND "${BENCH}" --sdf-backend cpu,gpu RESULT_VARIABLE rc OUTPUT_QUIET
  ERROR_VARIABLE err)
if(NOT err MATCHES "unknown backend \"gpu\"")
  message(FATAL_ERROR "a bad backend name is not named:\n${err}")
endif()

# 4. No Vulkan device (the loader pointed at no driver): the vulkan rows are left out, not
# faked, stderr says why, and the exit code is 3; the cpu and physics rows are all there.
execute_process(COMMAND "${CMAKE_COMMAND}" -E env "VK_ICD_FILENAMES=${WORK}/no-driver.json"
  "VK_DRIVER_FILES=${WORK}/no-driver.json" "${BENCH}" --embedded-only --placements 2
  --methods paper,physics-mesh --sdf-backend cpu,vulkan --json "${WORK}/novk.json"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 3 OR NOT err MATCHES "vulkan: no Vulkan device")
  message(FATAL_ERROR "no device: exit ${rc} (expected 3), stderr:\n${err}")
endif()
file(READ "${WORK}/novk.json" json)
row_keys("${json}" keys)
if(NOT keys STREQUAL "mug/paper/cpu;mug/physics-mesh/none;torus/paper/cpu;torus/physics-mesh/none;thin-plate/paper/cpu;thin-plate/physics-mesh/none")
  message(FATAL_ERROR "no device: unexpected rows ${keys}")
endif()
message(STATUS "autograsp-bench CLI checks passed")
