# Patch step of the Windows loader build (openxr_loader.cmake), run in the SDK's source folder.
# Upstream's loader CMake knows MSVC on Windows, not MinGW; what MinGW needs:
# - the name: CMake gives MinGW shared libraries a "lib" prefix, but Windows apps load (and
#   link against) openxr_loader.dll; without this the DLL is libopenxr_loader.dll.
# Idempotent: a second run finds the marker and changes nothing.
set(_file src/loader/CMakeLists.txt)
file(READ ${_file} _text)
set(_marker "# sdfg: MinGW names the DLL as MSVC does")
if(NOT _text MATCHES "${_marker}")
  string(APPEND _text "
${_marker}
if(MINGW AND DYNAMIC_LOADER)
    set_target_properties(openxr_loader PROPERTIES PREFIX \"\")
endif()
")
  file(WRITE ${_file} "${_text}")
endif()
