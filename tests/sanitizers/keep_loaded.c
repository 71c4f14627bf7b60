// Preloaded into the tests of the asan preset (CMakePresets.json): dlclose does nothing, so no
// library is unmapped before the process exits. LeakSanitizer runs at exit; a block that a
// library's static data still points to when the OpenXR or Vulkan loader unloads it (lavapipe,
// the validation layers: 128-byte blocks) then looks leaked, from "<unknown module>", which no
// suppression can name. With the library still mapped the block is reachable, and a real leak
// gets a stack with the library's name on it.
int dlclose(void* handle) {
  (void)handle;
  return 0;
}
