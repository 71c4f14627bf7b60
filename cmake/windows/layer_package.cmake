# The layer for Windows (included by layer/CMakeLists.txt): the implicit manifest beside the DLL
# naming it relatively (the loader resolves library_path against the manifest's folder), and a
# folder to ship: `cmake --install build/windows --prefix <dir>` puts the DLL, its manifest, the
# extension's header and the install scripts in <dir>; scripts/windows/install-layer.bat then
# registers the manifest where the loader looks (docs/windows.md).
sdfg_layer_manifest(${CMAKE_CURRENT_BINARY_DIR}/XrApiLayer_sdfg_autograsp.json
  "./$<TARGET_FILE_NAME:sdfg_layer>" TRUE)
set(SDFG_LAYER_IMPLICIT_JSON ${CMAKE_CURRENT_BINARY_DIR}/XrApiLayer_sdfg_autograsp.json
  PARENT_SCOPE)
set(SDFG_LAYER_DISABLE_ENV ${SDFG_LAYER_DISABLE_ENV} PARENT_SCOPE)
if(TARGET sdfg_layer_test_faults)
  # The layer's test build (test_fault.h), beside it, for the loader tests under Wine; not
  # installed.
  sdfg_layer_manifest(${CMAKE_CURRENT_BINARY_DIR}/XrApiLayer_sdfg_autograsp_test_faults.json
    "./$<TARGET_FILE_NAME:sdfg_layer_test_faults>" TRUE)
  set(SDFG_LAYER_TEST_IMPLICIT_JSON
    ${CMAKE_CURRENT_BINARY_DIR}/XrApiLayer_sdfg_autograsp_test_faults.json PARENT_SCOPE)
endif()
install(TARGETS sdfg_layer RUNTIME DESTINATION . LIBRARY DESTINATION .)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/XrApiLayer_sdfg_autograsp.json DESTINATION .)
install(FILES ${PROJECT_SOURCE_DIR}/scripts/windows/install-layer.bat
  ${PROJECT_SOURCE_DIR}/scripts/windows/uninstall-layer.bat DESTINATION .)
install(FILES ${PROJECT_SOURCE_DIR}/include/openxr/XR_SDFG_auto_grasp.h DESTINATION include/openxr)
