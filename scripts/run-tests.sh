#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, and runs every test with ctest.
# Extra arguments go to ctest (for example: -L core).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh" default
cd "$root"
ctest --preset default --parallel "$(nproc 2>/dev/null || echo 2)" "$@"
