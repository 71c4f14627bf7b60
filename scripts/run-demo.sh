#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the main job on embedded
# defaults. Until the headless demo exists this is the benchmark on the embedded objects.
# Extra arguments go to autograsp-bench.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh" default
mkdir -p "$root/out"
"$root/build/default/tools/bench/autograsp-bench" --embedded-only --placements 200 \
  --json "$root/out/bench.json" "$@"
