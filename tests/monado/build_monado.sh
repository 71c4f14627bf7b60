#!/usr/bin/env bash
# Builds Monado (headless, in-process: no service, no IPC, null compositor, drivers simulated and
# remote, no window system, USB, OpenCV or SDL) from the archive in ../shared/monado into
# <build-dir>, once: CMake names that folder by the archive's and this script's SHA-256
# (tests/third_party_key.cmake), so a second run reuses it and a changed fix rebuilds. The source is
# extracted into the build tree and fixed there, never copied into the repository
# (../shared/monado/README.md):
#   - src/xrt/targets/openxr/CMakeLists.txt links comp_main even with the main compositor off:
#     it is dropped from that list (the null compositor is linked through target_lists);
#   - the remote driver links aux_vive: XRT_MODULE_AUX_VIVE stays on.
# Exit 0: built (or cached), the runtime manifest's path in <build-dir>/built.stamp;
# 77: no archive (the caller reports SKIPPED); other: build failed.
# Usage: build_monado.sh <archive.tar.xz> <build-dir> [jobs]
set -euo pipefail
archive=$1
root=$2
jobs=${3:-2}
name=monado
# Sets stamp, src and start, or exits 77 (no archive) or 0 (already built).
source "$(dirname "${BASH_SOURCE[0]}")/../third_party_unpack.sh"
target_cmake="$src/src/xrt/targets/openxr/CMakeLists.txt"
sed -i '/^\t\t\tcomp_main$/d' "$target_cmake"
if grep -q 'comp_main' "$target_cmake"; then
  echo "build_monado: could not drop comp_main from $target_cmake"
  exit 1
fi
off=(XRT_FEATURE_SERVICE XRT_MODULE_IPC XRT_MODULE_COMPOSITOR_MAIN XRT_MODULE_MONADO_CLI
  XRT_MODULE_MONADO_GUI XRT_FEATURE_STEAMVR_PLUGIN XRT_FEATURE_WINDOW_PEEK XRT_FEATURE_DEBUG_GUI
  XRT_HAVE_OPENGL XRT_HAVE_OPENGLES XRT_HAVE_EGL XRT_HAVE_SDL2 XRT_HAVE_WAYLAND XRT_HAVE_XCB
  XRT_HAVE_XLIB XRT_HAVE_XRANDR XRT_HAVE_OPENCV XRT_HAVE_DBUS XRT_HAVE_LIBUDEV XRT_HAVE_SYSTEMD
  XRT_HAVE_LIBUSB XRT_HAVE_LIBUVC XRT_HAVE_HIDAPI XRT_HAVE_JPEG XRT_HAVE_GST XRT_HAVE_V4L2
  XRT_HAVE_BLUETOOTH XRT_HAVE_PERCETTO XRT_BUILD_DRIVER_NS XRT_BUILD_DRIVER_TWRAP
  XRT_BUILD_DRIVER_WMR XRT_BUILD_DRIVER_VIVE XRT_BUILD_DRIVER_SURVIVE XRT_BUILD_DRIVER_QWERTY
  XRT_BUILD_DRIVER_ARDUINO XRT_BUILD_DRIVER_DAYDREAM XRT_BUILD_DRIVER_HDK XRT_BUILD_DRIVER_HYDRA
  XRT_BUILD_DRIVER_PSMV XRT_BUILD_DRIVER_PSSENSE XRT_BUILD_DRIVER_PSVR XRT_BUILD_DRIVER_ROKID
  XRT_BUILD_DRIVER_RIFT_S XRT_BUILD_DRIVER_STEAMVR_LIGHTHOUSE XRT_BUILD_DRIVER_XREAL_AIR
  XRT_BUILD_DRIVER_OPENGLOVES XRT_BUILD_DRIVER_EUROC BUILD_TESTING BUILD_DOC)
on=(XRT_MODULE_COMPOSITOR_NULL XRT_BUILD_DRIVER_SIMULATED XRT_BUILD_DRIVER_REMOTE
  XRT_MODULE_AUX_VIVE XRT_FEATURE_OPENXR)
args=()
for o in "${off[@]}"; do args+=("-D$o=OFF"); done
for o in "${on[@]}"; do args+=("-D$o=ON"); done
cmake -S "$src" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${args[@]}" \
  >"$root/configure.log" 2>&1 || { tail -n 40 "$root/configure.log"; exit 1; }
cmake --build "$root/build" --parallel "$jobs" >"$root/build.log" 2>&1 ||
  { tail -n 60 "$root/build.log"; exit 1; }
manifest=$(find "$root/build" -name 'openxr_monado-dev.json' | head -n1)
[ -n "$manifest" ] || { echo "build_monado: no openxr_monado-dev.json"; exit 1; }
echo "$manifest" >"$stamp"
echo "build_monado: built in $(( $(date +%s) - start )) s ($(grep -c '^\[' "$root/build.log") steps): $manifest"
