#!/usr/bin/env bash
# Runs Debian's unmodified hello_xr on the mock runtime and checks that it really rendered:
# exit code 0, the session reached EXITING, the runtime counted N frames with layers, the last
# left-eye image holds hello_xr's clear colour and something else (its cubes), and neither the
# OpenXR core validation layer nor the Vulkan validation layer reported anything.
#
# Usage: run_hello_xr.sh --graphics Vulkan|Vulkan2 --runtime-json FILE --work-dir DIR
#                        [--frames N] [--layer-json FILE] [--env K=V] [--stdin-eof] [--timeout S]
#   --layer-json  an implicit layer manifest to install (the layer under test), optional
#   --env K=V     add K=V to hello_xr's (otherwise minimal) environment; repeatable
#   --stdin-eof   run with stdin at end of input instead: hello_xr must quit after 0 frames
#                 and still exit 0 (the trap a harness must avoid; this proves we see it)
set -euo pipefail

graphics="" runtime_json="" work_dir="" frames=10 layer_json="" stdin_eof=0 limit=60 extra_env=()
while [ $# -gt 0 ]; do
  case "$1" in
    --graphics) graphics="$2"; shift 2 ;;
    --runtime-json) runtime_json="$2"; shift 2 ;;
    --work-dir) work_dir="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --layer-json) layer_json="$2"; shift 2 ;;
    --env) extra_env+=("$2"); shift 2 ;;
    --stdin-eof) stdin_eof=1; shift ;;
    --timeout) limit="$2"; shift 2 ;;
    *) echo "run_hello_xr: unknown argument $1" >&2; exit 2 ;;
  esac
done
[ -n "$graphics" ] && [ -n "$runtime_json" ] && [ -n "$work_dir" ] ||
  { echo "run_hello_xr: --graphics, --runtime-json and --work-dir are required" >&2; exit 2; }

hello_xr=$(command -v hello_xr || true)
[ -n "$hello_xr" ] || { echo "FAIL: hello_xr not installed (Debian package libopenxr-utils)"; exit 1; }
lvp_icd=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
[ -f "$lvp_icd" ] || { echo "FAIL: lavapipe ICD $lvp_icd missing (mesa-vulkan-drivers)"; exit 1; }

rm -rf "$work_dir"
mkdir -p "$work_dir"
report="$work_dir/report.txt"
capture="$work_dir/left-eye.ppm"
cv_file="$work_dir/core-validation.txt"
out="$work_dir/stdout.txt"
err="$work_dir/stderr.txt"

env_args=(
  "PATH=$PATH"
  "HOME=$work_dir"
  "XDG_RUNTIME_DIR=$work_dir"
  "XR_RUNTIME_JSON=$runtime_json"
  "XR_ENABLE_API_LAYERS=XR_APILAYER_LUNARG_core_validation"
  "XR_CORE_VALIDATION_FILE_NAME=$cv_file"
  "VK_ICD_FILENAMES=$lvp_icd"
  "VK_DRIVER_FILES=$lvp_icd"
  # hello_xr never destroys its VkDevice, so the shader validation cache is never written and
  # every run would log an informational "cannot open cache" message; switch the cache off.
  "VK_LAYER_DISABLES=VK_VALIDATION_FEATURE_DISABLE_SHADER_VALIDATION_CACHE_EXT"
  "SDFG_MOCK_END_AFTER_FRAMES=$frames"
  "SDFG_MOCK_REPORT=$report"
  "SDFG_MOCK_CAPTURE=$capture"
)
env_args+=("${extra_env[@]}")
if [ -n "$layer_json" ]; then
  # An implicit layer is found under $XDG_DATA_HOME/openxr/1/api_layers/implicit.d.
  mkdir -p "$work_dir/data/openxr/1/api_layers/implicit.d"
  ln -s "$(realpath "$layer_json")" "$work_dir/data/openxr/1/api_layers/implicit.d/"
  env_args+=("XDG_DATA_HOME=$work_dir/data")
fi

# hello_xr quits at the first byte or at end of input on stdin, so a plain CI run renders
# nothing. Feed it from a FIFO whose write end we hold open until it exits.
rc=0
if [ "$stdin_eof" = 1 ]; then
  env -i "${env_args[@]}" timeout -k 5 "$limit" "$hello_xr" -g "$graphics" </dev/null >"$out" 2>"$err" || rc=$?
else
  fifo="$work_dir/stdin.fifo"
  mkfifo -m 600 "$fifo"
  env -i "${env_args[@]}" timeout -k 5 "$limit" "$hello_xr" -g "$graphics" <"$fifo" >"$out" 2>"$err" &
  pid=$!
  exec 3>"$fifo"
  wait "$pid" || rc=$?
  exec 3>&-
  rm -f "$fifo"
fi

failures=()
fail() { failures+=("$1"); }
value() { awk -v k="$1" '$1 == k { $1 = ""; sub(/^ /, ""); print; exit }' "$report" 2>/dev/null; }

[ "$rc" = 0 ] || fail "hello_xr exit code $rc (124 = timeout)"
[ -f "$report" ] || fail "the runtime wrote no report ($report): no session was destroyed"
if grep -q "No validation layers found" "$out" "$err"; then
  fail "hello_xr found no Vulkan validation layer (install vulkan-validationlayers)"
fi
# Any message of either validation layer fails the test; the core validation layer's banner
# "Core Validation output type: ..." on stderr is expected and is no message.
if grep -nE "VALID_(ERROR|WARNING|INFO)|\[Validation\]|Validation (Error|Warning|Performance|Information)|VUID-|\[Error" "$out" "$err"; then
  fail "validation or error messages in hello_xr's output (lines above)"
fi
if [ -s "$cv_file" ]; then
  cat "$cv_file"
  fail "the core validation layer logged messages to $cv_file"
fi

ended=$(value frames_ended); ended=${ended:-0}
with_layers=$(value frames_with_layers); with_layers=${with_layers:-0}
if [ "$stdin_eof" = 1 ]; then
  [ "$ended" = 0 ] || fail "with stdin at end of input hello_xr should render 0 frames, ended $ended"
else
  grep -q "XR_SESSION_STATE_EXITING" "$out" || fail "hello_xr never saw XR_SESSION_STATE_EXITING"
  [ "$ended" -ge "$frames" ] || fail "runtime counted $ended xrEndFrame calls, expected $frames"
  [ "$with_layers" -ge "$frames" ] || fail "only $with_layers of $ended frames submitted a layer"
  # Pixels of the last left-eye image: the top-left corner is hello_xr's clear colour
  # (0.184, 0.31, 0.31 linear = 119 151 151 in sRGB), the centre shows a cube face, and a
  # rendered scene has several colours.
  read -r cr cg cb ca <<<"$(value capture_corner)" || true
  centre=$(value capture_centre)
  colours=$(value capture_distinct_colours); colours=${colours:-0}
  near() { [ "${1:-999}" -ge $(($2 - 2)) ] && [ "${1:-999}" -le $(($2 + 2)) ]; }
  if ! { near "$cr" 119 && near "$cg" 151 && near "$cb" 151 && near "$ca" 255; }; then
    fail "corner pixel is '${cr:-} ${cg:-} ${cb:-} ${ca:-}', not hello_xr's clear colour 119 151 151 255"
  fi
  [ -n "$centre" ] && [ "$centre" != "$cr $cg $cb $ca" ] || fail "centre pixel '$centre' equals the clear colour: no cube"
  [ "$colours" -ge 3 ] || fail "the image has $colours colours: nothing rendered"
fi

echo "hello_xr -g $graphics: rc $rc, frames ended $ended, with layers $with_layers"
[ -f "$report" ] && sed 's/^/  report: /' "$report"
if [ ${#failures[@]} -gt 0 ]; then
  printf 'FAIL: %s\n' "${failures[@]}"
  echo "--- stderr ($err) ---"; tail -n 40 "$err"
  echo "--- stdout ($out) ---"; tail -n 40 "$out"
  exit 1
fi
echo PASS
