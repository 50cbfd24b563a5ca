#!/usr/bin/env node
// Frame time of splatgl's web build and of GaussianSplats3D, Spark and PlayCanvas in one
// browser (headless Chromium, SwiftShader WebGL2), on the same scene, cameras and canvas size:
//
//   node scripts/web/bench.mjs SCENE [OUT.json] [--width 1280] [--height 720] [--frames 10]
//        [--engines splatgl,gs3d,spark,playcanvas] [--splatgl PATH] [--target float|rgba8] [--warm 5]
//
// --warm: untimed frames per camera before the timed ones (fewer for large scenes).
// --target: where splatgl-web blends (`setTarget`; default its own default, float).
// --splatgl: the `splatgl` command used to convert the scene (default: target/release/splatgl,
// else target/debug/splatgl, else built with `cargo build --release -p splatgl-cli`); web/dist
// is built (`scripts/web.sh build`) when it is missing.
//
// SCENE is converted to INRIA PLY (`splatgl convert`), which every engine reads. The cameras:
// splatgl's default view of the scene (what `splatgl render` picks) and the same view orbited
// ±40° about the up axis. Each engine's page (scripts/web/bench/ENGINE.html) loads the PLY,
// and per camera lets its sort settle, then times frames: its render call and a 1-pixel read
// (which waits for the GPU). splatgl-web's frame includes its sort (on the page's thread);
// the others sort in workers, outside the timed frame. Also measured: splatgl's sort of 1M
// splats in wasm. Prints a table with each engine's time as a ratio to splatgl-web's.
// A benchmark, not a test: no pass or fail.
import { execFileSync, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const root = process.env.SPLATGL_ROOT || path.resolve(here, '../..');
const args = process.argv.slice(2);
const opt = (flag, dflt) => { const i = args.indexOf(flag); return i >= 0 ? args.splice(i, 2)[1] : dflt; };
const allEngines = ['splatgl', 'gs3d', 'spark', 'playcanvas'];
const engines = opt('--engines', allEngines.join(',')).split(',');
for (const e of engines) {
  if (!allEngines.includes(e)) { console.error(`bench.mjs: unknown engine ${e} (${allEngines.join(', ')})`); process.exit(2); }
}

/** The `splatgl` command: --splatgl, else a release or debug build, else one built now. */
function findSplatgl(given) {
  if (given) return given;
  const exe = process.platform === 'win32' ? 'splatgl.exe' : 'splatgl';
  for (const profile of ['release', 'debug']) {
    const p = path.join(root, 'target', profile, exe);
    if (fs.existsSync(p)) return p;
  }
  process.stderr.write('== no splatgl build found: cargo build --release -p splatgl-cli\n');
  execFileSync('cargo', ['build', '--release', '-p', 'splatgl-cli'], { cwd: root, stdio: 'inherit' });
  return path.join(root, 'target', 'release', exe);
}

if (args[0] === '--child') {
  // One engine's page: serve it, the views and the PLY; chromium; exit when it says done.
  const { renderViews } = await import('../conformance/common.mjs');
  const [, engine, shared] = args;
  // A folder of its own (renderViews removes it at the end).
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), `splatgl-web-bench-${engine}-`));
  fs.cpSync(shared, tmp, { recursive: true });
  renderViews({
    name: `bench-${engine}`, page: path.join(here, 'bench', `${engine}.html`), prefix: 'BENCH',
    views: JSON.parse(fs.readFileSync(path.join(tmp, 'views.json'), 'utf8')), tmp, out: tmp,
    mounts: { '/web/': path.join(root, 'web/dist'), '/bench/': path.join(here, 'bench') },
    limitS: 900,
  });
} else {
  const width = Number(opt('--width', '1280'));
  const height = Number(opt('--height', '720'));
  const frames = Number(opt('--frames', '10'));
  const splatglTarget = opt('--target', undefined);
  const warm = Number(opt('--warm', '5'));
  const given = opt('--splatgl', null);
  const [scene, outJson] = args;
  if (!scene) { console.error('usage: bench.mjs SCENE [OUT.json] [--width W] [--height H] [--frames N] [--engines E,..] [--splatgl PATH]'); process.exit(2); }
  const splatgl = findSplatgl(given);
  if (engines.includes('splatgl') && !fs.existsSync(path.join(root, 'web/dist/pkg/splatgl_web_bg.wasm'))) {
    process.stderr.write('== web/dist missing: scripts/web.sh build\n');
    execFileSync(path.join(root, 'scripts/web.sh'), ['build'], { cwd: root, stdio: 'inherit' });
  }
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'splatgl-web-bench-'));
  execFileSync(splatgl, ['convert', scene, path.join(tmp, 'scene.ply'), '-f'], { stdio: 'pipe' });
  // The default view as `splatgl render` prints it: --look-at eye,target,up --fov F.
  const said = spawnSync(splatgl, ['render', path.join(tmp, 'scene.ply'), '--backend', 'reference', '--width', '32',
    '--height', String(Math.max(1, Math.round(32 * height / width))), '-f', '-o', path.join(tmp, 'probe.png')], { encoding: 'utf8' });
  const m = /--look-at (\S+) --fov (\S+)/.exec(said.stderr + said.stdout);
  if (!m) { console.error(`bench.mjs: no camera from splatgl render:\n${said.stderr}`); process.exit(1); }
  const n = m[1].split(',').map(Number);
  const [eye, target, up, fovDeg] = [n.slice(0, 3), n.slice(3, 6), n.slice(6, 9), Number(m[2])];
  const orbit = (deg) => {
    const k = Math.hypot(...up), u = up.map((x) => x / k), a = deg * Math.PI / 180;
    const v = eye.map((x, i) => x - target[i]);
    const d = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    const c = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    return v.map((x, i) => target[i] + x * Math.cos(a) + c[i] * Math.sin(a) + u[i] * d * (1 - Math.cos(a)));
  };
  const views = [eye, orbit(40), orbit(-40)].map((e, camera) => ({
    file: '/files/scene.ply', width, height, eye: e, target, up, fovDeg, camera, frames, warm, splatglTarget,
  }));
  fs.writeFileSync(path.join(tmp, 'views.json'), JSON.stringify(views));
  const results = [];
  for (const engine of engines) {
    process.stderr.write(`== ${engine}\n`);
    const r = spawnSync(process.execPath, [fileURLToPath(import.meta.url), '--child', engine, tmp], { encoding: 'utf8' });
    for (const line of r.stderr.split('\n')) {
      const b = /^page: BENCH (.*)$/.exec(line);
      if (b) results.push(JSON.parse(b[1]));
      else if (line.startsWith('page: ')) process.stderr.write(`${line}\n`);
    }
  }
  fs.rmSync(tmp, { recursive: true, force: true });
  const mean = (e) => {
    const r = results.filter((x) => x.engine === e);
    return r.length === views.length ? r.reduce((s, x) => s + x.ms, 0) / r.length : null;
  };
  const base = mean('splatgl-web');
  const names = [...new Set(results.map((r) => r.engine))];
  console.log(`${path.basename(scene)}, ${width}×${height}, ${views.length} cameras, ${frames} frames each`);
  for (const e of names) {
    const per = results.filter((x) => x.engine === e).map((x) => x.ms.toFixed(1)).join(' / ');
    const mu = mean(e);
    console.log(`${e.padEnd(18)} ${per} ms${mu && base ? `  mean ${mu.toFixed(1)} ms = ${(mu / base).toFixed(2)}× splatgl-web` : ''}`);
  }
  // What each engine asked of WebGL (common.mjs wraps the context's methods), camera 1.
  for (const r of results.filter((x) => x.camera === 0 && x.gl)) {
    const g = r.gl, mb = (b) => (b / 1048576).toFixed(1);
    console.log(`${r.engine.padEnd(18)} per frame: ${g.draws} draw calls, ${g.instances} instances, ${g.vertices} vertices; allocated: textures ${mb(g.textureBytes)} MiB, buffers ${mb(g.bufferBytes)} MiB`);
  }
  for (const r of results.filter((x) => x.stages)) {
    const s = r.stages, f = (x) => (x === undefined ? '—' : x.toFixed(1));
    console.log(`splatgl-web camera ${r.camera + 1} GPU stages: pre-pass ${f(s.prepassMs)} ms, copy ${f(s.copyMs)} ms, quads ${f(s.quadsMs)} ms${s.error ? ` (${s.error})` : ''}`);
  }
  const sort = results.find((r) => r.sortMs1M !== undefined);
  if (sort) console.log(`splatgl sort of 1M splats in wasm: ${sort.sortMs1M.toFixed(1)} ms`);
  const missing = engines.length - names.length;
  if (missing) console.log(`(${missing} engine(s) reported nothing: see the page lines above)`);
  if (outJson) fs.writeFileSync(outJson, JSON.stringify({ scene, width, height, views, results }, null, 1));
}
