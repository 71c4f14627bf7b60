#!/bin/bash
# Packages autograsp-frame-cost to run on another Linux x86-64 machine that lacks this project's
# Debian packages (a GPU machine lent for a few minutes; docs/benchmarks-gpu.md, "How to run
# frame-cost on the device"):
#
#   OUTDIR/bin/autograsp-frame-cost        the tool (debug info stripped)
#   OUTDIR/layer/                          the layer and an explicit manifest naming it by a
#                                          relative library_path (the build tree's names it by
#                                          absolute path, which the copy does not have)
#   OUTDIR/runtime/                        the mock runtime and its manifest (relative already)
#   OUTDIR/lib/                            the shared libraries the three link, found with ldd,
#                                          except glibc's and the C++ runtime's (the machine has
#                                          those), plus the GL dispatch libraries (libGLdispatch,
#                                          libGLX and theirs) through which NVIDIA's Vulkan ICD
#                                          loads: without them it answers no vkCreateInstance
#   OUTDIR/meshes/                         with MESHES_DIR: the research meshes the tool reads
#                                          (bunny, armadillos; 21 MiB), else absent (skipped)
#   OUTDIR/run-frame-cost.sh               sets LD_LIBRARY_PATH and VK_DRIVER_FILES and runs the
#                                          tool with --layer-dir, --runtime-json and --meshes
#                                          pointing in OUTDIR; its arguments go to the tool
#
# Usage: tools/frame-cost/package-for-device.sh OUTDIR [BUILD_DIR [MESHES_DIR]]
#   BUILD_DIR: the build tree with autograsp-frame-cost, sdfg_layer and sdfg_mock_runtime built
#   (default build/default). MESHES_DIR: e.g. ../shared/meshes. OUTDIR is emptied first. Fails
#   if the package exceeds 60 MiB.
set -euo pipefail

if [ $# -lt 1 ] || [ $# -gt 3 ]; then
  sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
  exit 2
fi
src=$(cd "$(dirname "$0")/../.." && pwd)
out=$1
build=${2:-$src/build/default}
meshes=${3:-}
die() { echo "package-for-device: $*" >&2; exit 1; }

tool=$build/tools/frame-cost/autograsp-frame-cost
layer_json=$build/layer/explicit/XrApiLayer_sdfg_autograsp.json
runtime_json=$build/tests/mock_runtime/sdfg_mock_runtime.json
for f in "$tool" "$layer_json" "$runtime_json"; do
  [ -f "$f" ] || die "$f is missing: build autograsp-frame-cost sdfg_layer sdfg_mock_runtime in $build"
done
# The libraries, as the manifests name them (the layer's absolute, the runtime's relative).
library_path() {
  python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); print(d[sys.argv[2]]["library_path"])' "$1" "$2"
}
layer_lib=$(library_path "$layer_json" api_layer)
runtime_lib=$(library_path "$runtime_json" runtime)
case $runtime_lib in /*) ;; *) runtime_lib=$(dirname "$runtime_json")/$runtime_lib ;; esac
[ -f "$layer_lib" ] || die "the layer's manifest names $layer_lib, which is missing"
[ -f "$runtime_lib" ] || die "the runtime's manifest names $runtime_lib, which is missing"

# Emptied only when it is a package already (or empty): a mistyped OUTDIR is not wiped.
if [ -d "$out" ] && [ -n "$(ls -A "$out")" ] && [ ! -f "$out/run-frame-cost.sh" ]; then
  die "$out is not empty and holds no earlier package: give a new or empty folder"
fi
rm -rf "$out"
mkdir -p "$out/bin" "$out/lib" "$out/layer" "$out/runtime"
# Stripped copies: the debug info of a RelWithDebInfo build is most of their size.
strip --strip-debug -o "$out/bin/autograsp-frame-cost" "$tool"
layer_name=$(basename "$layer_lib")
strip --strip-debug -o "$out/layer/$layer_name" "$layer_lib"
python3 - "$layer_json" "$out/layer/XrApiLayer_sdfg_autograsp.json" "./$layer_name" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["api_layer"]["library_path"] = sys.argv[3]  # relative to the manifest, as the loader reads it
json.dump(d, open(sys.argv[2], "w"), indent=2)
PY
runtime_name=$(basename "$runtime_lib")
strip --strip-debug -o "$out/runtime/$runtime_name" "$runtime_lib"
python3 - "$runtime_json" "$out/runtime/sdfg_mock_runtime.json" "./$runtime_name" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["runtime"]["library_path"] = sys.argv[3]
json.dump(d, open(sys.argv[2], "w"), indent=2)
PY

# What the machine is assumed to have: glibc, the C++ runtime and the dynamic loader.
is_base() {
  case $(basename "$1") in
    libc.so.* | libm.so.* | libdl.so.* | libpthread.so.* | librt.so.* | ld-linux*.so.* | \
      libstdc++.so.* | libgcc_s.so.* | linux-vdso.so.*) return 0 ;;
  esac
  return 1
}
# The GL dispatch libraries NVIDIA's ICD needs (this machine's, from Debian's libglvnd).
gl_libs=()
for name in libGLdispatch.so.0 libGLX.so.0; do
  path=$(ldconfig -p | awk -v n="$name" '$1 == n && /x86-64/ { print $NF; exit }')
  [ -n "$path" ] || die "$name not found (Debian: libglvnd0 and libglx0)"
  gl_libs+=("$path")
done
# Each needed library once, under the name the dynamic linker looks for (its soname).
declare -A copied=()
for binary in "$tool" "$layer_lib" "$runtime_lib" "${gl_libs[@]}"; do
  if [[ " ${gl_libs[*]} " == *" $binary "* ]]; then
    name=$(basename "$binary")
    copied[$name]=1
    cp -L "$binary" "$out/lib/$name"
  fi
  while read -r name arrow path _; do
    [ "$arrow" = "=>" ] || continue
    [ "$path" != "not" ] || die "$(basename "$binary") needs $name, which ldd does not find"
    is_base "$path" && continue
    [ -n "${copied[$name]:-}" ] && continue
    copied[$name]=1
    cp -L "$path" "$out/lib/$name"
  done < <(ldd "$binary")
done
chmod u+w "$out"/lib/*
strip --strip-debug "$out"/lib/*

if [ -n "$meshes" ]; then
  mkdir -p "$out/meshes"
  # The files main.cpp looks for; a missing one is skipped by the tool, as at home.
  for f in stanford-bunny.obj stanford-armadillo-100k.obj stanford-armadillo-400k-subdiv.obj; do
    if [ -f "$meshes/$f" ]; then cp "$meshes/$f" "$out/meshes/"; else echo "no $meshes/$f" >&2; fi
  done
fi

cat > "$out/run-frame-cost.sh" <<'SH'
#!/bin/bash
# Runs the packaged autograsp-frame-cost with its own layer, mock runtime and libraries (made by
# tools/frame-cost/package-for-device.sh). Arguments go to the tool, e.g.
#   ./run-frame-cost.sh --session vulkan --target buffer --embedded-only --json out.json
# NVIDIA's driver (a container's /usr/local/nvidia) is used when there; otherwise the Vulkan
# loader's own search, or VK_DRIVER_FILES / VK_ICD_FILENAMES as set by the caller.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
export LD_LIBRARY_PATH="$here/lib:/usr/local/nvidia/lib64${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -z "${VK_DRIVER_FILES:-}" ] && [ -z "${VK_ICD_FILENAMES:-}" ] && [ -f "$nvidia_icd" ]; then
  export VK_DRIVER_FILES=$nvidia_icd
fi
exec "$here/bin/autograsp-frame-cost" --layer-dir "$here/layer" \
  --runtime-json "$here/runtime/sdfg_mock_runtime.json" --meshes "$here/meshes" "$@"
SH
chmod +x "$out/run-frame-cost.sh"

size=$(du -sm "$out" | cut -f1)
echo "packaged autograsp-frame-cost in $out ($size MiB):"
(cd "$out" && find . -type f | sort | sed 's/^\.\//  /')
[ "$size" -lt 60 ] || die "the package is $size MiB, over 60"
