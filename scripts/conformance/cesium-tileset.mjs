#!/usr/bin/env node
// Renders a tileset splatgl built (`splatgl convert SCENE out/tileset.json --spz-compress`)
// with CesiumJS 1.145 (npm `cesium`) in headless Chromium, from the cameras of a 3DGS
// cameras.json in the tileset's frame (as `splatgl render out/tileset.json --print-camera-json`
// prints them), so its images can be compared with splatgl's of the same cameras.
//
//   node scripts/conformance/cesium-tileset.mjs TILESET.json CAMERAS.json OUT
//        [--max-sse PX[,PX...]] [--timeout S]
//
// OUT/view_I_sse_PX.png for camera I of CAMERAS.json and each maximumScreenSpaceError PX
// (default 16, Cesium's default); stderr has one line per image saying what Cesium drew
// ("view_0_sse_16: drawn N splats in T tiles after F frames").
//
// The same page and workarounds as cesium.mjs (the conformance adapter; cesium.html):
//  - every .glb under the tileset's folder is served rewritten by cesium-gltf.mjs — the COLOR_0
//    placeholder CesiumJS reads SPZ colours into, and the node matrix RUB_TO_GLTF that undoes
//    SPZ's RUB payload axes, which CesiumJS does not, so the splats are where the tiles'
//    bounding volumes (and splatgl) put them; tileset.json is served as written;
//  - the tileset's frame (z up, as 3D Tiles) goes to the east-north-up frame at longitude 0,
//    latitude 0, height 0 — (x, y, z) → (R + z, x, y), R = 6378137, exact numbers — by the
//    tileset's modelMatrix, and the cameras by the same matrix, so Cesium sees what splatgl's
//    cameras.json describes (Cesium's camera needs a cartographic position, so not the ECEF
//    origin);
//  - no roll or shift by default (CESIUM_ROLL, CESIUM_SHIFT as in cesium.mjs: a captured
//    scene has no exactly axis-aligned footprints); near plane 0.2 (splatgl's profile), far
//    10⁴ units; dynamic and foveated screen-space error off, so every tile the view wants is
//    loaded before the image is taken (`tilesLoaded`, and the splat sort made for the camera).
// Paths in tileset.json are Cesium's to resolve; only files inside the tileset's folder are
// served (common.mjs), from 127.0.0.1.
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { readGlb, writeGlb, renderViews } from './common.mjs';
import { cesiumPlaceholders, RUB_TO_GLTF } from './cesium-gltf.mjs';

const me = 'cesium-tileset.mjs';
const args = process.argv.slice(2);
const opt = (flag, dflt) => {
  const i = args.indexOf(flag);
  if (i >= 0 && i + 1 >= args.length) {
    console.error(`${me}: ${flag} needs a value`);
    process.exit(2);
  }
  return i >= 0 ? args.splice(i, 2)[1] : dflt;
};
const sses = opt('--max-sse', '16').split(',').map(Number);
const limitS = Number(opt('--timeout', '600'));
const [tilesetJson, camerasJson, out] = args;
if (!tilesetJson || !camerasJson || !out || sses.some((s) => !(s > 0))) {
  console.error(`usage: ${me} TILESET.json CAMERAS.json OUT [--max-sse PX[,PX...]] [--timeout S]`);
  process.exit(2);
}
const number = (name, dflt) => {
  const v = Number(process.env[name] ?? dflt);
  if (!Number.isFinite(v)) { console.error(`${me}: ${name} is not a number`); process.exit(2); }
  return v;
};
const root = process.env.SPLATGL_ROOT || path.resolve(path.dirname(new URL(import.meta.url).pathname), '../..');
const cesium = path.join(root, '.npm-tools/node_modules/cesium/Build/Cesium');
if (!fs.existsSync(path.join(cesium, 'Cesium.js'))) {
  console.error(`${me}: cesium/Build/Cesium/Cesium.js not installed (scripts/npm-tools.sh)`);
  process.exit(2);
}

// The tileset's folder, copied with its .glb content rewritten for CesiumJS (files only; no
// links followed out of it).
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'splatgl-cesium-tileset-'));
const src = path.dirname(path.resolve(tilesetJson));
let glbs = 0;
const copy = (from, to) => {
  fs.mkdirSync(to, { recursive: true });
  for (const e of fs.readdirSync(from, { withFileTypes: true })) {
    const [f, t] = [path.join(from, e.name), path.join(to, e.name)];
    if (e.isDirectory()) copy(f, t);
    else if (!e.isFile()) continue;
    else if (e.name.endsWith('.glb')) {
      const { json, bin } = readGlb(fs.readFileSync(f));
      try { cesiumPlaceholders(json, RUB_TO_GLTF); } catch (err) {
        console.error(`${me}: ${f}: ${err.message}`);
        process.exit(2);
      }
      fs.writeFileSync(t, writeGlb(json, bin));
      glbs++;
    } else fs.copyFileSync(f, t);
  }
};
copy(src, path.join(tmp, 'tileset'));
console.error(`${me}: ${glbs} tile contents rewritten for CesiumJS`);

const R = 6378137;
// Tileset frame → ECEF: x east, y north, z up at (R, 0, 0); column-major.
const PLACE = [0, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, R, 0, 0, 1];
const cams = JSON.parse(fs.readFileSync(camerasJson, 'utf8'));
const views = [];
cams.forEach((c, i) => {
  if (Math.abs(c.fx - c.fy) > 1e-3 * c.fy) console.error(`camera ${i}: fx != fy; the page takes fy`);
  for (const sse of sses) {
    views.push({
      image: `view_${i}_sse_${sse}`, tileset: `/files/tileset/${path.basename(tilesetJson)}`,
      width: c.width, height: c.height, fy: c.fy, position: c.position, rotation: c.rotation,
      world: PLACE, modelMatrix: PLACE, maximumScreenSpaceError: sse,
      roll: number('CESIUM_ROLL', 0), shift: number('CESIUM_SHIFT', 0),
      znear: 0.2, zfar: 1e4, maxFrames: 3000, report: true,
    });
  }
});
renderViews({
  name: 'cesium-tileset', page: 'cesium.html', prefix: 'CESIUM', views, tmp, out, limitS,
  mounts: { '/cesium/': cesium }, chromiumArgs: ['--force-device-scale-factor=1'],
});
