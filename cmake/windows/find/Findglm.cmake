# GLM for the Windows cross build: the host's headers, copied (cmake/windows/windows.cmake).
if(NOT TARGET glm::glm AND EXISTS ${SDFG_HOST_INCLUDE}/glm)
  add_library(glm::glm INTERFACE IMPORTED GLOBAL)
  set_target_properties(glm::glm PROPERTIES INTERFACE_INCLUDE_DIRECTORIES ${SDFG_HOST_INCLUDE})
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(glm REQUIRED_VARS SDFG_HOST_INCLUDE)
