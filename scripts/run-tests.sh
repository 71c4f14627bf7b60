#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, and runs every test with ctest.
# Extra arguments go to ctest (for example: -L core).
#
# Every run starts from none of the state an earlier run (or the machine's user) left behind, so
# a failure that only shows on a fresh machine shows on every run:
# - an empty Mesa shader cache (MESA_SHADER_CACHE_DIR): with a warm one, lavapipe skips
#   seconds of shader compilation, which once hid a cold-start failure of the Vulkan path;
# - empty XDG config, data and cache folders and no /usr/local/share or /etc/xdg: no user
#   configuration of the layer, and no installed copy of it as an implicit OpenXR layer;
# - a fresh TMPDIR, and none of the variables that steer the layer (SDFG_AUTOGRASP_*), the mock
#   runtime (SDFG_MOCK_*) or the OpenXR and Vulkan loaders (XR_*, VK_*).
# All of it lives in one temporary folder, removed at exit. The build tree is reused
# incrementally; the tests that write into it clear their own folders first.
#
# SDFG_TEST_PRESETS (default: "default") lists the CMake presets to build and test, in order,
# each with its own fresh shader cache; CI runs "default asan tsan" (see .ci/run). The run stops
# at the first preset with a failure, so ctest's summary line of the failing run is the last
# thing printed.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
presets="${SDFG_TEST_PRESETS:-default}"

state="$(mktemp -d "${TMPDIR:-/tmp}/sdfg-run-tests.XXXXXX")"
trap 'rm -rf "$state"' EXIT
mkdir -p "$state/config" "$state/data" "$state/cache" "$state/xdg-config-dirs" "$state/tmp"
export XDG_CONFIG_HOME="$state/config"
export XDG_DATA_HOME="$state/data"
export XDG_CACHE_HOME="$state/cache"
export XDG_CONFIG_DIRS="$state/xdg-config-dirs"
export XDG_DATA_DIRS=/usr/share  # Debian's OpenXR and Vulkan manifests; not /usr/local/share
export TMPDIR="$state/tmp"
unset MESA_SHADER_CACHE_DISABLE MESA_DISK_CACHE_SINGLE_FILE DISABLE_XR_APILAYER_SDFG_AUTOGRASP
while IFS= read -r name; do
  case "$name" in
    SDFG_AUTOGRASP_* | SDFG_MOCK_* | XR_* | VK_*) unset "$name" ;;
  esac
done < <(compgen -e)

jobs="$(nproc 2>/dev/null || echo 2)"
cd "$root"
for preset in $presets; do
  start=$SECONDS
  "$root/scripts/build.sh" "$preset"
  cache="$state/mesa-shader-cache-$preset"
  mkdir -p "$cache"
  echo "run-tests: preset $preset built in $((SECONDS - start)) s; testing with an empty Mesa" \
    "shader cache ($cache)"
  # Nothing is printed after ctest: its summary line closes the output.
  MESA_SHADER_CACHE_DIR="$cache" ctest --preset "$preset" --parallel "$jobs" "$@"
done
