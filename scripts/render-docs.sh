#!/usr/bin/env bash
# Renders the Graphviz sources of docs/architecture/ to SVG pictures in docs/img/ (committed, so
# readers need nothing). Installs Debian's graphviz first when `dot` is missing (sudo when not
# root). Run it after editing a .dot file.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if ! command -v dot >/dev/null; then
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends graphviz >/dev/null
fi
for src in "$root"/docs/architecture/*.dot; do
  out="$root/docs/img/$(basename "${src%.dot}").svg"
  dot -Tsvg "$src" -o "$out"
  echo "render-docs: $out"
done
