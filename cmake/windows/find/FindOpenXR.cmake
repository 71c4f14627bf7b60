# OpenXR for the Windows cross build. OpenXR::headers: the host's headers, copied (the same
# version the Linux build compiles against). OpenXR::openxr_loader: the Khronos loader built for
# Windows from ../shared/openxr-sdk (tests/windows/openxr_loader.cmake) where that exists.
if(NOT TARGET OpenXR::headers AND EXISTS ${SDFG_HOST_INCLUDE}/openxr)
  add_library(OpenXR::headers INTERFACE IMPORTED GLOBAL)
  set_target_properties(OpenXR::headers PROPERTIES INTERFACE_INCLUDE_DIRECTORIES ${SDFG_HOST_INCLUDE})
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenXR REQUIRED_VARS SDFG_HOST_INCLUDE)
