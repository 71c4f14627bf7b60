# The JSON checks the tools' smoke tests share (cmake -P scripts, included with
# include(${CMAKE_CURRENT_LIST_DIR}/json_checks.cmake)).

# require_json_keys(<json> <what> [PATH <member or index>...] KEYS <key>...)
# Fails, naming `what` and the key, unless every key is a member of the object at PATH.
function(require_json_keys json what)
  cmake_parse_arguments(arg "" "" "PATH;KEYS" ${ARGN})
  foreach(key ${arg_KEYS})
    string(JSON v ERROR_VARIABLE e GET "${json}" ${arg_PATH} ${key})
    if(e)
      message(FATAL_ERROR "${what} lacks ${key}: ${e}")
    endif()
  endforeach()
endfunction()

# check_provenance(<json>)
# The commit of the code that wrote the file: a full hash (this is a checkout) or "unknown" (a
# tarball); and whether the tree differed from it (true, false, or null when unknown).
function(check_provenance json)
  string(JSON commit ERROR_VARIABLE err GET "${json}" provenance commit)
  string(LENGTH "${commit}" length)
  string(JSON dirty_type ERROR_VARIABLE err2 TYPE "${json}" provenance tree_dirty)
  if(err OR err2 OR NOT (commit MATCHES "^[0-9a-f]+$" AND length EQUAL 40)
      AND NOT commit STREQUAL "unknown" OR NOT dirty_type MATCHES "^(BOOLEAN|NULL)$")
    message(FATAL_ERROR "provenance: commit \"${commit}\" ${err}, tree_dirty ${dirty_type} ${err2}")
  endif()
endfunction()
