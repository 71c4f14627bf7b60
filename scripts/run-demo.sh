#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the headless demo
# (autograsp-demo) on the embedded objects (mug, torus, thin plate): an OpenXR app through the
# real loader, the mock runtime and the layer, rendered with Vulkan (lavapipe without a GPU).
# Then a table scene grasped by the engine in-process (a mug, a block and a comb on a table top) and the
# outer hand (a hand pushed into the table, tracked and shown). It writes PNG pictures and
# out/demo/report.html.
# Extra arguments go to autograsp-demo (see --help), e.g. --mesh my.obj or --width 1024.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh" default
"$root/build/default/tools/demo/autograsp-demo" --embedded-only --out "$root/out/demo" "$@"
