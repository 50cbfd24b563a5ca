#!/usr/bin/env bash
# Runs the loader fuzz targets (fuzz/, cargo-fuzz layout):
#   scripts/fuzz.sh [TARGET|all] [SECONDS]      default: all targets, 60 s each, one after the other
#   scripts/fuzz.sh smoke [SECONDS]             CI's smoke test: every target replays its seeds
#                                               and fuzzes SECONDS (default 2), built in the dev
#                                               profile (44 s to build instead of 110 s; slower
#                                               executions, so -timeout=10 instead of 1)
# Each run: libFuzzer with -timeout=1 (an input taking over 1 s is a hang) and -rss_limit_mb=1024
# (an allocation over 1 GiB is a failure), debug assertions and overflow checks on, no sanitizer
# (the loaders are safe Rust; a sanitizer only slows the search on a 2-core machine).
# Seeds are regenerated every run into fuzz/seeds/TARGET from the test writers and the small
# real files (crates/splatgl-testkit/src/bin/fuzz_seeds.rs); what the fuzzer finds grows fuzz/corpus/TARGET. Neither
# is committed. A crash, contract violation, hang or blow-up leaves its input in
# fuzz/artifacts/TARGET/ and makes this script fail; turn it into a test in tests/.
# Uses the nightly toolchain when installed, else stable with RUSTC_BOOTSTRAP=1; installs
# cargo-fuzz when missing. FUZZ_FLAGS adds libFuzzer options (e.g. FUZZ_FLAGS=-jobs=2).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
targets=(ply gltf_json glb gltf_struct cameras_json spz splat ksplat sog tileset)
which=${1:-all}
secs=${2:-60}
build=(--sanitizer none --debug-assertions --release)
timeout=1
if [ "$which" = smoke ]; then
  which=all secs=${2:-2} timeout=10
  build=(--sanitizer none --dev)
fi
if [ "$which" != all ]; then
  [[ " ${targets[*]} " == *" $which "* ]] || { echo "unknown target $which (${targets[*]})" >&2; exit 2; }
  targets=("$which")
fi
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --version 0.13.2 --locked --debug
if rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
  fuzz=(cargo +nightly fuzz)
else
  export RUSTC_BOOTSTRAP=1
  fuzz=(cargo fuzz)
fi
rm -rf fuzz/seeds
cargo run --quiet -p splatgl-testkit --bin fuzz_seeds -- fuzz/seeds "$root/../shared/data/real"
"${fuzz[@]}" build "${build[@]}"
for t in "${targets[@]}"; do
  mkdir -p "fuzz/corpus/$t" "fuzz/artifacts/$t"
  echo "== $t: ${secs}s"
  # shellcheck disable=SC2086
  "${fuzz[@]}" run "${build[@]}" "$t" "$root/fuzz/corpus/$t" "$root/fuzz/seeds/$t" -- \
    -max_total_time="$secs" -timeout="$timeout" -rss_limit_mb=1024 -print_final_stats=1 \
    -artifact_prefix="$root/fuzz/artifacts/$t/" ${FUZZ_FLAGS:-}
done
