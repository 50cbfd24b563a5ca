// What the benchmark pages share (served as /bench/common.mjs): the views, the timing loop and
// the report line. Each page renders the same PLY from the same cameras at the same size with
// its engine and reports `BENCH {"engine", "camera", "ms"}` per camera on the adapter's log.
import { log } from '/page.mjs';

export const frame = () => new Promise((r) => requestAnimationFrame(r));

// What each engine asks of WebGL, counted by wrapping WebGL2RenderingContext's methods before
// any page makes a context (this module is imported first): draw calls, instances and vertices
// per frame (in `time`), and the bytes of every texture and buffer allocated (resident: what
// the engine uploaded; the canvas itself not counted).
const counts = { draws: 0, instances: 0, vertices: 0, textureBytes: 0, bufferBytes: 0 };
{
  const G = WebGL2RenderingContext;
  const P = G.prototype;
  // Bytes per texel of the sized formats the engines use (others counted as 4).
  const texel = new Map([[G.RGBA8, 4], [G.RGBA16F, 8], [G.RGBA32F, 16], [G.RGBA32UI, 16],
    [G.RGBA16UI, 8], [G.RG32UI, 8], [G.RG32F, 8], [G.R32UI, 4], [G.R32F, 4], [G.RGB32F, 12],
    [G.RGBA8UI, 4], [G.RG16F, 4], [G.R16F, 2], [G.RGB8, 3], [G.R8, 1], [G.RG8, 2],
    [G.SRGB8_ALPHA8, 4], [G.RGB16F, 6], [G.RGBA16I, 8], [G.RGBA32I, 16], [G.RG16UI, 4]]);
  const wrap = (name, f) => {
    const orig = P[name];
    P[name] = function (...a) { f(a); return orig.apply(this, a); };
  };
  wrap('drawArrays', (a) => { counts.draws++; counts.instances++; counts.vertices += a[2]; });
  wrap('drawElements', (a) => { counts.draws++; counts.instances++; counts.vertices += a[1]; });
  wrap('drawArraysInstanced', (a) => { counts.draws++; counts.instances += a[3]; counts.vertices += a[2] * a[3]; });
  wrap('drawElementsInstanced', (a) => { counts.draws++; counts.instances += a[4]; counts.vertices += a[1] * a[4]; });
  const bytes = (fmt, w, h, d) => (texel.get(fmt) ?? 4) * w * h * d;
  wrap('texStorage2D', (a) => { counts.textureBytes += bytes(a[2], a[3], a[4], 1); });
  wrap('texStorage3D', (a) => { counts.textureBytes += bytes(a[2], a[3], a[4], a[5]); });
  wrap('texImage2D', (a) => { if (a.length >= 8 && typeof a[3] === 'number') counts.textureBytes += bytes(a[2], a[3], a[4], 1); });
  wrap('texImage3D', (a) => { counts.textureBytes += bytes(a[2], a[3], a[4], a[5]); });
  wrap('bufferData', (a) => {
    const v = a[1];
    counts.bufferBytes += typeof v === 'number' ? v : (v && v.byteLength) || 0;
  });
}

/** Draw calls, instances and vertices per frame of the last `time`, and the bytes of every
 * texture and buffer allocated so far. */
export const glCounts = () => ({ ...lastFrame, textureBytes: counts.textureBytes, bufferBytes: counts.bufferBytes });
let lastFrame = {};

/** The views (views.json): one per camera, each { file, width, height, eye, target, up, fovDeg, camera, frames }. */
export async function views() {
  return (await fetch('/views.json')).json();
}

/** Times `frames` calls of `draw` (each followed by `sync`, a 1-pixel read that waits for the
 * GPU) after `warm` untimed ones: { ms per frame, lit: `lit()` after the last frame }. */
export async function time(draw, sync, { warm = 5, frames = 10 } = {}, lit = () => null) {
  for (let i = 0; i < warm; i++) { await draw(); sync(); await frame(); }
  let total = 0;
  let shown = null;
  const before = { ...counts };
  for (let i = 0; i < frames; i++) {
    const t0 = performance.now();
    await draw();
    sync();
    total += performance.now() - t0;
    // What the last frame drew, read before the page composites it (untimed).
    if (i === frames - 1) shown = lit();
    await frame();
  }
  const per = (k) => Math.round((counts[k] - before[k]) / frames);
  lastFrame = { draws: per('draws'), instances: per('instances'), vertices: per('vertices') };
  return { ms: total / frames, lit: shown };
}

/** A 1-pixel read of `gl`'s bound framebuffer: returns once everything asked is drawn. */
export const syncOf = (gl) => {
  const px = new Uint8Array(4);
  return () => gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
};

/** The fraction of the bound framebuffer's pixels that are not black: the splats were drawn. */
export function litFraction(gl, w, h) {
  const px = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  let lit = 0;
  for (let i = 0; i < px.length; i += 4) if (px[i] + px[i + 1] + px[i + 2] > 24) lit++;
  return lit / (w * h);
}

export async function report(engine, v, ms, extra = {}) {
  await log(`BENCH ${JSON.stringify({ engine, camera: v.camera, ms, gl: glCounts(), ...extra })}`);
}

export async function done() {
  await fetch('/done', { method: 'POST', body: '' });
}

export function canvasFor(v) {
  const c = document.createElement('canvas');
  c.width = v.width; c.height = v.height;
  c.style.width = `${v.width}px`; c.style.height = `${v.height}px`;
  document.body.appendChild(c);
  return c;
}
