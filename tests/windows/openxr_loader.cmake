# The Khronos OpenXR loader for Windows (openxr_loader.dll), built with the same MinGW toolchain
# from the SDK archive under ../shared/openxr-sdk (release 1.1.53, generated sources included).
# Upstream builds it with MSVC only; openxr_loader_mingw.cmake patches what MinGW needs.
# Defines OpenXR::openxr_loader and SDFG_WINDOWS_LOADER_DLL when the archive is there;
# otherwise SDFG_WINDOWS_LOADER_MISSING says why not.
set(SDFG_OPENXR_SDK_ARCHIVE "${SDFG_SHARED_DIR}/openxr-sdk/OpenXR-SDK-1.1.53.tar.xz" CACHE FILEPATH
  "OpenXR SDK source archive the Windows loader is built from")
set(SDFG_WINDOWS_LOADER_JOBS 1 CACHE STRING "Parallel jobs for the loader's build")
if(NOT EXISTS "${SDFG_OPENXR_SDK_ARCHIVE}")
  set(SDFG_WINDOWS_LOADER_MISSING "no OpenXR SDK archive at ${SDFG_OPENXR_SDK_ARCHIVE} (../shared)")
  return()
endif()
include(ExternalProject)
set(_bin ${CMAKE_CURRENT_BINARY_DIR}/openxr_sdk/build)
ExternalProject_Add(sdfg_openxr_loader
  URL "${SDFG_OPENXR_SDK_ARCHIVE}"
  URL_HASH SHA256=0a1ea58c86414386a86b8277a72518fb883856ebb51b9936c92efcb889bebcdd
  DOWNLOAD_EXTRACT_TIMESTAMP ON
  PREFIX ${CMAKE_CURRENT_BINARY_DIR}/openxr_sdk
  BINARY_DIR ${_bin}
  PATCH_COMMAND ${CMAKE_COMMAND} -P ${CMAKE_CURRENT_LIST_DIR}/openxr_loader_mingw.cmake
  CMAKE_GENERATOR Ninja
  CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${CMAKE_TOOLCHAIN_FILE} -DCMAKE_BUILD_TYPE=Release
    -DDYNAMIC_LOADER=ON -DBUILD_TESTS=OFF -DBUILD_API_LAYERS=OFF -DBUILD_CONFORMANCE_TESTS=OFF
    -DBUILD_WITH_SYSTEM_JSONCPP=OFF -Wno-dev
  BUILD_COMMAND ${CMAKE_COMMAND} --build ${_bin} --target openxr_loader -j ${SDFG_WINDOWS_LOADER_JOBS}
  INSTALL_COMMAND ""
  BUILD_BYPRODUCTS ${_bin}/src/loader/libopenxr_loader.dll.a ${_bin}/src/loader/openxr_loader.dll
  LOG_CONFIGURE ON LOG_BUILD ON LOG_OUTPUT_ON_FAILURE ON)
add_library(OpenXR::openxr_loader SHARED IMPORTED GLOBAL)
set_target_properties(OpenXR::openxr_loader PROPERTIES
  IMPORTED_IMPLIB ${_bin}/src/loader/libopenxr_loader.dll.a
  IMPORTED_LOCATION ${_bin}/src/loader/openxr_loader.dll
  INTERFACE_LINK_LIBRARIES OpenXR::headers)
add_dependencies(OpenXR::openxr_loader sdfg_openxr_loader)
set(SDFG_WINDOWS_LOADER_DLL ${_bin}/src/loader/openxr_loader.dll)
