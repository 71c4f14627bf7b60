#!/usr/bin/env bash
# Checks the built layer library: its only exported symbol is xrNegotiateLoaderApiLayerInterface,
# it does not link the OpenXR loader, its file name follows the Khronos pattern, and it needs no
# library beyond the C and C++ runtimes (an implicit layer is loaded into every OpenXR app: no
# physics engine, mesh importer or evaluator may ride along with it). And it has no test fault
# (check_no_test_fault.sh, which is shown the layer's test build too when that is given).
#   check_exports.sh LIBRARY [TEST_BUILD]
set -euo pipefail
lib="$1"
test_build="${2:-}"
fail=0
case "$(basename "$lib")" in
  libXrApiLayer_*.so) ;;
  *) echo "FAIL: library name $(basename "$lib") is not libXrApiLayer_<name>.so"; fail=1 ;;
esac
exported=$(nm -D --defined-only "$lib" | awk '$2 ~ /^[TtDdBbRrVvWwiu]$/ { print $3 }' | sort -u)
echo "exported: $exported"
if [ "$exported" != "xrNegotiateLoaderApiLayerInterface" ]; then
  echo "FAIL: the library must export exactly xrNegotiateLoaderApiLayerInterface"; fail=1
fi
needed=$(objdump -p "$lib" | awk '$1 == "NEEDED" { print $2 }')
echo "needed: $(echo $needed)"
if echo "$needed" | grep -q openxr_loader; then
  echo "FAIL: the layer links the OpenXR loader"; fail=1
fi
# Allow-list, so that any new dependency is a decision: the C/C++ runtimes, and the sanitizer
# runtimes in the sanitizer presets.
allowed='^(libstdc\+\+|libm|libgcc_s|libc|libdl|libpthread|librt|ld-linux-x86-64|libasan|libubsan|libtsan)\.so'
for lib_needed in $needed; do
  if ! echo "$lib_needed" | grep -Eq "$allowed"; then
    echo "FAIL: the layer needs $lib_needed, which is not on its allow-list of runtimes"; fail=1
  fi
done
# No undefined xr* symbol either: the layer reaches OpenXR only through the chain.
if nm -D --undefined-only "$lib" | awk '{ print $2 }' | grep -q '^xr'; then
  echo "FAIL: the layer imports xr* symbols"; fail=1
fi
bash "$(dirname "${BASH_SOURCE[0]}")/check_no_test_fault.sh" "$lib" ${test_build:+"$test_build"} || fail=1
[ "$fail" = 0 ] && echo PASS
exit "$fail"
