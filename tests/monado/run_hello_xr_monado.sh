#!/usr/bin/env bash
# Debian's unmodified hello_xr on Monado (headless build, null compositor, remote driver) with
# the layer installed as an implicit layer: it must reach FOCUSED, render for 3 s, quit when asked
# (a byte on stdin: hello_xr then tears down its running session at once, without EXITING),
# exit 0, and neither the core validation layer nor the layer may log an error.
# Exit 77 (ctest: skipped) when there is no Monado build.
# hello_xr's stdout is line-buffered (stdbuf) so the wait below sees its state changes.
# Usage: run_hello_xr_monado.sh <monado-stamp> <layer-json> <work-dir> [Vulkan|Vulkan2]
set -euo pipefail
stamp=$1 layer_json=$2 work=$3 graphics=${4:-Vulkan2}
if [ ! -f "$stamp" ]; then
  echo "SDFG_SKIPPED: no Monado build ($stamp); the archive ../shared/monado is absent"
  exit 77
fi
manifest=$(cat "$stamp")
hello_xr=$(command -v hello_xr || true)
[ -n "$hello_xr" ] || { echo "FAIL: hello_xr not installed (libopenxr-utils)"; exit 1; }
rm -rf "$work"
mkdir -p "$work/data/openxr/1/api_layers/implicit.d"
cp "$layer_json" "$work/data/openxr/1/api_layers/implicit.d/"
fifo="$work/stdin"
trap '' PIPE  # hello_xr may be gone when asked to quit; its status tells what happened
mkfifo "$fifo"
env -i PATH="$PATH" HOME="$work" XDG_RUNTIME_DIR="$work" XDG_DATA_HOME="$work/data" \
  XDG_CONFIG_DIRS="$work/no-config" XR_RUNTIME_JSON="$manifest" \
  XR_ENABLE_API_LAYERS=XR_APILAYER_LUNARG_core_validation \
  XR_CORE_VALIDATION_FILE_NAME="$work/core-validation.txt" \
  XRT_COMPOSITOR_NULL=1 P_OVERRIDE_ACTIVE_CONFIG=remote XRT_LOG=warning \
  VK_ICD_FILENAMES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json \
  timeout 120 stdbuf -oL "$hello_xr" -g "$graphics" -ff Hmd -vc Stereo <"$fifo" >"$work/stdout.txt" \
  2>"$work/stderr.txt" &
pid=$!
exec 3>"$fifo"  # held open: hello_xr quits on a byte or at end of input
# Wait for the outcome (the session focused), bounded, then ask hello_xr to quit.
for _ in $(seq 600); do
  grep -q 'XR_SESSION_STATE_FOCUSED' "$work/stdout.txt" 2>/dev/null && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.1
done
focused=0
grep -q 'XR_SESSION_STATE_FOCUSED' "$work/stdout.txt" && focused=1
# A few more seconds of frames with the layer in the chain.
[ "$focused" = 1 ] && sleep 3
echo q >&3 || true
rc=0
wait "$pid" || rc=$?
exec 3>&-
fail=0
[ "$focused" = 1 ] || { echo "FAIL: hello_xr never reached FOCUSED"; fail=1; }
[ "$rc" = 0 ] || { echo "FAIL: hello_xr exited $rc"; fail=1; }
if [ -s "$work/core-validation.txt" ] && grep -q 'VALID_' "$work/core-validation.txt"; then
  echo "FAIL: core validation reported:"; head -n 20 "$work/core-validation.txt"; fail=1
fi
if grep -q '\[sdfg_autograsp\].*error' "$work/stderr.txt"; then
  echo "FAIL: the layer logged an error:"; grep '\[sdfg_autograsp\]' "$work/stderr.txt" | head; fail=1
fi
if [ "$fail" != 0 ]; then
  echo "--- stdout (tail)"; tail -n 20 "$work/stdout.txt"
  echo "--- stderr (tail)"; tail -n 20 "$work/stderr.txt"
  exit 1
fi
echo "PASS: hello_xr -g $graphics on Monado with the layer: focused, rendered, exited 0"
