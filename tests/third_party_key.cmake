# The name of the folder a third-party build from ../shared lives in (given to its build script
# and to the tests that read its built.stamp): the first 16 hex of the archive's SHA-256, '-', the
# first 8 of the build script's, so a changed fix in the script makes a new build instead of
# reusing one made without it. "absent" without the archive (the build and its tests then report
# themselves skipped).
function(sdfg_third_party_key archive recipe out_var)
  if(EXISTS "${archive}")
    file(SHA256 "${archive}" archive_hash)
    file(SHA256 "${recipe}" recipe_hash)
    string(SUBSTRING "${archive_hash}" 0 16 archive_hash)
    string(SUBSTRING "${recipe_hash}" 0 8 recipe_hash)
    set(${out_var} "${archive_hash}-${recipe_hash}" PARENT_SCOPE)
    # An edited script changes the key: CMake configures again.
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${recipe}")
  else()
    set(${out_var} "absent" PARENT_SCOPE)
  endif()
endfunction()
