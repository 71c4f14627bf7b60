# Sourced by tests/cts/build_cts.sh and tests/monado/build_monado.sh: unpacks a third-party source
# archive from ../shared into `root`, the build's folder, whose name CMake keys by the archive and
# the build script (tests/third_party_key.cmake), so a second run reuses the build there and a
# changed fix in the script gets a folder of its own. Expects `archive`, `root` and `name` (for
# messages) set.
# Exits the calling script: 77 when the archive is missing (the caller's test reports SKIPPED),
# 0 when the build in `root` is already done (its built.stamp exists). Otherwise leaves `root`
# emptied and re-extracted, and `stamp` (the file to write when done), `src` (the extracted
# source tree) and `start` (seconds, for the build time) set.
if [ ! -f "$archive" ]; then
  echo "SDFG_SKIPPED: no $name archive at $archive"
  exit 77
fi
stamp="$root/built.stamp"
if [ -f "$stamp" ]; then
  echo "build_$name: cached build $root"
  exit 0
fi
start=$(date +%s)
rm -rf "$root"
mkdir -p "$root"
tar xJf "$archive" -C "$root"
src=$(find "$root" -mindepth 1 -maxdepth 1 -type d | head -n1)
