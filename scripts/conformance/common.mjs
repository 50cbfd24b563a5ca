// What the conformance adapters for other renderers (gs3d.mjs, spark.mjs, cesium.mjs) share:
// the command line, each asset of a generated suite prepared for the renderer (by default
// converted to INRIA PLY with `splatgl convert --up y`) and its cameras turned into views, and
// a page served from 127.0.0.1 to headless Chromium, which POSTs each image back (written as
// OUT/ASSET/CAMERA.png); chromium is killed after the last image or after the time limit.
//
//   renderSuite({ name, page, required, prefix, viewExtra, banner, prepare, mounts, chromiumArgs })
//
// name: the adapter's name in messages ("gs3d" -> "gs3d.mjs: ..."); page: the HTML file next
// to this module that renders the views; required: files under .npm-tools/node_modules the
// page imports; prefix: the environment variables' prefix (PREFIX_VIEW=ASSET/CAMERA renders
// one view, PREFIX_DEBUG=1 asks the page to log, PREFIX_GL=1 runs ANGLE on GL instead of
// SwiftShader); viewExtra: fields added to every view; banner: printed on stderr first;
// prepare(asset, { suite, tmp, splatgl, dir }): writes what the page loads into `dir` (a
// folder of its own under the temporary folder) and returns the fields it adds to each of the
// asset's views (default: the PLY conversion, { ply: '/files/ASSET/asset.ply' }); mounts: URL
// prefixes served from folders, besides /files/ (the prepared files) and /npm/ (default:
// none); chromiumArgs: extra flags. SPLATGL_ROOT: the splatgl checkout (target/debug/splatgl,
// .npm-tools/); default: the checkout this module is in.
import { spawn, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));

// A GLB's JSON (first chunk) and BIN (second chunk, if any); .gltf: the JSON alone.
export const readGlb = (d) => {
  if (d.length >= 20 && d.readUInt32LE(0) === 0x46546c67) {
    const len = d.readUInt32LE(12);
    const json = JSON.parse(d.subarray(20, 20 + len).toString('utf8'));
    const at = 20 + len;
    const bin = d.length >= at + 8 ? d.subarray(at + 8, at + 8 + d.readUInt32LE(at)) : null;
    return { json, bin };
  }
  return { json: JSON.parse(d.toString('utf8')), bin: null };
};
export const writeGlb = (json, bin) => {
  let js = Buffer.from(JSON.stringify(json), 'utf8');
  js = Buffer.concat([js, Buffer.alloc((4 - (js.length % 4)) % 4, 0x20)]);
  const chunks = [Buffer.alloc(8), js];
  chunks[0].writeUInt32LE(js.length, 0);
  chunks[0].writeUInt32LE(0x4e4f534a, 4);
  if (bin) {
    const b = Buffer.concat([bin, Buffer.alloc((4 - (bin.length % 4)) % 4, 0)]);
    const h = Buffer.alloc(8);
    h.writeUInt32LE(b.length, 0);
    h.writeUInt32LE(0x004e4942, 4);
    chunks.push(h, b);
  }
  const body = Buffer.concat(chunks);
  const header = Buffer.alloc(12);
  header.writeUInt32LE(0x46546c67, 0);
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(12 + body.length, 8);
  return Buffer.concat([header, body]);
};

// The glTF JSON of an asset (.glb: its first chunk; .gltf: the file), for its cameras' znear.
export const gltfJson = (file) => readGlb(fs.readFileSync(file)).json;

// The default `prepare`: the asset as INRIA PLY, in the axes its numbers are written in.
const plyOf = (a, { suite, splatgl, dir }) => {
  execFileSync(splatgl, ['convert', path.join(suite, a.file), path.join(dir, 'asset.ply'), '--up', 'y', '-f'], { stdio: 'pipe' });
  return { ply: `/files/${a.name}/asset.ply` };
};

const types = { '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json',
                '.wasm': 'application/wasm', '.css': 'text/css', '.png': 'image/png', '.jpg': 'image/jpeg',
                '.glb': 'model/gltf-binary', '.html': 'text/html' };

export function renderSuite({ name, page, required, prefix, viewExtra = {}, banner = null,
                              prepare = plyOf, mounts = {}, chromiumArgs = [] }) {
  const me = `${name}.mjs`;
  // The splatgl checkout (its target/debug/splatgl and .npm-tools/): SPLATGL_ROOT, else the
  // folder two above this module (scripts/conformance/).
  const root = process.env.SPLATGL_ROOT || path.resolve(here, '../..');
  const args = process.argv.slice(2);
  const opt = (flag, dflt) => {
    const i = args.indexOf(flag);
    return i >= 0 ? args.splice(i, 2)[1] : dflt;
  };
  const splatgl = opt('--splatgl', path.join(root, 'target/debug/splatgl'));
  // --only ASSET[,ASSET...]: those assets only.
  const onlyArg = opt('--only', null);
  const only = onlyArg && new Set(onlyArg.split(','));
  const limitS = Number(opt('--timeout', '600'));
  const [suite, out] = args;
  if (!suite || !out) {
    console.error(`usage: ${me} SUITE OUT [--splatgl PATH] [--only ASSET[,ASSET...]] [--timeout S]`);
    process.exit(2);
  }
  const npm = path.join(root, '.npm-tools/node_modules');
  for (const p of required) {
    if (!fs.existsSync(path.join(npm, p))) {
      console.error(`${me}: ${p} not installed (scripts/npm-tools.sh)`);
      process.exit(2);
    }
  }
  if (banner) console.error(banner);
  const manifest = JSON.parse(fs.readFileSync(path.join(suite, 'manifest.json'), 'utf8'));
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), `splatgl-${name}-`));
  const views = [];
  const onlyView = process.env[`${prefix}_VIEW`];
  for (const a of manifest.assets) {
    if (only && !only.has(a.name)) continue;
    if (onlyView && !onlyView.startsWith(`${a.name}/`)) continue;
    const dir = path.join(tmp, a.name);
    fs.mkdirSync(dir, { recursive: true });
    let fields;
    try {
      fields = prepare(a, { suite, tmp, splatgl, dir });
    } catch (e) {
      console.error(`${a.name}: cannot prepare it: ${e.stderr || e.message}`);
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
      views.push({ image: c.image, ...fields, width: c.width, height: c.height,
                   gltfCamera: c.gltf_camera,
                   fy: j.fy, position: j.position, rotation: j.rotation,
                   ...viewExtra,
                   znear: gltfCameras[c.gltf_camera]?.perspective?.znear ?? 0.05 });
      if (Math.abs(j.fx - j.fy) > 1e-3 * j.fy || Math.abs(j.cx - c.width / 2) > 1e-3 || Math.abs(j.cy - c.height / 2) > 1e-3) {
        console.error(`${c.image}: fx != fy or the principal point is off centre; the page assumes neither`);
      }
    }
  }

  renderViews({ name, page, prefix, views, tmp, out, mounts, chromiumArgs, limitS, npm });
}

// Serves `page` (next to this module), views.json, the prepared files in `tmp` (/files/), the
// npm tools (/npm/) and `mounts` from 127.0.0.1 to headless Chromium, writes each image the
// page POSTs back as OUT/IMAGE.png (only the views' own image names), and exits with 0 when
// every view came back, else 1; `tmp` is removed once chromium has exited.
export function renderViews({ name, page, prefix, views, tmp, out, mounts = {}, chromiumArgs = [],
                              limitS = 600, npm = path.join(process.env.SPLATGL_ROOT || path.resolve(here, '../..'), '.npm-tools/node_modules') }) {
  const me = `${name}.mjs`;
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
    if (url === '/' || url === '/page') file = path.resolve(here, page); // relative to this folder, or absolute
    else if (url === '/page.mjs') file = path.join(here, 'page.mjs');
    else if (url === '/views.json') return send(res, 200, 'application/json', JSON.stringify(views));
    else {
      const served = { '/files/': tmp, '/npm/': npm, ...mounts };
      const at = Object.keys(served).find((p) => url.startsWith(p));
      if (at) file = inside(served[at], url.slice(at.length));
    }
    if (!file || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
      if (process.env[`${prefix}_DEBUG`]) console.error(`${me}: 404 ${url}`);
      return send(res, 404, 'text/plain', 'not found');
    }
    send(res, 200, types[path.extname(file)] || 'application/octet-stream', fs.readFileSync(file));
  });
  server.listen(0, '127.0.0.1', () => {
    const port = server.address().port;
    const chromium = ['chromium', 'chromium-browser'].find((b) => {
      try { execFileSync(b, ['--version'], { stdio: 'ignore' }); return true; } catch { return false; }
    });
    if (!chromium) { console.error(`${me}: chromium not found`); process.exit(2); }
    const browser = spawn(chromium, ['--headless', '--no-sandbox', ...(process.env[`${prefix}_GL`] ? ['--use-angle=gl', '--ignore-gpu-blocklist', '--use-gl=angle'] : ['--use-angle=swiftshader']),
      '--enable-unsafe-swiftshader', '--disable-extensions', '--no-first-run', ...chromiumArgs,
      `--user-data-dir=${path.join(tmp, 'profile')}`, `http://127.0.0.1:${port}/page${process.env[`${prefix}_DEBUG`] ? '?debug' : ''}`],
      { stdio: ['ignore', 'ignore', 'pipe'] });
    browser.stderr.on('data', () => {});
    const timer = setTimeout(() => { console.error(`${me}: timed out after ${limitS} s`); done(); }, limitS * 1000);
    finished.then(() => {
      clearTimeout(timer);
      console.log(`${me}: ${received} of ${views.length} images -> ${out}`);
      const code = received === views.length ? 0 : 1;
      // Remove the temporary folder (prepared files, chromium profile) only once chromium has exited:
      // it may still be writing its profile when it is killed.
      const cleanup = () => {
        try { fs.rmSync(tmp, { recursive: true, force: true, maxRetries: 5 }); } catch (e) {
          console.error(`${me}: could not remove ${tmp}: ${e.message}`);
        }
        process.exit(code);
      };
      server.close();
      if (browser.exitCode !== null || browser.signalCode !== null) cleanup();
      else { browser.once('exit', cleanup); browser.kill('SIGKILL'); setTimeout(cleanup, 5000); }
    });
  });
}
