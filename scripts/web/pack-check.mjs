#!/usr/bin/env node
// The npm package `splatgl` as a user gets it (scripts/web.sh pack): `npm pack web/dist` into
// target/web-pack/, the tarball installed (offline: it has no dependencies) into a temporary
// copy of web/example, `tsc --noEmit --checkJs` of the example against the package's
// declarations (TypeScript from .npm-tools, scripts/npm-tools.sh), and the example page
// rendered in headless Chromium (scripts/web/example-check.html). Prints `page: RESULT {json}`
// (files, splats, litPixels, title, or failure) on stderr; exits 1 on any failure.
//
//   node scripts/web/pack-check.mjs
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { renderViews } from '../conformance/common.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const root = process.env.SPLATGL_ROOT || path.resolve(here, '../..');
const fail = (msg) => { console.error(`pack-check.mjs: ${msg}`); process.exit(1); };
const dist = path.join(root, 'web/dist');
if (!fs.existsSync(path.join(dist, 'package.json'))) fail('web/dist/package.json missing: ./scripts/web.sh build');

const packDir = path.join(root, 'target/web-pack');
fs.mkdirSync(packDir, { recursive: true });
const packed = JSON.parse(execFileSync('npm', ['pack', dist, '--json', '--pack-destination', packDir],
  { encoding: 'utf8', stdio: ['ignore', 'pipe', 'inherit'] }))[0];
const files = packed.files.map((f) => f.path).sort();
const want = ['package.json', 'pkg/splatgl_web.js', 'pkg/splatgl_web_bg.wasm', 'splatgl.d.ts', 'splatgl.js'];
if (JSON.stringify(files) !== JSON.stringify(want)) fail(`the package holds ${files.join(', ')}; expected ${want.join(', ')}`);
const tarball = path.join(packDir, packed.filename);
console.error(`pack-check.mjs: ${tarball}: ${packed.size} bytes packed, ${packed.unpackedSize} unpacked`);

const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'splatgl-pack-'));
const app = path.join(tmp, 'app');
fs.cpSync(path.join(root, 'web/example'), app, { recursive: true });
fs.writeFileSync(path.join(app, 'package.json'), JSON.stringify({ name: 'splatgl-example', private: true, type: 'module' }));
execFileSync('npm', ['install', '--offline', '--no-audit', '--no-fund', '--loglevel=error', tarball],
  { cwd: app, stdio: ['ignore', 'inherit', 'inherit'] });

const tsc = path.join(root, '.npm-tools/node_modules/typescript/bin/tsc');
if (!fs.existsSync(tsc)) fail(`${tsc} missing: scripts/npm-tools.sh installs TypeScript`);
try {
  execFileSync(process.execPath, [tsc, '--noEmit', '--allowJs', '--checkJs', '--strict',
    '--target', 'es2022', '--module', 'es2022', '--moduleResolution', 'bundler', '--lib', 'es2022,dom',
    path.join(app, 'example.js')], { cwd: app, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
} catch (e) {
  fail(`tsc --noEmit on the example:\n${e.stdout}${e.stderr}`);
}
console.error('pack-check.mjs: tsc --noEmit --checkJs --strict: the example type-checks against splatgl.d.ts');
console.error(`page: FILES ${JSON.stringify(files)}`);

renderViews({
  name: 'pack-check',
  page: path.join(here, 'example-check.html'),
  prefix: 'WEB',
  views: [],
  tmp,
  out: tmp,
  mounts: { '/app/': app },
  limitS: 120,
});
