#!/usr/bin/env bash
# Installs what is missing, then configures and builds the project with a CMake preset. Used by
# run-tests.sh (everything) and run-demo.sh (the demo alone).
#   build.sh [PRESET] [--deps demo] [--target NAME]... [--build-dir DIR]
# PRESET: default "default". --deps demo: install only the demo's packages
# (install-deps.sh --demo; default: every package). --target: build only these targets and what
# they depend on (default: all). --build-dir: the build folder (default: the preset's own,
# build/<preset>, where ctest --preset looks).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset=default
if [ $# -gt 0 ] && [ "${1#-}" = "$1" ]; then
  preset="$1"
  shift
fi
deps=()
targets=()
build_dir="$root/build/$preset"
while [ $# -gt 0 ]; do
  case "$1" in
    --deps)
      [ "${2:-}" = demo ] || { echo "build.sh: --deps takes 'demo'" >&2; exit 2; }
      deps=(--demo)
      shift 2
      ;;
    --target)
      [ -n "${2:-}" ] || { echo "build.sh: --target needs a name" >&2; exit 2; }
      targets+=(--target "$2")
      shift 2
      ;;
    --build-dir)
      [ -n "${2:-}" ] || { echo "build.sh: --build-dir needs a folder" >&2; exit 2; }
      build_dir="$2"
      shift 2
      ;;
    *)
      echo "usage: build.sh [PRESET] [--deps demo] [--target NAME]... [--build-dir DIR]" >&2
      exit 2
      ;;
  esac
done

"$root/scripts/install-deps.sh" "${deps[@]}"
cmake -S "$root" --preset "$preset" -B "$build_dir" >/dev/null
jobs="$(nproc 2>/dev/null || echo 2)"
cmake --build "$build_dir" --parallel "$jobs" "${targets[@]}"
