#!/usr/bin/env bash
# Installs the pinned npm tools the tests cross-check against into .npm-tools/ (where the tests
# look): splat-transform and GaussianSplats3D's .ksplat writer (with three) for
# tests/it/splat_transform.rs and crates/splatgl-cli/tests/it/splat_transform_gltf.rs, and the Khronos glTF-Validator (scripts/gltf_validate.mjs) for the
# converter and conformance tests. Reinstalled only when the pinned list changes
# (.npm-tools/ci-installed records it). Without npm it says so and returns 1.
set -euo pipefail
cd "$(dirname "$0")/.."
npm_tools=(@playcanvas/splat-transform@3.7.0 @mkkellogg/gaussian-splats-3d@0.4.7 three@0.170.0
  gltf-validator@2.0.0-dev.3.10
  # Spark 2.2 (scripts/conformance/spark.mjs) needs three >= 0.180 (a peer), GS3D's pin is 0.170:
  # Spark's three is the alias three-spark (spark.html maps "three" to it); --force lets npm
  # install Spark beside the unmet peer instead of refusing (ERESOLVE).
  @sparkjsdev/spark@2.2.0 three-spark@npm:three@0.180.0 --force
  cesium@1.145.0
  # PlayCanvas 2.23 reads KHR_gaussian_splatting glTF itself (scripts/conformance/playcanvas.mjs).
  playcanvas@2.23.3
  # Babylon.js 9 reads KHR_gaussian_splatting glTF itself (scripts/conformance/babylon.mjs).
  @babylonjs/core@9.28.0 @babylonjs/loaders@9.28.0
  # The web package's declarations are checked with tsc --noEmit (scripts/web/pack-check.mjs).
  typescript@5.9.3)
if [ "$(cat .npm-tools/ci-installed 2>/dev/null)" = "${npm_tools[*]}" ]; then
  exit 0
fi
if ! command -v npm >/dev/null; then
  echo "scripts/npm-tools.sh: npm not found; the splat-transform and glTF-Validator tests will skip" >&2
  exit 1
fi
npm install --prefix .npm-tools --no-audit --no-fund --loglevel=error "${npm_tools[@]}"
echo "${npm_tools[*]}" > .npm-tools/ci-installed
