#!/usr/bin/env node
// Renders a splatgl conformance suite with CesiumJS 1.145 (npm `cesium`) in headless Chromium,
// so `splatgl conformance run SUITE --images OUT` grades a renderer splatgl did not write.
//
//   node scripts/conformance/cesium.mjs SUITE OUT [--splatgl target/debug/splatgl] [--only ASSET]
//
// CesiumJS 1.145 draws Gaussian splats only as the content of a 3D Tiles tileset, and only
// SPZ-compressed ones: GltfLoader.js marks a primitive for splat processing only when it
// carries KHR_gaussian_splatting_compression_spz_2 (fetchSpzExtensionFrom, line 2158-2168 and
// 2358-2363), and Cesium3DTileContentFactory.js (lines 98-102, 115-119) routes glTF content to
// GaussianSplat3DTileContent only when the tileset lists both extensions as required. So each
// asset is
//
//  1. converted with `splatgl convert ASSET content.glb --spz-compress` (SPZ v2; node
//     transforms baked into one primitive, as the RC's math allows; lossy, see docs/formats.md);
//  2. given the COLOR_0 placeholder CesiumJS reads the SPZ colours and alphas into
//     (GltfVertexBufferLoader.js line 444: only the semantic COLOR_0) in place of the RC's
//     KHR_gaussian_splatting:SH_DEGREE_0_COEF_0 and :OPACITY placeholders (which CesiumJS would
//     count as SH coefficients: GaussianSplat3DTileContent.js line 646-661) — the SPZ payload is
//     not touched — and an identity node matrix (it multiplies nodes[0].matrix unconditionally,
//     GaussianSplatPrimitive.js line 1245-1249);
//  3. made the one content of a tileset.json (3D Tiles 1.1, 3DTILES_content_gltf listing both
//     extensions as used and required; root tile: bounding sphere around the decoded positions
//     plus a margin, geometricError 0, refine ADD; the tileset's own geometricError large so the
//     root is traversed at all) whose root transform makes Cesium's world
//     frame the glTF's world frame, placed on the ellipsoid, exactly (WORLD, TILE_TRANSFORM
//     below).
//
// Each camera of the asset's cameras.json is then set on Cesium's camera, mapped by WORLD
// (position; direction = R·(0, 0, 1) and up = −R·(0, 1, 0) from the OpenCV camera → world
// rotation R; PerspectiveFrustum fov and aspect from fy, width, height; near = the glTF
// camera's znear), a fresh tileset is loaded for it (so Cesium's one sort is made for exactly
// that camera), and the canvas is read back as PNG: OUT/ASSET/CAMERA.png. The npm packages come
// from .npm-tools/ (scripts/npm-tools.sh); the page and Cesium's static files (Build/Cesium)
// are served from 127.0.0.1 only; no Ion token, imagery, terrain, globe, sky or credits are
// requested; chromium is killed after the last image or after the time limit.
//
// Like gs3d.mjs, it rolls each camera by CESIUM_ROLL = 1e-4 rad about its view axis by
// default, and also moves it sideways by CESIUM_SHIFT = 1e-4 (about 0.003 px), which keeps
// Cesium's vertex shader off its degenerate eigenvector case (exactly axis-aligned footprints
// wider than tall, and exactly round ones, vanish or turn; cesium.html explains).
// CESIUM_ROLL=0 CESIUM_SHIFT=0 renders the cameras exactly, and that bug with them.
//
// Environment: CESIUM_ROLL (radians, default 1e-4), CESIUM_SHIFT (glTF units, default 1e-4),
// CESIUM_VIEW=ASSET/CAMERA (one view), CESIUM_DEBUG=1 (page logs on stderr),
// CESIUM_GL=1 (ANGLE on GL instead of SwiftShader), SPLATGL_ROOT (the splatgl checkout with
// target/debug/splatgl and .npm-tools/; default: the checkout this script is in). The server
// and chromium: common.mjs.
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { renderSuite, readGlb, writeGlb } from './common.mjs';
import { cesiumPlaceholders, IDENTITY } from './cesium-gltf.mjs';

// Where the glTF's world frame goes: the east-north-up frame at longitude 0, latitude 0,
// height 0 (ECEF (R, 0, 0), R = 6378137 m; east (0, 1, 0), north (0, 0, 1), up (1, 0, 0),
// exact numbers), glTF +y up, as Cesium turns y-up content: WORLD = ENU · Y_UP_TO_Z_UP,
// (x, y, z) → (R + y, x, −z). (Not the ECEF origin: Cesium's camera needs a cartographic
// position, Camera._updateCameraChanged, which the Earth's centre has not.) The cameras are
// mapped by WORLD too (cesium.html), so every view is the one of cameras.json exactly.
const R = 6378137;
const WORLD = [0, 1, 0, 0, 1, 0, 0, 0, 0, 0, -1, 0, R, 0, 0, 1];
// The root tile's transform, column-major. Cesium places a splat at
//   tile transform · Y_UP_TO_Z_UP · nodes[0].matrix · p_payload
// (GaussianSplatPrimitive.js transformTile, lines 1239-1249; the axis correction is
// getAxisCorrectionMatrix(Y, X) = Y_UP_TO_Z_UP, line 1003-1007: (x, y, z) → (x, −z, y)), and
// reads the SPZ payload's numbers as they are (GltfSpzLoader.js line 237-239:
// coordinateSystem "UNSPECIFIED"). splatgl writes the payload in SPZ's RUB axes as the
// extension's text asks (docs/formats.md, "glTF with SPZ compression"): p_payload = D · p,
// D = diag(−1, 1, −1) — a 180° turn about y, applied to rotations and (by parity) SH
// coefficients as well. So the transform is WORLD · (Y_UP_TO_Z_UP · D)⁻¹ = ENU · diag(−1, −1, 1)
// (Y_UP_TO_Z_UP · D · Y_UP_TO_Z_UP⁻¹ is the 180° turn about z), and a splat at glTF p lands at
// WORLD · p. SH view directions use the inverse of the same chain (GaussianSplatPrimitive.js
// line 1785-1807), so they end up in the payload's frame, where the SH were written.
const TILE_TRANSFORM = [0, -1, 0, 0, 0, 0, -1, 0, 1, 0, 0, 0, R, 0, 0, 1];
const yUpToZUp = ([x, y, z]) => [x, -z, y];

const numberEnv = (name, dflt) => {
  const v = Number(process.env[name] ?? dflt);
  if (!Number.isFinite(v)) { console.error(`cesium.mjs: ${name} is not a number`); process.exit(2); }
  return v;
};
const roll = numberEnv('CESIUM_ROLL', '1e-4');
const shift = numberEnv('CESIUM_SHIFT', '1e-4');
const banner = [
  roll !== 0 ? `cesium.mjs: cameras rolled by ${roll} rad (CESIUM_ROLL=0 for none)` : null,
  shift !== 0 ? `cesium.mjs: cameras shifted by ${shift} sideways (CESIUM_SHIFT=0 for none)` : null,
].filter(Boolean).join('\n') || null;

// Steps 1-3 above for one asset: DIR/content.glb and DIR/tileset.json.
function tilesetOf(a, { suite, splatgl, dir }) {
  const glb = path.join(dir, 'content.glb');
  execFileSync(splatgl, ['convert', path.join(suite, a.file), glb, '--spz-compress', '-f'], { stdio: 'pipe' });
  const { json, bin } = readGlb(fs.readFileSync(glb));
  const pos = cesiumPlaceholders(json, IDENTITY);
  fs.writeFileSync(glb, writeGlb(json, bin));
  // Bounding sphere of the decoded positions (POSITION min/max: glTF axes, as a reader
  // converting RUB decodes them; D turns them to the payload's), in the tile's frame (after
  // Y_UP_TO_Z_UP), with a margin for the splats' extent: it only lowers the near plane
  // Cesium fits to it (View.js line 183), never below the camera's.
  const [cx, cy, cz] = pos.min.map((lo, i) => (lo + pos.max[i]) / 2);
  const c = yUpToZUp([-cx, cy, -cz]);
  const half = Math.hypot(...pos.min.map((lo, i) => (pos.max[i] - lo) / 2));
  const tileset = {
    asset: { version: '1.1' },
    extensionsUsed: ['3DTILES_content_gltf'],
    extensions: { '3DTILES_content_gltf': {
      extensionsUsed: ['KHR_gaussian_splatting', 'KHR_gaussian_splatting_compression_spz_2'],
      extensionsRequired: ['KHR_gaussian_splatting', 'KHR_gaussian_splatting_compression_spz_2'],
    } },
    // Positive, or the root is never traversed: Cesium3DTilesetBaseTraversal.js line 54-59
    // stops when the tileset's own geometricError gives an SSE <= the maximum (16 px).
    geometricError: 1e6,
    root: {
      transform: TILE_TRANSFORM,
      boundingVolume: { sphere: [...c, half * 1.5 + 1] },
      geometricError: 0,
      refine: 'ADD',
      content: { uri: 'content.glb' },
    },
  };
  fs.writeFileSync(path.join(dir, 'tileset.json'), JSON.stringify(tileset));
  return { tileset: `/files/${a.name}/tileset.json` };
}

const root = process.env.SPLATGL_ROOT || path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
renderSuite({
  name: 'cesium',
  page: 'cesium.html',
  required: ['cesium/Build/Cesium/Cesium.js'],
  prefix: 'CESIUM',
  viewExtra: { roll, shift, world: WORLD },
  banner,
  prepare: tilesetOf,
  mounts: { '/cesium/': path.join(root, '.npm-tools/node_modules/cesium/Build/Cesium') },
  chromiumArgs: ['--force-device-scale-factor=1'],
});
