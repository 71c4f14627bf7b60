# Catch2 v2 (header only) for the Windows cross build: the host's header, copied.
if(NOT TARGET Catch2::Catch2 AND EXISTS ${SDFG_HOST_INCLUDE}/catch2)
  add_library(Catch2::Catch2 INTERFACE IMPORTED GLOBAL)
  set_target_properties(Catch2::Catch2 PROPERTIES INTERFACE_INCLUDE_DIRECTORIES ${SDFG_HOST_INCLUDE})
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Catch2 REQUIRED_VARS SDFG_HOST_INCLUDE)
