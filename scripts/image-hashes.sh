#!/usr/bin/env bash
# Hashes every image splatgl produces for a refactoring check ("bit-identical before and
# after"): the conformance suite's files and references (`conformance generate`), both
# backends' runs of it (`conformance run --backend gl|reference`: images and report.json), and
# renders of every real scene in ../shared/data/real with both backends (160×120).
#   scripts/image-hashes.sh SPLATGL_BINARY OUT_DIR > hashes.txt
# Run it with the binary of each commit and diff the two lists.
set -u
bin=$(realpath "$1"); out=$2
real="$(cd "$(dirname "$0")/.." && pwd)/../shared/data/real"
rm -rf "$out"; mkdir -p "$out/real"
"$bin" conformance generate "$out/suite" >/dev/null
for b in gl reference; do
  "$bin" conformance run --backend "$b" "$out/suite" -o "$out/run-$b" >/dev/null
done
for f in "$real"/*.{ply,spz,glb,gltf,splat,ksplat}; do
  n=$(basename "$f")
  for b in reference gl; do
    "$bin" render "$f" --backend "$b" --width 160 --height 120 -f -o "$out/real/$n.$b.png" \
      >/dev/null 2>&1 || echo "render failed: $n $b" >&2
  done
done
cd "$out" && find . -type f \( -name '*.png' -o -name '*.pfm' -o -name '*.glb' -o -name '*.gltf' \
  -o -name '*.bin' -o -name '*.json' \) -print0 | sort -z | xargs -0 sha256sum
