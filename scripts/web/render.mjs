#!/usr/bin/env node
// Renders one file (or the bundled default scene) with splatgl's web build in headless
// Chromium, as `splatgl render --backend gl` renders it natively without camera options: the
// default view (the default scene's own, else the cloud framed), RGBA16F blending, an 8-bit PNG.
//
//   node scripts/web/render.mjs FILE|--default OUT.png [--width W] [--height H] [--gltf-camera N]
//
// The page is scripts/conformance/splatgl-web.html (one view); the server and chromium are
// scripts/conformance/common.mjs's.
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { renderViews } from '../conformance/common.mjs';
import { fileURLToPath } from 'node:url';

const root = process.env.SPLATGL_ROOT || path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const args = process.argv.slice(2);
const opt = (flag, dflt) => {
  const i = args.indexOf(flag);
  return i >= 0 ? args.splice(i, 2)[1] : dflt;
};
const width = Number(opt('--width', '640'));
const height = Number(opt('--height', '480'));
const gltfCamera = Number(opt('--gltf-camera', '-1'));
const [input, outPng] = args;
if (!input || !outPng || !outPng.endsWith('.png') || !(width > 0) || !(height > 0)) {
  console.error('usage: render.mjs FILE|--default OUT.png [--width W] [--height H] [--gltf-camera N]');
  process.exit(2);
}
const dist = path.join(root, 'web/dist');
if (!fs.existsSync(path.join(dist, 'pkg/splatgl_web_bg.wasm'))) {
  console.error('render.mjs: web/dist is not built (./scripts/web.sh build)');
  process.exit(2);
}
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'splatgl-web-render-'));
let file = null;
if (input !== '--default') {
  const name = path.basename(input);
  fs.copyFileSync(input, path.join(tmp, name));
  file = `/files/${name}`;
}
const image = path.basename(outPng, '.png');
renderViews({
  name: 'render',
  page: 'splatgl-web.html',
  prefix: 'WEB',
  views: [{ image, file, gltfCamera, width, height, background: [0, 0, 0] }],
  tmp,
  out: path.dirname(path.resolve(outPng)),
  mounts: { '/web/': dist },
});
