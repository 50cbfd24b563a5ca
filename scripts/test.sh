#!/usr/bin/env bash
# The project's test command (README), in four lanes, each timed:
#   fast: format check, clippy with warnings as errors for every feature set users build
#         (default and --no-default-features checked; --all-features and every target linted
#         as the tests build them: see RUSTC_WORKSPACE_WRAPPER below), docs without broken links, an
#         independent Python re-implementation of the reference's math, and every unit and
#         integration test of every crate except the slow cross-checks;
#   python: the Python package (crates/splatgl-python) installed into a venv under the target
#         folder with `pip install .` (maturin, the dev profile), Ray for the `ray` extra, then
#         its pytest suite (python/tests, splatgl.ray's on a local cluster) against the command;
#   platforms: the other platforms (docs/platforms.md): clippy with warnings as errors for
#         macOS (aarch64-apple-darwin, which can only be checked here), and for Windows
#         (x86_64-pc-windows-gnu) and the browser (wasm32-unknown-unknown) as they are built:
#         the Windows build staged by scripts/windows/build.sh (mingw-w64), its tests, and the
#         web build (scripts/web.sh build);
#   slow: the cross-checks that drive a browser, an X server or Wine: the engines graded in
#         headless Chromium (GaussianSplats3D, Spark, CesiumJS, PlayCanvas, Babylon.js),
#         splat-transform's streamed SOG and glTF, the viewer under Xvfb, the Windows build
#         under Wine (splatgl.exe render and view, the C legacy host against splatgl.dll), and
#         the web build in headless Chromium (scenes, the conformance suite, the viewer page).
# `scripts/test.sh fast`, `python`, `platforms` or `slow` runs one lane (python after fast: it
# uses the command fast builds; slow after platforms: it runs the Windows build). Tests that cannot run here (no
# EGL, no real data, no npm tool) are listed at the end; with SPLATGL_REQUIRE=all (.ci/run sets
# it) each of them fails instead.
set -euo pipefail
cd "$(dirname "$0")/.."
lane=${1:-all}
# Clippy in the builds themselves: every workspace crate any lane compiles goes through
# clippy-driver with warnings as errors (what `cargo clippy -- -D warnings` runs), so a target
# that is built is linted by the same pass instead of a separate `cargo clippy` check of it.
# Cargo keeps the wrapper in its fingerprints: every lane sets it, or a lane would rebuild.
# (`cargo install` of tools unsets it: their lints are not ours.)
RUSTC_WORKSPACE_WRAPPER="$(rustup which clippy-driver 2>/dev/null || command -v clippy-driver)"
export RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS="-D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__"
target="${CARGO_TARGET_DIR:-target}"
skipped="$target/tmp/skipped-tests.txt"

# The integration-test modules (in crates/splatgl-cli/tests/it) of the slow lane: filters for
# the test harness, each a module path prefix.
slow=(conformance_third_party:: conformance_cesium:: conformance_playcanvas:: conformance_babylon:: tiles_cesium::
  tiles_streamed_sog::
  splat_transform_gltf:: viewer:: viewer_panel:: windows:: web::)
skip_slow=()
for m in "${slow[@]}"; do skip_slow+=(--skip "$m"); done

fast() {
  cargo fmt --all -- --check
  cargo fmt --manifest-path fuzz/Cargo.toml -- --check
  # All features, all targets: linted as the tests and benches below build them.
  cargo clippy --workspace --locked -- -D warnings
  cargo clippy -p splatgl --no-default-features --locked -- -D warnings
  RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --all-features --locked
  # The command, and the C libraries the C and C++ host tests link (cargo test builds only
  # the crates' rlibs).
  cargo build --locked --quiet -p splatgl-cli -p splatgl-capi
  python3 scripts/xcheck_reference.py "$target/debug/splatgl"
  # The Python extension is tested by its own lane (it links no libpython: no Rust test).
  cargo test --workspace --exclude splatgl-python --all-features --locked --lib --bins --tests \
    --examples -- "${skip_slow[@]}"
  # The benchmarks' smoke runs (each checks its own results; they take no harness options).
  cargo test --workspace --exclude splatgl-python --all-features --locked --benches
}

python() {
  local venv="$target/pyvenv"
  [ -x "$venv/bin/python" ] || python3 -m venv "$venv"
  # ray: the optional extra splatgl.ray needs (its tests start a local cluster).
  "$venv/bin/pip" install --quiet --disable-pip-version-check \
    maturin==1.16.0 pytest==9.2.0 numpy==2.4.6 ray==2.60.0
  PATH="$PWD/$venv/bin:$PATH" MATURIN_PEP517_ARGS="--profile dev" "$venv/bin/pip" install --quiet \
    --disable-pip-version-check --no-build-isolation --force-reinstall --no-deps .
  SPLATGL_BIN="$target/debug/splatgl" "$venv/bin/python" -m pytest -q python/tests
}

platforms() {
  # The targets' standard libraries (a no-op where .ci/run or an earlier run added them).
  local t
  for t in x86_64-pc-windows-gnu aarch64-apple-darwin wasm32-unknown-unknown; do
    rustup target list --installed | grep -qx "$t" || rustup target add "$t"
  done
  # Library, CLI (with the viewer and http), C API for macOS: checked only (one target: both
  # take the same cfg paths; docs/platforms.md). Windows and the browser are linted as they
  # are built below (web/dist in release, the Windows build staged by build.sh).
  cargo clippy --locked --target aarch64-apple-darwin -p splatgl-cli -p splatgl-capi -- -D warnings
  ./scripts/web.sh build
  ./scripts/windows/build.sh
  # The library's unit and integration tests built for Windows and run under Wine (headless
  # GL through WGL), all but the two modules that run host tools the Wine prefix lacks
  # (layering: cargo tree; splat_transform: node).
  xvfb-run -a env CARGO_TARGET_X86_64_PC_WINDOWS_GNU_RUNNER="$PWD/scripts/windows/wine.sh" \
    cargo test --locked --target x86_64-pc-windows-gnu -p splatgl --lib --test it -- \
    --skip layering:: --skip splat_transform::
  # The release archives' layout, from the dev builds above (scripts/dist.sh checks them).
  ./scripts/dist.sh --dev
}

slow() {
  # The fast lane's feature resolution (--workspace), so nothing is built again.
  cargo test --workspace --all-features --locked --test it -- "${slow[@]}"
}

# The pinned npm tools both lanes' cross-checks use (when npm is present).
./scripts/npm-tools.sh || true
mkdir -p "$target/tmp"
rm -f "$skipped"
run_lane() {
  local start=$SECONDS
  echo "== lane $1"
  "$1"
  echo "== lane $1: $((SECONDS - start)) s"
}
case "$lane" in
  fast) run_lane fast ;;
  slow) run_lane slow ;;
  python) run_lane python ;;
  platforms) run_lane platforms ;;
  all) run_lane fast; run_lane python; run_lane platforms; run_lane slow ;;
  *) echo "usage: scripts/test.sh [fast|python|platforms|slow|all]" >&2; exit 2 ;;
esac
if [ -s "$skipped" ]; then
  echo "skipped tests (what they need is missing here; SPLATGL_REQUIRE=all makes these failures):"
  sort "$skipped" | sed 's/^/  /'
fi
