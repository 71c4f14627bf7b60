#!/usr/bin/env bash
# Installs the Debian 12 packages SDF Autograsp needs, skipping those already present (a second
# run changes nothing).
#   install-deps.sh         every package: build, test and run everything (run-tests.sh)
#   install-deps.sh --demo  only what building and running autograsp-demo needs (run-demo.sh):
#                           no Wine, MinGW-w64, CTS or Monado build dependencies, no hello_xr
#                           or validation layers, no gnuplot or clang-format
# The demo set must still configure the whole project: every hard find_package of the default
# preset (tests included: the demo's mock runtime lives in tests/) is in it.
set -euo pipefail

set_name=all
case "${1:-}" in
  "") ;;
  --demo) set_name=demo ;;
  *)
    echo "usage: install-deps.sh [--demo]" >&2
    exit 2
    ;;
esac

demo_packages=(
  # build tools (git: the commit the demo's report names)
  build-essential cmake ninja-build pkg-config git
  # OpenXR: the Khronos loader and headers
  libopenxr-dev libopenxr-loader1
  # Vulkan: Mesa's lavapipe (CPU driver), headers, loader, glslang
  mesa-vulkan-drivers libvulkan-dev glslang-tools
  # maths, tests (configure needs Catch2: the mock runtime is in tests/), physics baseline
  libglm-dev catch2 libbullet-dev
  # mesh files (OBJ, PLY) and the evaluator's exact distance (CGAL AABB tree)
  libassimp-dev libcgal-dev libgmp-dev libmpfr-dev
  # the demo's pictures
  libpng-dev
  # the tools' JSON files and command lines (header-only; tools/ only, never the layer)
  nlohmann-json3-dev libcli11-dev
)
more_packages=(
  clang-format
  # hello_xr and the core validation layer (ctest -L client, -L layer)
  libopenxr-utils openxr-layer-corevalidation
  # the Khronos Vulkan validation layers (GPU and layer tests)
  vulkan-validationlayers
  # the benchmark report's plots
  gnuplot-nox
  # the OpenXR CTS, built from ../shared/cts by `ctest -L cts` (tests/cts/build_cts.sh)
  python3 python3-jinja2 libx11-xcb-dev libxrandr-dev libxxf86vm-dev mesa-common-dev
  libxcb-glx0-dev
  # Monado, built from ../shared/monado by `ctest -L monado` (tests/monado/build_monado.sh)
  libeigen3-dev libudev-dev
  # Windows x64 (preset windows, docs/windows.md): MinGW-w64's cross compiler, POSIX-threads
  # flavour (std::thread), with its binutils (dlltool, objdump); Wine 8 runs the tests
  g++-mingw-w64-x86-64-posix wine wine64
)

packages=("${demo_packages[@]}")
if [ "$set_name" = all ]; then
  packages+=("${more_packages[@]}")
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages of the $set_name set already installed"
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
