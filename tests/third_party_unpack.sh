# Sourced by tests/cts/build_cts.sh and tests/monado/build_monado.sh: unpacks a third-party source
# archive from ../shared into <out-dir>/<key>/, once per archive and build script, so a second run
# reuses the build there. The key is the first 16 hex of the archive's SHA-256, '-', the first 8
# of the build script's (tests/third_party_key.cmake computes the same for the stamp's path): a
# changed fix in the script rebuilds. Expects `archive`, `recipe` (the build script), `out` and
# `name` (for messages) set.
# Exits the calling script: 77 when the archive is missing (the caller's test reports SKIPPED),
# 0 when a build of this archive is already done (its built.stamp exists). Otherwise leaves
# `root` (the keyed folder, emptied and re-extracted), `stamp` (the file to write when done),
# `src` (the extracted source tree) and `start` (seconds, for the build time) set.
if [ ! -f "$archive" ]; then
  echo "SDFG_SKIPPED: no $name archive at $archive"
  exit 77
fi
hash=$(sha256sum "$archive" | cut -c1-16)-$(sha256sum "$recipe" | cut -c1-8)
root="$out/$hash"
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
