// splatgl in the browser: the JavaScript API over the wasm module (crates/splatgl-web).
//
//   import * as splatgl from './splatgl.js';
//   const r = await splatgl.create(canvas);           // a WebGL2 context on the canvas
//   await r.load(bytes, 'scene.ply');                 // any format splatgl reads
//   r.setCamera(view, proj);                          // column-major 4×4 matrices (16 numbers)
//   r.draw();                                         // cull, sort back to front, blend
//   r.dispose();                                      // frees its GPU objects
//
// Types: splatgl.d.ts (checked with tsc --noEmit --checkJs against example/example.js).
// Errors (no WebGL2, a file that cannot be loaded, bad matrices) are thrown as Error with
// splatgl's message; after a failed load the renderer keeps what it had.
import init, { Renderer, sort_ms } from './pkg/splatgl_web.js';

let ready = null;

/** A renderer on `canvas` (loads the wasm module on first use). */
export async function create(canvas) {
  ready ??= init({ module_or_path: new URL('./pkg/splatgl_web_bg.wasm', import.meta.url) });
  await ready;
  return new SplatglRenderer(new Renderer(canvas));
}

/** Milliseconds per sort of `n` random splats by camera distance in wasm (one thread),
 * averaged over `reps` (after `create`). */
export function sortMs(n, reps = 10) { return sort_ms(n, reps); }

class SplatglRenderer {
  constructor(inner) { this.inner = inner; }

  /** Loads a file from its bytes (ArrayBuffer or Uint8Array); `name` gives its format. Returns
   * { name, format, splats, sh_degree, cameras, warnings } (`format` undefined for none). */
  async load(bytes, name) {
    const data = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes);
    // Checked before the bytes are copied into the module's memory.
    const { maxBytes } = this.limits;
    if (data.byteLength > maxBytes) {
      throw new Error(`${name}: ${data.byteLength} bytes, more than the renderer's limit of ${maxBytes} bytes (setLimits({ maxBytes }))`);
    }
    return info(this.inner.load(data, name));
  }

  /** Bounds what one load may take: `maxBytes` of file (default 1 GiB; also what a compressed
   * format may inflate to) and `maxSplats` (default 4,194,304); an absent key keeps its bound.
   * A load over a bound throws an Error naming it, and the previous scene stays drawn. */
  setLimits({ maxBytes, maxSplats } = {}) { this.inner.set_limits(maxBytes, maxSplats); }

  /** The bounds of a load: { maxBytes, maxSplats }. */
  get limits() {
    const l = JSON.parse(this.inner.limits());
    return { maxBytes: l.max_bytes, maxSplats: l.max_splats };
  }

  /** Loads the bundled default scene. */
  loadDefault() { return info(this.inner.load_default()); }

  /** Where `draw` blends: 'float' (the default: RGBA32F where the browser blends it, else
   * RGBA16F, resolved into the canvas) or 'rgba8' (in the canvas's 8 bits: colours above 1
   * clamped per splat). */
  setTarget(target) { this.inner.set_target(target); }

  /** Times each GPU stage of every draw from now on (or stops): throws where the browser has
   * no EXT_disjoint_timer_query_webgl2. */
  setStageTiming(on) { this.inner.set_stage_timing(on); }

  /** GPU milliseconds of the last draw's stages: { prepassMs, copyMs, quadsMs }, each
   * undefined when it did not run, timing is off, or the result is not there yet (WebGL
   * gives results only after the page returned to its event loop: ask a frame later). */
  stageTimes() {
    const t = JSON.parse(this.inner.stage_times());
    return { prepassMs: t.prepass_ms ?? undefined, copyMs: t.copy_ms ?? undefined, quadsMs: t.quads_ms ?? undefined };
  }

  /** Frees the renderer's GPU objects and its memory in the module; any later call throws. */
  dispose() {
    if (this.inner === disposed) return;
    this.inner.dispose();
    this.inner.free();
    this.inner = disposed;
  }

  /** The view (world → eye, looking down −z) and projection matrices, column-major. */
  setCamera(view, proj) { this.inner.set_camera(Float32Array.from(view), Float32Array.from(proj)); }

  /** Clears to `background` ([r, g, b], 0–1) and draws; returns the CPU milliseconds spent. */
  draw(background = [0, 0, 0]) { return this.inner.draw(background[0], background[1], background[2]); }

  /** Returns once the GL has drawn everything asked of it (a 1-pixel read). */
  finish() { this.inner.finish(); }

  /** SH degree to draw (`undefined`: the file's). */
  setShDegree(degree) { this.inner.set_sh_degree(degree); }

  /** The default view at width × height: { eye, target, up, fovDeg }. */
  defaultView(width, height) {
    const v = this.inner.default_view(width, height);
    return { eye: [v[0], v[1], v[2]], target: [v[3], v[4], v[5]], up: [v[6], v[7], v[8]], fovDeg: v[9] };
  }

  /** An 8-bit RGB PNG (Uint8Array) as `splatgl render --backend gl` renders it: glTF camera
   * `gltfCamera`, or the default view when it is negative. */
  renderPng(gltfCamera, width, height, background = [0, 0, 0]) {
    return this.inner.render_png(gltfCamera, width, height, background[0], background[1], background[2]);
  }

  /** The number of splats loaded. */
  get splatCount() { return this.inner.splat_count(); }

  /** GL_VERSION / GL_RENDERER and whether RGBA16F blending is available. */
  glInfo() { return this.inner.gl_info(); }
}

/** What a disposed renderer holds: any use throws with a message that says why. */
const disposed = new Proxy({}, { get() { throw new Error('splatgl: this renderer was disposed'); } });

/** The loader's JSON answer, with `undefined` (not null) for what is absent. */
function info(json) {
  const o = JSON.parse(json);
  for (const k of Object.keys(o)) if (o[k] === null) o[k] = undefined;
  return o;
}

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const unit = (a) => { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; };

/** A view matrix looking from `eye` at `target` with `up` up (column-major). */
export function lookAt(eye, target, up) {
  const f = unit(sub(target, eye));
  const s = unit(cross(f, up));
  const u = cross(s, f);
  return [s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
          -dot(s, eye), -dot(u, eye), dot(f, eye), 1];
}

/** A perspective projection (vertical field of view in degrees; column-major, GL depth). */
export function perspective(fovDeg, aspect, near, far) {
  const t = 1 / Math.tan(fovDeg * Math.PI / 360);
  return [t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (far + near) / (near - far), -1,
          0, 0, 2 * far * near / (near - far), 0];
}
