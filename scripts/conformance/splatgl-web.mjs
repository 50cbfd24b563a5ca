#!/usr/bin/env node
// Renders a splatgl conformance suite with splatgl's web build (web/dist: the wasm module over
// WebGL2) in headless Chromium (SwiftShader), so `splatgl conformance run SUITE --images OUT`
// grades the same renderer compiled for the browser.
//
//   node scripts/conformance/splatgl-web.mjs SUITE OUT [--only ASSET] [--timeout S]
//
// Each asset's file is loaded as it is (no conversion) and each camera rendered from the
// asset's own glTF camera node, at the manifest's size, over the manifest's background: what
// `conformance run --backend gl` renders natively. The page is splatgl-web.html; the server,
// chromium and the files are common.mjs's. Environment: WEB_VIEW=ASSET/CAMERA (one view),
// WEB_DEBUG=1, WEB_GL=1 (ANGLE on GL instead of SwiftShader), SPLATGL_ROOT.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { renderSuite } from './common.mjs';

const root = process.env.SPLATGL_ROOT || path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const dist = path.join(root, 'web/dist');
if (!fs.existsSync(path.join(dist, 'pkg/splatgl_web_bg.wasm'))) {
  console.error('splatgl-web.mjs: web/dist is not built (./scripts/web.sh build)');
  process.exit(2);
}
const suite = process.argv[2];
const background = suite ? JSON.parse(fs.readFileSync(path.join(suite, 'manifest.json'), 'utf8')).background ?? [0, 0, 0] : [0, 0, 0];

renderSuite({
  name: 'splatgl-web',
  page: 'splatgl-web.html',
  required: [],
  prefix: 'WEB',
  viewExtra: { background },
  mounts: { '/web/': dist },
  prepare: (a, { suite, dir }) => {
    const name = path.basename(a.file);
    fs.copyFileSync(path.join(suite, a.file), path.join(dir, name));
    return { file: `/files/${a.name}/${name}` };
  },
});
