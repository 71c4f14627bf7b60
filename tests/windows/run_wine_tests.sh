#!/usr/bin/env bash
# Runs the Windows build's layer tests under Wine (ctest label windows, tests/windows).
#   run_wine_tests.sh --prefix DIR --setup --runtime-json FILE --layer-json FILE
#     makes the private Wine prefix DIR once (wineboot, bounded in time, no window) and registers
#     the mock runtime as the active OpenXR runtime and the layer as an implicit layer in its
#     registry, as an installer does on Windows. Under Wine every process counts as elevated, so
#     the loader ignores XR_RUNTIME_JSON and XR_API_LAYER_PATH: the registry is the only way in.
#   run_wine_tests.sh --prefix DIR --run PROGRAM SPEC
#     runs the Catch2 test PROGRAM.exe with test spec SPEC in that prefix.
#   run_wine_tests.sh --prefix DIR --scripts SCRIPTS_DIR DLL JSON
#     stages DLL, JSON and SCRIPTS_DIR/*.bat in a folder as a user unpacks them, runs
#     install-layer.bat and uninstall-layer.bat (for all users, then with /user) and checks the
#     registry after each.
# No Wine on this machine: prints SDFG_SKIPPED (ctest counts the test as skipped) and exits 0.
set -euo pipefail

prefix="" mode="" scripts_dir="" dll="" runtime_json="" layer_json="" program="" spec=""
while [ $# -gt 0 ]; do
  case "$1" in
    --prefix) prefix="$2"; shift 2 ;;
    --setup) mode=setup; shift ;;
    --runtime-json) runtime_json="$2"; shift 2 ;;
    --layer-json) layer_json="$2"; shift 2 ;;
    --run) mode=run; program="$2"; spec="$3"; shift 3 ;;
    --scripts) mode=scripts; scripts_dir="$2"; dll="$3"; layer_json="$4"; shift 4 ;;
    *) echo "run_wine_tests.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -n "$prefix" ] && [ -n "$mode" ] || { echo "usage: see the header of $0" >&2; exit 2; }

if ! command -v wine >/dev/null 2>&1; then
  echo "SDFG_SKIPPED: wine is not installed (scripts/install-deps.sh installs it)"
  exit 0
fi

export WINEPREFIX="$prefix"
export WINEARCH=win64
export WINEDEBUG=-all
# No window and no download prompt: no display, and no Mono or Gecko installer at wineboot.
unset DISPLAY WAYLAND_DISPLAY
export WINEDLLOVERRIDES="mscoree,mshtml="
# winevulkan hands Vulkan calls to the host's loader: Mesa's lavapipe, as the Linux tests use.
export VK_ICD_FILENAMES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json

key='HKLM\Software\Khronos\OpenXR\1'
ready="$prefix/.sdfg-prefix-ready"
if [ "$mode" = setup ]; then
  start=$(date +%s)
  # A prefix without the marker is half made (an interrupted run): made again from nothing.
  if [ ! -f "$ready" ]; then
    rm -rf "$prefix" && mkdir -p "$prefix"
    timeout 300 wineboot --init >/dev/null 2>&1 || {
      echo "FAIL: wineboot did not make the prefix $prefix within 300 s"; exit 1; }
  fi
  runtime_win=$(winepath -w "$runtime_json")
  layer_win=$(winepath -w "$layer_json")
  # A fresh list of implicit layers: only the layer under test.
  timeout 60 wine reg delete "$key\\ApiLayers\\Implicit" /f >/dev/null 2>&1 || true
  timeout 60 wine reg add "$key" /v ActiveRuntime /t REG_SZ /d "$runtime_win" /f >/dev/null
  timeout 60 wine reg add "$key\\ApiLayers\\Implicit" /v "$layer_win" /t REG_DWORD /d 0 /f \
    >/dev/null
  timeout 60 wine reg query "$key" /s
  # The server writes the registry to the prefix's files when it exits: wait for that, so the
  # prefix is whole on disk before the marker says so.
  timeout 60 wineserver -w || true
  touch "$ready"
  echo "prefix $prefix ready in $(($(date +%s) - start)) s"
  exit 0
fi

if [ ! -f "$ready" ]; then
  echo "FAIL: no Wine prefix at $prefix (the windows_wine_prefix test makes it)"
  exit 1
fi
if [ "$mode" = scripts ]; then
  pkg="$prefix-install-test/SDF Autograsp"  # a space in the path, as under Program Files
  rm -rf "$pkg" && mkdir -p "$pkg"
  cp "$dll" "$layer_json" "$scripts_dir"/install-layer.bat "$scripts_dir"/uninstall-layer.bat "$pkg"/
  manifest_win=$(winepath -w "$pkg/XrApiLayer_sdfg_autograsp.json")
  registered() {  # root: HKLM or HKCU
    timeout 60 wine reg query "$1\Software\Khronos\OpenXR\1\ApiLayers\Implicit" /v "$manifest_win" \
      >/dev/null 2>&1
  }
  bat() { (cd "$pkg" && timeout 60 wine cmd /c "$@" 2>&1 | tr -d '\r'); }
  failures=0
  for arg in "" /user; do
    root=HKLM
    [ "$arg" = /user ] && root=HKCU
    echo "--- install-layer.bat $arg"
    bat install-layer.bat $arg
    if registered $root; then echo "ok: registered under $root"; else echo "FAIL: not under $root"; failures=$((failures + 1)); fi
    echo "--- uninstall-layer.bat $arg"
    bat uninstall-layer.bat $arg
    if registered $root; then echo "FAIL: still under $root"; failures=$((failures + 1)); else echo "ok: gone from $root"; fi
  done
  echo "--- install-layer.bat /bogus (refused)"
  out=$(bat install-layer.bat /bogus || true)
  echo "$out"
  if grep -q "unknown argument" <<<"$out" && ! registered HKLM && ! registered HKCU; then
    echo "ok: refused"
  else
    echo "FAIL: /bogus accepted"; failures=$((failures + 1))
  fi
  [ "$failures" -eq 0 ] || { echo "FAIL: $failures checks"; exit 1; }
  echo "OK"
  exit 0
fi

# --warn NoTests: a spec that matches nothing fails instead of passing having run nothing.
exec timeout 550 wine "$program" "$spec" --warn NoTests
