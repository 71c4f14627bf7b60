# nlohmann/json for the Windows cross build (autograsp-doctor): the host's header-only library,
# copied (cmake/windows/windows.cmake).
if(NOT TARGET nlohmann_json::nlohmann_json AND EXISTS ${SDFG_HOST_INCLUDE}/nlohmann/json.hpp)
  add_library(nlohmann_json::nlohmann_json INTERFACE IMPORTED GLOBAL)
  set_target_properties(nlohmann_json::nlohmann_json PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES ${SDFG_HOST_INCLUDE})
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(nlohmann_json REQUIRED_VARS SDFG_HOST_INCLUDE)
