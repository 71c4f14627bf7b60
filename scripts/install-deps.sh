#!/usr/bin/env bash
# Installs every Debian 12 package SDF Autograsp needs to build, test and run.
# Idempotent: packages already present are skipped, so a second run changes nothing.
set -euo pipefail

packages=(
  # build tools
  build-essential cmake ninja-build pkg-config git clang-format
  # OpenXR: the Khronos loader, headers, hello_xr and the core validation layer
  libopenxr-dev libopenxr-loader1 libopenxr-utils openxr-layer-corevalidation
  # Vulkan: Mesa's lavapipe (CPU driver), headers, loader, validation layers, glslang
  mesa-vulkan-drivers libvulkan-dev vulkan-validationlayers glslang-tools
  # maths, tests, physics baseline
  libglm-dev catch2 libbullet-dev
  # mesh files (OBJ, PLY) and the evaluator's exact distance (CGAL AABB tree)
  libassimp-dev libcgal-dev libgmp-dev libmpfr-dev
  # images and plots for the demo and the benchmark report
  libpng-dev gnuplot-nox
  # the tools' JSON files and command lines (header-only; tools/ only, never the layer)
  nlohmann-json3-dev libcli11-dev
  # the OpenXR CTS, built from ../shared/cts by `ctest -L cts` (tests/cts/build_cts.sh)
  python3 python3-jinja2 libx11-xcb-dev libxrandr-dev libxxf86vm-dev mesa-common-dev
  libxcb-glx0-dev
  # Monado, built from ../shared/monado by `ctest -L monado` (tests/monado/build_monado.sh)
  libeigen3-dev libudev-dev
  # Windows x64 (preset windows, docs/windows.md): MinGW-w64's cross compiler, POSIX-threads
  # flavour (std::thread), with its binutils (dlltool, objdump); Wine 8 runs the tests
  g++-mingw-w64-x86-64-posix wine wine64
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
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
