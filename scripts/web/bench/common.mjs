// What the benchmark pages share (served as /bench/common.mjs): the views, the timing loop and
// the report line. Each page renders the same PLY from the same cameras at the same size with
// its engine and reports `BENCH {"engine", "camera", "ms"}` per camera on the adapter's log.
import { log } from '/page.mjs';

export const frame = () => new Promise((r) => requestAnimationFrame(r));

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
  for (let i = 0; i < frames; i++) {
    const t0 = performance.now();
    await draw();
    sync();
    total += performance.now() - t0;
    // What the last frame drew, read before the page composites it (untimed).
    if (i === frames - 1) shown = lit();
    await frame();
  }
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
  await log(`BENCH ${JSON.stringify({ engine, camera: v.camera, ms, ...extra })}`);
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
