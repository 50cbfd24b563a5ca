// TypeScript declarations of the splatgl web API (web/splatgl.js over the wasm module).
// Checked by `tsc --noEmit` against web/example/example.ts (scripts/web.sh pack).

/** Three numbers: a point, a direction or an RGB colour (0–1). */
export type Vec3 = [number, number, number];

/** What a load says of the file. */
export interface LoadInfo {
  /** The name given to `load` ("default scene" for `loadDefault`). */
  name: string;
  /** The format read (e.g. "ply", "glb", "spz"); undefined for the default scene. */
  format?: string;
  /** Splats loaded. */
  splats: number;
  /** SH degree of the file (0–3). */
  sh_degree: number;
  /** glTF camera nodes in the file. */
  cameras: number;
  /** The loader's findings (what it dropped or doubted), one message each. */
  warnings: string[];
}

/** A view as `splatgl render` frames what is loaded. */
export interface View {
  eye: Vec3;
  target: Vec3;
  up: Vec3;
  /** Vertical field of view in degrees. */
  fovDeg: number;
}

/** Where `draw` blends: floating point (RGBA32F where the browser can blend it, else RGBA16F)
 * resolved into the canvas (the default), or the canvas's 8 bits. */
export type Target = 'float' | 'rgba8';

/** What one load may take (`Renderer.setLimits`). */
export interface Limits {
  /** Most bytes of a file (and of what a compressed format inflates to); default 1 GiB. */
  maxBytes: number;
  /** Most splats; default 4,194,304. */
  maxSplats: number;
}

/** GPU milliseconds of the stages of one draw (undefined: the stage did not run). */
export interface StageTimes {
  /** The pre-pass: the per-splat maths, once per splat (transform feedback). */
  prepassMs?: number;
  /** The copy of the pre-pass's records into the records texture. */
  copyMs?: number;
  /** The quads: vertices, rasterisation, fragments, blending. */
  quadsMs?: number;
}

/** A splat renderer on one WebGL2 canvas. */
export interface Renderer {
  /** Loads a file from its bytes; `name`'s extension helps detect the format. Throws with the
   * loader's message on a file that cannot be loaded (the previous scene stays). */
  load(bytes: ArrayBuffer | Uint8Array, name: string): Promise<LoadInfo>;
  /** Bounds what one load may take (an absent key keeps its bound); a load over a bound
   * throws an Error naming it and the previous scene stays drawn. */
  setLimits(limits: Partial<Limits>): void;
  /** The bounds of a load. */
  readonly limits: Limits;
  /** Loads the bundled default scene. */
  loadDefault(): LoadInfo;
  /** The view (world → eye, looking down −z) and projection matrices, 16 numbers each,
   * column-major. */
  setCamera(view: ArrayLike<number>, projection: ArrayLike<number>): void;
  /** Clears to `background` and draws (cull, sort back to front, blend); returns the CPU
   * milliseconds spent. */
  draw(background?: Vec3): number;
  /** Where `draw` blends (default 'float'). */
  setTarget(target: Target): void;
  /** Returns once the GL has drawn everything asked of it. */
  finish(): void;
  /** SH degree to draw (undefined: the file's). */
  setShDegree(degree: number | undefined): void;
  /** The default view at width × height. */
  defaultView(width: number, height: number): View;
  /** An 8-bit RGB PNG as `splatgl render --backend gl` renders it: glTF camera `gltfCamera`,
   * or the default view when it is negative. */
  renderPng(gltfCamera: number, width: number, height: number, background?: Vec3): Uint8Array;
  /** Splats loaded. */
  readonly splatCount: number;
  /** GL_VERSION / GL_RENDERER and whether RGBA16F blending is available. */
  glInfo(): string;
  /** Times each GPU stage of every draw from now on (or stops); throws where the browser has
   * no EXT_disjoint_timer_query_webgl2. */
  setStageTiming(on: boolean): void;
  /** GPU milliseconds of the last draw's stages (undefined until the page has returned to its
   * event loop after the draw: ask a frame later). */
  stageTimes(): StageTimes;
  /** Frees the renderer's GPU objects and its module memory; any later call throws. */
  dispose(): void;
}

/** A renderer on `canvas` (a WebGL2 context is created on it; the module loads on first use). */
export function create(canvas: HTMLCanvasElement): Promise<Renderer>;

/** Milliseconds per sort of `n` random splats by camera distance in wasm (after `create`). */
export function sortMs(n: number, reps?: number): number;

/** A view matrix looking from `eye` at `target` with `up` up (column-major, 16 numbers). */
export function lookAt(eye: Vec3, target: Vec3, up: Vec3): number[];

/** A perspective projection: vertical field of view in degrees, GL depth (column-major). */
export function perspective(fovDeg: number, aspect: number, near: number, far: number): number[];
