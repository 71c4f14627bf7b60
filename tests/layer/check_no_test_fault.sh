#!/usr/bin/env bash
# Checks that a build of the layer (.so or .dll) has no test fault: the string "test_layer_fault"
# (layer/test_fault.h) appears nowhere in the file. Given the layer's test build too, checks that
# the same search finds it there, so a broken search cannot pass.
#   check_no_test_fault.sh LIBRARY [TEST_BUILD]
set -euo pipefail
lib="$1"
test_build="${2:-}"
fail=0
# grep -a: the whole file as bytes, every section, debug information included.
if LC_ALL=C grep -aqi test_layer_fault "$lib"; then
  echo "FAIL: $(basename "$lib") holds \"test_layer_fault\": the test fault is in the shipped layer"
  fail=1
fi
if [ -n "$test_build" ] && ! LC_ALL=C grep -aqi test_layer_fault "$test_build"; then
  echo "FAIL: no \"test_layer_fault\" in the test build $(basename "$test_build"): the search is broken"
  fail=1
fi
[ "$fail" = 0 ] && echo "no test fault in $(basename "$lib")"
exit "$fail"
