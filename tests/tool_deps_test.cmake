# The tools' own libraries (nlohmann/json and CLI11, found in tools/CMakeLists.txt) stay in the
# tools: no file of what runs in an app (layer/, src/engine/, include/) includes either. They are
# header-only, so an include is all it would take for the layer to carry them.
# Usage: cmake -DSOURCE_DIR=<repository root> -P tool_deps_test.cmake
cmake_minimum_required(VERSION 3.25)
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "pass -DSOURCE_DIR=<repository root>")
endif()
set(found "")
set(checked 0)
foreach(dir layer src/engine include)
  file(GLOB_RECURSE files "${SOURCE_DIR}/${dir}/*.h" "${SOURCE_DIR}/${dir}/*.hpp"
    "${SOURCE_DIR}/${dir}/*.cpp" "${SOURCE_DIR}/${dir}/*.c" "${SOURCE_DIR}/${dir}/*.in")
  foreach(file IN LISTS files)
    math(EXPR checked "${checked} + 1")
    file(STRINGS "${file}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"](nlohmann/|CLI/)")
    foreach(line IN LISTS lines)
      list(APPEND found "${file}: ${line}")
    endforeach()
  endforeach()
endforeach()
if(checked LESS 20)
  message(FATAL_ERROR "only ${checked} files found under layer/, src/engine/, include/: wrong root?")
endif()
if(found)
  string(REPLACE ";" "\n" found "${found}")
  message(FATAL_ERROR "the tools' libraries are included by code that runs in an app:\n${found}")
endif()
message(STATUS "${checked} files of layer/, src/engine/, include/ include neither nlohmann/json nor CLI11")
