#!/usr/bin/env bash
# The layer tests on a busy machine (ctest label stress, docs/layer.md "Tests"): layer_tests run
# whole RUNS times in a row (SDFG_STRESS_RUNS, default 20) with two busy loops beside it, which
# take CPU time from the app's threads, the layer's worker and lavapipe, as other programs do on
# a player's machine. Every wait of the tests is for an outcome, with bounds measured on the same
# machine or generous ones: any failed run fails this.
#   stress_layer.sh LAYER_TESTS [CATCH2 ARGUMENTS...]
set -uo pipefail
tests="$1"
shift
runs="${SDFG_STRESS_RUNS:-20}"
case "$runs" in
  '' | *[!0-9]* | 0) echo "FAIL: SDFG_STRESS_RUNS must be a positive count, not '$runs'"; exit 2 ;;
esac

# Each loop spins until this script is gone, even when killed without a chance to stop them
# (kill -0 and the arithmetic are bash builtins: no process is started per turn).
parent=$$
busy=()
spin() {
  while kill -0 "$parent" 2>/dev/null; do
    i=0
    while [ "$i" -lt 200000 ]; do i=$((i + 1)); done
  done
}
child=""
stop_all() {
  for pid in "${busy[@]}" $child; do kill "$pid" 2>/dev/null; done
  for pid in "${busy[@]}" $child; do wait "$pid" 2>/dev/null; done
  busy=()
}
trap stop_all EXIT
trap 'exit 130' INT TERM
spin &
busy+=($!)
spin &
busy+=($!)

log="$(mktemp -t sdfg-stress-XXXXXX.log)"
failed=0
start=$(date +%s)
for run in $(seq 1 "$runs"); do
  run_start=$(date +%s)
  # In the background: bash runs a trap only once a foreground command ends, and a stopped run
  # must not go on with the loops gone.
  "$tests" "$@" >"$log" 2>&1 &
  child=$!
  wait "$child"
  status=$?
  child=""
  took=$(($(date +%s) - run_start))
  if [ "$status" -eq 0 ]; then
    echo "run $run/$runs: passed in $took s"
  else
    failed=$((failed + 1))
    echo "run $run/$runs: FAILED (exit status $status) in $took s; its output:"
    cat "$log"
  fi
done
rm -f "$log"
echo "$failed of $runs runs failed, $(($(date +%s) - start)) s in all, beside two busy loops"
[ "$failed" -eq 0 ]
