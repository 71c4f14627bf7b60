#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the headless demo
# (autograsp-demo) on the embedded objects (mug, torus, thin plate): an OpenXR app through the
# real loader, the mock runtime and the layer, rendered with Vulkan (lavapipe without a GPU).
# Then a table scene grasped by the engine in-process (a mug, a block and a comb on a table top) and the
# outer hand (a hand pushed into the table, tracked and shown). It writes PNG pictures and
# out/demo/report.html.
#
# Quick on a fresh machine: only the demo's packages (install-deps.sh --demo) and only the demo's
# target with what it loads (the layer and the mock runtime; their manifests are written when
# CMake configures), in a build folder of its own (preset demo, build/demo) compiled at -O1
# without debug info: about 40% less compile time than the default preset's -O2 -g, with the same
# pictures and figures (GCC 12's -O1 has false maybe-uninitialized warnings in libstdc++'s
# std::optional moves, hence that warning off there). run-tests.sh installs and builds everything.
# Extra arguments go to autograsp-demo (see --help), e.g. --mesh my.obj or --width 1024.
# SDFG_BUILD_DIR: another build folder (default build/demo).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${SDFG_BUILD_DIR:-$root/build/demo}"
"$root/scripts/build.sh" demo --deps demo --target autograsp-demo --build-dir "$build_dir"
"$build_dir/tools/demo/autograsp-demo" --embedded-only --out "$root/out/demo" "$@"
