#!/usr/bin/env bash
# Headless GL benchmark at 1920×1080 with the generated 1M-splat SH-3 and 4M-splat SH-0
# scenes, printing frames/s per scene, view (full / half in view) and draw path (former =
# before issue 15, new = the default path). The same command gives GPU figures on a machine
# whose EGL has a GPU (the first line names the GL renderer), llvmpipe figures elsewhere.
#
#   scripts/bench-gpu.sh                 # 1920×1080, scenes 1m,4m, 5 frames each
#   FRAMES=3 SCENES=1m SIZE=1280x720 scripts/bench-gpu.sh
#   CROSSOVER=100,1000,10000 scripts/bench-gpu.sh   # also the pre-pass crossover table
#
# The whole `cargo bench --features testing --bench gl` output is kept in target/bench-gpu.log.
set -euo pipefail
cd "$(dirname "$0")/.."
log=target/bench-gpu.log
mkdir -p target
SPLATGL_BENCH_SIZE="${SIZE:-1920x1080}" \
SPLATGL_BENCH_SCENES="${SCENES:-1m,4m}" \
SPLATGL_BENCH_FRAMES="${FRAMES:-5}" \
SPLATGL_BENCH_CROSSOVER="${CROSSOVER:-none}" \
SPLATGL_BENCH_PREDICT=0 \
    cargo bench --features testing --bench gl >"$log" 2>&1 || { tail -30 "$log"; exit 1; }
grep -m1 '^context:' "$log"
grep -m1 '^framebuffer' "$log"
echo
printf '%-7s %-5s %-7s %10s %10s %9s  %s\n' scene view path drawn "frame ms" "frames/s" "GPU ms: pre-pass / copy / quads"
# Rows of the main table: scene | view | path | drawn | fragments | sort | draw | CPU | frame | fps | pre-pass
# | GPU stages (timer queries: where the frame goes on the GPU)
awk -F'|' 'NF >= 11 && $2 ~ /full|half/ && $3 ~ /former|cull|extent|new/ {
    gsub(/ /, "", $1); gsub(/ /, "", $2); gsub(/ /, "", $3)
    printf "%-7s %-5s %-7s %10d %10.1f %9.2f  %s\n", $1, $2, $3, $4, $9, $10, $12
}' "$log"
echo
# The speed-up summary and, if asked for, the crossover table.
sed -n '/draw: cull/,/^$/p' "$log"
if [ "${CROSSOVER:-none}" != none ]; then sed -n '/direct draw ms/,/^$/p' "$log"; fi
