# What the Windows cross build (preset `windows`, cmake/toolchains/mingw-w64.cmake) needs from the
# host: header-only libraries (GLM, the Vulkan and OpenXR headers, Catch2, and nlohmann/json for
# autograsp-doctor) are platform-neutral, so Debian's copies serve. They are copied into the build
# tree, never put on the include path in place (-I/usr/include would let glibc's headers shadow
# MinGW's). The find modules beside this file give them the target names the Linux build gets
# from find_package.
set(SDFG_HOST_INCLUDE ${CMAKE_BINARY_DIR}/host_include)
foreach(dir glm vulkan vk_video openxr catch2 nlohmann)
  if(EXISTS /usr/include/${dir} AND NOT EXISTS ${SDFG_HOST_INCLUDE}/${dir})
    file(COPY /usr/include/${dir} DESTINATION ${SDFG_HOST_INCLUDE})
  endif()
endforeach()
list(PREPEND CMAKE_MODULE_PATH ${CMAKE_CURRENT_LIST_DIR}/find)

# Nothing offline (mesh importers, physics baseline, tools, examples) is built for Windows: only
# what runs in an app (the layer and the engine), autograsp-doctor (installed with the layer), the
# mock runtime and the layer's tests.
set(SDFG_BUILD_OFFLINE OFF)
set(SDFG_BUILD_TOOLS OFF CACHE BOOL "" FORCE)
set(SDFG_BUILD_EXAMPLES OFF CACHE BOOL "" FORCE)
