// The web viewer: a file dropped, picked or given by ?url= (any format splatgl reads), orbit
// with the left button, pan with the right (or shift), zoom with the wheel, fly with WASD/QE,
// F frames the scene again. The splat count, SH degree and frame time are shown; a file that
// cannot be loaded shows splatgl's message and the page keeps the previous scene.
import * as splatgl from './splatgl.js';

const canvas = document.getElementById('view');
const stats = document.getElementById('stats');
const error = document.getElementById('error');
const background = [0, 0, 0];
let renderer;
let info = null;
let cam = null; // { eye, target, up, fovDeg }
let frameMs = 0;
let cpuMs = 0;
let dirty = true;

function showError(e) {
  error.textContent = String(e && e.message || e);
  window.splatglLastError = error.textContent; // for the tests
}

function resize() {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; dirty = true; }
}

function frameScene() {
  if (!info) return;
  cam = renderer.defaultView(canvas.width, canvas.height);
  dirty = true;
}

async function open(bytes, name) {
  try {
    info = await renderer.load(bytes, name);
    error.textContent = '';
    window.splatglLastError = '';
    frameScene();
  } catch (e) {
    showError(e);
  }
  window.splatglLoaded = (window.splatglLoaded || 0) + 1; // for the tests
}

// A file picked or dropped: its size checked against the renderer's limit before it is read.
async function openFile(f) {
  const { maxBytes } = renderer.limits;
  if (f.size > maxBytes) {
    showError(`${f.name}: ${f.size} bytes, more than the viewer's limit of ${maxBytes} bytes`);
    return;
  }
  await open(await f.arrayBuffer(), f.name);
}

// `url`'s body, read as it arrives and refused past `maxBytes` (a server's Content-Length
// is checked first, but a body may be longer than it says, or have none).
async function fetchBounded(url, maxBytes) {
  const res = await fetch(url);
  if (!res.ok) throw new Error(`${url}: HTTP ${res.status}`);
  const tooBig = (n) => new Error(`${url}: ${n} bytes or more, more than the viewer's limit of ${maxBytes} bytes`);
  const declared = Number(res.headers.get('content-length'));
  if (declared > maxBytes) throw tooBig(declared);
  const reader = res.body.getReader();
  const parts = [];
  let total = 0;
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    total += value.byteLength;
    if (total > maxBytes) { await reader.cancel(); throw tooBig(total); }
    parts.push(value);
  }
  const bytes = new Uint8Array(total);
  let at = 0;
  for (const p of parts) { bytes.set(p, at); at += p.byteLength; }
  return bytes;
}

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const len = (a) => Math.hypot(a[0], a[1], a[2]);
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const unit = (a) => scale(a, 1 / (len(a) || 1));

// Rotates `v` about unit axis `k` by `angle` (Rodrigues).
function rotate(v, k, angle) {
  const c = Math.cos(angle), s = Math.sin(angle);
  const kv = cross(k, v), d = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
  return add(add(scale(v, c), scale(kv, s)), scale(k, d * (1 - c)));
}

function orbit(dx, dy) {
  const up = unit(cam.up);
  let off = sub(cam.eye, cam.target);
  off = rotate(off, up, -dx * 0.005);
  const right = unit(cross(sub(cam.target, cam.eye), up));
  const pitched = rotate(off, right, -dy * 0.005);
  if (Math.abs(unit(pitched)[0] * up[0] + unit(pitched)[1] * up[1] + unit(pitched)[2] * up[2]) < 0.995) off = pitched;
  cam.eye = add(cam.target, off);
}

function pan(dx, dy) {
  const d = len(sub(cam.eye, cam.target));
  const f = unit(sub(cam.target, cam.eye));
  const right = unit(cross(f, cam.up));
  const up = cross(right, f);
  const k = d * 2 * Math.tan(cam.fovDeg * Math.PI / 360) / canvas.clientHeight;
  const move = add(scale(right, -dx * k), scale(up, dy * k));
  cam.eye = add(cam.eye, move);
  cam.target = add(cam.target, move);
}

let drag = null;
canvas.addEventListener('pointerdown', (e) => { drag = { x: e.clientX, y: e.clientY, pan: e.button !== 0 || e.shiftKey }; canvas.setPointerCapture(e.pointerId); });
canvas.addEventListener('pointerup', () => { drag = null; });
canvas.addEventListener('contextmenu', (e) => e.preventDefault());
canvas.addEventListener('pointermove', (e) => {
  if (!drag || !cam) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX; drag.y = e.clientY;
  if (drag.pan) pan(dx, dy); else orbit(dx, dy);
  dirty = true;
});
canvas.addEventListener('wheel', (e) => {
  if (!cam) return;
  e.preventDefault();
  const off = sub(cam.eye, cam.target);
  cam.eye = add(cam.target, scale(off, Math.exp(e.deltaY * 0.001)));
  dirty = true;
}, { passive: false });

const keys = new Set();
window.addEventListener('keydown', (e) => {
  if (e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement) return;
  if (e.key === 'f' || e.key === 'F') frameScene();
  keys.add(e.key.toLowerCase());
});
window.addEventListener('keyup', (e) => keys.delete(e.key.toLowerCase()));

function fly(dt) {
  if (!cam || keys.size === 0) return;
  const f = unit(sub(cam.target, cam.eye));
  const right = unit(cross(f, cam.up));
  const up = unit(cam.up);
  const speed = 0.5 * len(sub(cam.eye, cam.target)) * dt;
  let m = [0, 0, 0];
  if (keys.has('w')) m = add(m, f);
  if (keys.has('s')) m = sub(m, f);
  if (keys.has('d')) m = add(m, right);
  if (keys.has('a')) m = sub(m, right);
  if (keys.has('e')) m = add(m, up);
  if (keys.has('q')) m = sub(m, up);
  if (len(m) === 0) return;
  m = scale(unit(m), speed);
  cam.eye = add(cam.eye, m);
  cam.target = add(cam.target, m);
  dirty = true;
}

document.getElementById('file').addEventListener('change', async (e) => {
  const f = e.target.files[0];
  if (f) await openFile(f);
});
document.getElementById('sh').addEventListener('change', (e) => {
  renderer.setShDegree(e.target.value === '' ? undefined : Number(e.target.value));
  dirty = true;
});
document.getElementById('frame').addEventListener('click', frameScene);
window.addEventListener('dragover', (e) => { e.preventDefault(); document.body.classList.add('dragging'); });
window.addEventListener('dragleave', () => document.body.classList.remove('dragging'));
window.addEventListener('drop', async (e) => {
  e.preventDefault();
  document.body.classList.remove('dragging');
  const f = e.dataTransfer.files[0];
  if (f) await openFile(f);
});

let last = performance.now();
function tick(t) {
  const dt = Math.min(0.1, (t - last) / 1000);
  last = t;
  resize();
  fly(dt);
  if (dirty && cam) {
    const near = Math.max(1e-3, 0.01 * len(sub(cam.eye, cam.target)));
    renderer.setCamera(splatgl.lookAt(cam.eye, cam.target, cam.up),
                       splatgl.perspective(cam.fovDeg, canvas.width / canvas.height, near, 1e4 * near));
    const t0 = performance.now();
    try {
      cpuMs = renderer.draw(background);
    } catch (e) {
      showError(e);
    }
    frameMs = performance.now() - t0;
    dirty = false;
  }
  if (info) {
    const sh = document.getElementById('sh').value;
    stats.textContent = `${info.name}: ${info.splats.toLocaleString()} splats, SH degree ${sh === '' ? info.sh_degree : Math.min(Number(sh), info.sh_degree)}\n`
      + `frame ${frameMs.toFixed(1)} ms (CPU ${cpuMs.toFixed(1)} ms), ${canvas.width}×${canvas.height}`;
  }
  requestAnimationFrame(tick);
}

async function main() {
  try {
    renderer = await splatgl.create(canvas);
  } catch (e) {
    stats.textContent = '';
    showError(`splatgl cannot start here: ${e.message || e}`);
    return;
  }
  window.splatglRenderer = renderer; // for the tests and the console
  window.splatglOpen = open;
  resize();
  const params = new URLSearchParams(location.search);
  // ?maxBytes=N: the most bytes a file may have (default: the renderer's, 1 GiB).
  if (params.get('maxBytes')) renderer.setLimits({ maxBytes: Number(params.get('maxBytes')) });
  const url = params.get('url');
  if (url) {
    try {
      await open(await fetchBounded(url, renderer.limits.maxBytes), url.split('/').pop().split('?')[0]);
    } catch (e) {
      showError(e);
    }
  } else {
    info = renderer.loadDefault();
    frameScene();
  }
  window.splatglReady = true;
  requestAnimationFrame(tick);
}
main();
