#!/usr/bin/env bash
# splatgl in the browser (docs/web.md).
#
#   ./scripts/web.sh build                 web/dist/: index.html (the viewer), viewer.js,
#                                          splatgl.js (the API), pkg/ (the wasm module)
#   ./scripts/web.sh conformance SUITE OUT every camera of a generated suite rendered by the web
#                                          build in headless Chromium, PNGs as
#                                          `splatgl conformance run SUITE --images OUT` reads them
#   ./scripts/web.sh render FILE|--default OUT.png [--width W] [--height H]
#                                          one image, the default view (as `splatgl render`)
#   ./scripts/web.sh bench SCENE [OUT.json] frame times of splatgl-web in headless Chromium
#                                          (scripts/web/bench.mjs)
#   ./scripts/web.sh serve [PORT]          serves web/dist on 127.0.0.1 (default port 8080)
#   ./scripts/web.sh pack                  the npm package `splatgl` (web/dist is its root) as
#                                          target/web-pack/splatgl-VERSION.tgz, then checked:
#                                          installed beside web/example, type-checked with
#                                          tsc --noEmit, the example rendered in headless Chromium
#
# build needs the wasm32-unknown-unknown target (rustup target add wasm32-unknown-unknown) and
# wasm-bindgen-cli of the version Cargo.lock pins (installed with cargo install when missing);
# the others need node and chromium (.ci/run installs them). SPLATGL_WEB_PROFILE=dev builds
# without optimisation (faster, larger).
set -euo pipefail
cd "$(dirname "$0")/.."
target_dir="${CARGO_TARGET_DIR:-target}"
cmd=${1:-}
[ $# -gt 0 ] && shift

build() {
  local profile=${SPLATGL_WEB_PROFILE:-release} dir
  [ "$profile" = dev ] && dir=debug || dir=$profile
  if ! rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
    echo "== rustup target add wasm32-unknown-unknown"
    rustup target add wasm32-unknown-unknown
  fi
  local version
  version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/"/, "", $3); print $3; exit }' Cargo.lock)
  if [ "$(wasm-bindgen --version 2>/dev/null | awk '{ print $2 }')" != "$version" ]; then
    echo "== installing wasm-bindgen-cli $version (cargo install --debug; about a minute, once)"
    # Not --locked: its lock file pins a webpki-roots release the registry no longer offers.
    # The debug build of the one binary used: 58 s to build on 2 cores instead of ~4 min
    # optimised (no registry this project reaches ships it prebuilt), and 1.0 s instead of
    # 0.24 s per run, with byte-identical output.
    env -u RUSTC_WORKSPACE_WRAPPER -u CLIPPY_ARGS \
      cargo install --quiet --debug wasm-bindgen-cli --version "$version" --bin wasm-bindgen
  fi
  echo "== building splatgl-web for wasm32-unknown-unknown ($profile)"
  cargo build --locked --quiet --target wasm32-unknown-unknown --profile "$profile" -p splatgl-web
  rm -rf web/dist
  mkdir -p web/dist/pkg
  wasm-bindgen --target web --no-typescript --out-dir web/dist/pkg \
    "$target_dir/wasm32-unknown-unknown/$dir/splatgl_web.wasm"
  cp web/index.html web/viewer.js web/splatgl.js web/splatgl.d.ts web/package.json web/dist/
  local wasm=web/dist/pkg/splatgl_web_bg.wasm
  echo "web/dist: $(stat -c %s "$wasm") bytes of wasm, $(gzip -9 -c "$wasm" | wc -c) gzipped"
}

case "$cmd" in
  build) build ;;
  conformance)
    [ $# -ge 2 ] || { echo "usage: scripts/web.sh conformance SUITE OUT" >&2; exit 2; }
    node scripts/conformance/splatgl-web.mjs "$@" ;;
  render)
    [ $# -ge 2 ] || { echo "usage: scripts/web.sh render FILE|--default OUT.png [--width W] [--height H]" >&2; exit 2; }
    node scripts/web/render.mjs "$@" ;;
  bench)
    [ $# -ge 1 ] || { echo "usage: scripts/web.sh bench SCENE [OUT.json]" >&2; exit 2; }
    node scripts/web/bench.mjs "$@" ;;
  pack)
    [ -f web/dist/pkg/splatgl_web_bg.wasm ] || build
    node scripts/web/pack-check.mjs ;;
  serve)
    port=${1:-8080}
    echo "http://127.0.0.1:$port/ (web/dist; Ctrl-C stops)"
    exec python3 -m http.server "$port" --bind 127.0.0.1 --directory web/dist ;;
  *)
    sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2 ;;
esac
