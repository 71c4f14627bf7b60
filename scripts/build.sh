#!/usr/bin/env bash
# Installs what is missing, then configures and builds the project with the given preset
# (default: "default"). Used by run-tests.sh and run-demo.sh.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset="${1:-default}"
"$root/scripts/install-deps.sh"
cmake -S "$root" --preset "$preset" >/dev/null
jobs="$(nproc 2>/dev/null || echo 2)"
cmake --build "$root/build/$preset" --parallel "$jobs"
