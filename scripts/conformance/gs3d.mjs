#!/usr/bin/env node
// Renders a splatgl conformance suite with GaussianSplats3D 0.4.7 in headless Chromium, so
// `splatgl conformance run SUITE --images OUT` grades a renderer splatgl did not write.
//
//   node scripts/conformance/gs3d.mjs SUITE OUT [--splatgl target/debug/splatgl] [--only ASSET]
//
// Each asset is converted to INRIA PLY with `splatgl convert --up y` (glTF axes kept; node
// transforms baked, which the RC's math allows), each camera of its cameras.json is set on a
// three.js PerspectiveCamera (fov from fy, znear from the suite), and the canvas is read
// back as PNG: OUT/ASSET/CAMERA.png. The npm packages come from .npm-tools/ (scripts/npm-tools.sh);
// the page is served from 127.0.0.1 only, and chromium is killed after the last image or
// after the time limit.
//
// The page works around two GaussianSplats3D 0.4.7 bugs that only tiny scenes like the
// suite's show (see gs3d.html: fixDrawRange, fixCovariances), and by default rolls each
// camera by GS3D_ROLL = 1e-4 rad about its view axis, which keeps GS3D's vertex shader off
// its degenerate eigenvector case (exactly axis-aligned footprints; gs3d.html explains).
// GS3D_ROLL=0 renders the cameras exactly, and that bug with them.
//
// Environment: GS3D_ROLL (radians, default 1e-4), GS3D_VIEW=ASSET/CAMERA (one view),
// GS3D_DEBUG=1 (page logs on stderr), GS3D_GL=1 (ANGLE on GL instead of SwiftShader),
// SPLATGL_ROOT (the splatgl checkout with target/debug/splatgl and .npm-tools/; default: the
// checkout this script is in).
import { spawn, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
// The splatgl checkout (its target/debug/splatgl and .npm-tools/): SPLATGL_ROOT, else the
// folder two above this script (scripts/conformance/).
const root = process.env.SPLATGL_ROOT || path.resolve(here, '../..');
const args = process.argv.slice(2);
const opt = (name, dflt) => {
  const i = args.indexOf(name);
  return i >= 0 ? args.splice(i, 2)[1] : dflt;
};
const splatgl = opt('--splatgl', path.join(root, 'target/debug/splatgl'));
const only = opt('--only', null);
const limitS = Number(opt('--timeout', '600'));
const [suite, out] = args;
if (!suite || !out) {
  console.error('usage: gs3d.mjs SUITE OUT [--splatgl PATH] [--only ASSET] [--timeout S]');
  process.exit(2);
}
const npm = path.join(root, '.npm-tools/node_modules');
for (const p of ['three/build/three.module.js', '@mkkellogg/gaussian-splats-3d/build/gaussian-splats-3d.module.js']) {
  if (!fs.existsSync(path.join(npm, p))) {
    console.error(`gs3d.mjs: ${p} not installed (scripts/npm-tools.sh)`);
    process.exit(2);
  }
}
// The glTF JSON of an asset (.glb: its first chunk; .gltf: the file), for its cameras' znear.
const gltfJson = (file) => {
  const d = fs.readFileSync(file);
  if (d.length >= 20 && d.readUInt32LE(0) === 0x46546c67) {
    const len = d.readUInt32LE(12);
    return JSON.parse(d.subarray(20, 20 + len).toString('utf8'));
  }
  return JSON.parse(d.toString('utf8'));
};
const manifest = JSON.parse(fs.readFileSync(path.join(suite, 'manifest.json'), 'utf8'));
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'splatgl-gs3d-'));
const views = [];
const onlyView = process.env.GS3D_VIEW;
const roll = Number(process.env.GS3D_ROLL ?? '1e-4');
if (!Number.isFinite(roll)) { console.error('gs3d.mjs: GS3D_ROLL is not a number'); process.exit(2); }
if (roll !== 0) console.error(`gs3d.mjs: cameras rolled by ${roll} rad (GS3D_ROLL=0 for none)`);
for (const a of manifest.assets) {
  if (only && a.name !== only) continue;
  if (onlyView && !onlyView.startsWith(`${a.name}/`)) continue;
  const ply = path.join(tmp, `${a.name}.ply`);
  try {
    execFileSync(splatgl, ['convert', path.join(suite, a.file), ply, '--up', 'y', '-f'], { stdio: 'pipe' });
  } catch (e) {
    console.error(`${a.name}: convert failed: ${e.stderr}`);
    continue;
  }
  const cams = JSON.parse(fs.readFileSync(path.join(suite, a.cameras_json), 'utf8'));
  let gltfCameras = [];
  try { gltfCameras = gltfJson(path.join(suite, a.file)).cameras || []; } catch (e) {
    console.error(`${a.name}: cannot read the glTF cameras (${e.message}); znear 0.05`);
  }
  for (const c of a.cameras) {
    const j = cams[c.cameras_json_index];
    if (onlyView && c.image !== onlyView) continue;
    views.push({ image: c.image, ply: `/ply/${a.name}.ply`, width: c.width, height: c.height,
                 fy: j.fy, position: j.position, rotation: j.rotation,
                 roll,
                 znear: gltfCameras[c.gltf_camera]?.perspective?.znear ?? 0.05 });
    if (Math.abs(j.fx - j.fy) > 1e-3 * j.fy || Math.abs(j.cx - c.width / 2) > 1e-3 || Math.abs(j.cy - c.height / 2) > 1e-3) {
      console.error(`${c.image}: fx != fy or the principal point is off centre; the page assumes neither`);
    }
  }
}

const send = (res, code, type, body) => { res.writeHead(code, { 'content-type': type }); res.end(body); };
const inside = (base, rel) => {
  const p = path.resolve(base, '.' + path.posix.normalize('/' + rel));
  return p.startsWith(base + path.sep) ? p : null;
};
let done;
const finished = new Promise((r) => { done = r; });
let received = 0;
const expected = new Set(views.map((v) => v.image));
const server = http.createServer((req, res) => {
  let url;
  try { url = decodeURIComponent(req.url.split('?')[0]); } catch { return send(res, 400, 'text/plain', 'bad url'); }
  if (req.method === 'POST') {
    let body = '';
    req.on('data', (d) => { body += d; });
    req.on('end', () => {
      if (url === '/result') {
        let msg;
        try { msg = JSON.parse(body); } catch { return send(res, 400, 'text/plain', 'bad json'); }
        const { image, png } = msg;
        // Only the suite's own image names: nothing is written outside OUT.
        if (!expected.has(image) || typeof png !== 'string') return send(res, 400, 'text/plain', 'unknown image');
        const file = path.join(out, `${image}.png`);
        fs.mkdirSync(path.dirname(file), { recursive: true });
        fs.writeFileSync(file, Buffer.from(png.split(',')[1], 'base64'));
        received++;
      } else if (url === '/log') {
        console.error(`page: ${body}`);
      } else if (url === '/done') {
        done();
      }
      send(res, 200, 'text/plain', 'ok');
    });
    return;
  }
  let file = null;
  let type = 'application/octet-stream';
  if (url === '/' || url === '/page') { file = path.join(here, 'gs3d.html'); type = 'text/html'; }
  else if (url === '/views.json') return send(res, 200, 'application/json', JSON.stringify(views));
  else if (url.startsWith('/npm/')) { file = inside(npm, url.slice(5)); type = 'text/javascript'; }
  else if (url.startsWith('/ply/')) file = inside(tmp, url.slice(5));
  if (!file || !fs.existsSync(file)) return send(res, 404, 'text/plain', 'not found');
  send(res, 200, type, fs.readFileSync(file));
});
server.listen(0, '127.0.0.1', () => {
  const port = server.address().port;
  const chromium = ['chromium', 'chromium-browser'].find((b) => {
    try { execFileSync(b, ['--version'], { stdio: 'ignore' }); return true; } catch { return false; }
  });
  if (!chromium) { console.error('gs3d.mjs: chromium not found'); process.exit(2); }
  const browser = spawn(chromium, ['--headless', '--no-sandbox', ...(process.env.GS3D_GL ? ['--use-angle=gl', '--ignore-gpu-blocklist', '--use-gl=angle'] : ['--use-angle=swiftshader']),
    '--enable-unsafe-swiftshader', '--disable-extensions', '--no-first-run',
    `--user-data-dir=${path.join(tmp, 'profile')}`, `http://127.0.0.1:${port}/page${process.env.GS3D_DEBUG ? '?debug' : ''}`],
    { stdio: ['ignore', 'ignore', 'pipe'] });
  browser.stderr.on('data', () => {});
  const timer = setTimeout(() => { console.error(`gs3d.mjs: timed out after ${limitS} s`); done(); }, limitS * 1000);
  finished.then(() => {
    clearTimeout(timer);
    console.log(`gs3d.mjs: ${received} of ${views.length} images -> ${out}`);
    const code = received === views.length ? 0 : 1;
    // Remove the temporary folder (PLYs, chromium profile) only once chromium has exited:
    // it may still be writing its profile when it is killed.
    const cleanup = () => {
      try { fs.rmSync(tmp, { recursive: true, force: true, maxRetries: 5 }); } catch (e) {
        console.error(`gs3d.mjs: could not remove ${tmp}: ${e.message}`);
      }
      process.exit(code);
    };
    server.close();
    if (browser.exitCode !== null || browser.signalCode !== null) cleanup();
    else { browser.once('exit', cleanup); browser.kill('SIGKILL'); setTimeout(cleanup, 5000); }
  });
});
