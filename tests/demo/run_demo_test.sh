#!/usr/bin/env bash
# The demo test: autograsp-demo on a small setting (embedded objects, 512 px panels) plus a broken
# mesh file. The broken file must get a clear message naming it, the run must go on and grasp
# every embedded object and each object of the table scene, and exit 1 (something was skipped);
# then autograsp-demo-check checks the pictures and the reports (the commit of the code among
# them; the outer hand's depths). Last, --help and bad options.
# usage: run_demo_test.sh DEMO CHECKER WORK_DIR
set -uo pipefail
demo="$1" checker="$2" work="$3"
rm -rf "$work" && mkdir -p "$work"
broken="$work/broken-mesh.obj"
printf 'v 0 0 0\nv 1 0 0\nf 1 2 9\nthis is not an OBJ file\n' > "$broken"
"$demo" --embedded-only --width 512 --mesh "$broken" --out "$work/out" \
  >"$work/stdout.txt" 2>"$work/stderr.txt"
rc=$?
cat "$work/stdout.txt"
fail=0
if [ "$rc" -ne 1 ]; then echo "FAIL: exit status $rc, expected 1 (a mesh was skipped)"; fail=1; fi
if ! grep -q "^autograsp-demo: skipping .*$broken.*: parse failed" "$work/stderr.txt"; then
  echo "FAIL: no message naming the broken mesh on stderr:"; cat "$work/stderr.txt"; fail=1
else
  echo "ok:   $(grep "skipping" "$work/stderr.txt")"
fi
if ! grep -q "^autograsp-demo: 3 objects, 9 grasps" "$work/stdout.txt"; then
  echo "FAIL: the embedded objects were not all grasped after the broken mesh"; fail=1
fi
# The table scene: each grasp takes the object the hand was placed on (not the table, which is
# scene geometry, nor the neighbour).
for object in mug block comb; do
  if ! grep -q "^  table scene: placed on the $object, took the $object," "$work/stdout.txt"; then
    echo "FAIL: the grasp placed on the $object did not take it"; fail=1
  fi
done
if ! grep -q "report are in $work/out/" "$work/stdout.txt"; then
  echo "FAIL: the summary does not say where the files are"; fail=1
fi
if ! grep -q "broken-mesh.obj" "$work/out/report.md"; then
  echo "FAIL: report.md does not list the skipped mesh"; fail=1
fi
"$checker" "$work/out" 512 mug torus thin-plate || fail=1
# Options: --help prints the usage (exit 0); a value out of range is named (exit 2), and so is an
# unknown option; neither starts the demo.
if ! "$demo" --help | grep -q "^usage: autograsp-demo"; then
  echo "FAIL: --help does not print the usage"; fail=1
fi
for args in "--width 100|--width: \"100\" is not 256..2048" "--resolution 0x10|--resolution: \"0x10\" is not 2..128" \
    "--bogus|not expected: --bogus"; do
  message="${args#*|}"
  "$demo" ${args%%|*} --out "$work/not-run" >/dev/null 2>"$work/usage.txt"
  rc=$?
  if [ "$rc" -ne 2 ] || ! grep -qF -- "$message" "$work/usage.txt" || [ -e "$work/not-run" ]; then
    echo "FAIL: '${args%%|*}' exited $rc, expected 2 with '$message':"; cat "$work/usage.txt"; fail=1
  else
    echo "ok:   ${args%%|*}: $(cat "$work/usage.txt")"
  fi
done
exit $fail
