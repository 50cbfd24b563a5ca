#!/usr/bin/env node
// The web viewer's error path, in headless Chromium: web/dist/index.html is opened with
// ?url= naming a malformed file, then given a good one (GOOD, any file splatgl reads) as a
// dropped file is; the page (viewer-check.html) prints `page: RESULT {json}` on stderr:
// malformedError (the message shown), errorAfterGood, splats, litPixels, stats.
//
//   node scripts/web/viewer-check.mjs GOOD
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { renderViews } from '../conformance/common.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const root = process.env.SPLATGL_ROOT || path.resolve(here, '../..');
const good = process.argv[2];
if (!good) { console.error('usage: viewer-check.mjs GOOD'); process.exit(2); }
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'splatgl-web-check-'));
fs.copyFileSync(good, path.join(tmp, 'good.ply'));
// A PLY header that promises more vertices than the file holds.
fs.writeFileSync(path.join(tmp, 'malformed.ply'),
  'ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x01');
renderViews({
  name: 'viewer-check',
  page: path.join(here, 'viewer-check.html'),
  prefix: 'WEB',
  views: [],
  tmp,
  out: tmp,
  mounts: { '/web/': path.join(root, 'web/dist') },
  limitS: 120,
});
