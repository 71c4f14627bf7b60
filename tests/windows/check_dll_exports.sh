#!/usr/bin/env bash
# Checks that a Windows DLL exports exactly the names given, read from its export table with
# MinGW's objdump (tests/windows, label windows).
#   check_dll_exports.sh OBJDUMP DLL NAME...
set -euo pipefail
objdump="$1" dll="$2"
shift 2
if [ -z "$objdump" ] || ! command -v "$objdump" >/dev/null 2>&1; then
  echo "SDFG_SKIPPED: no MinGW objdump"
  exit 0
fi
# The name table: lines "[   0] name" after "[Ordinal/Name Pointer] Table".
actual=$("$objdump" -p "$dll" | sed -n '/\[Ordinal\/Name Pointer\] Table/,/^$/p' |
  sed -n 's/^[[:space:]]*\[ *[0-9]*\] \(.*\)$/\1/p' | sort)
expected=$(printf '%s\n' "$@" | sort)
echo "exports of $(basename "$dll"):"
echo "$actual"
if [ "$actual" != "$expected" ]; then
  echo "FAIL: expected exactly:"
  echo "$expected"
  exit 1
fi
echo "OK"
