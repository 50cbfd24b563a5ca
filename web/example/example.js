// The splatgl package in a page: a renderer on the canvas, the bundled default scene (or
// ?url=FILE), framed as `splatgl render` frames it, drawn once. Type-checked against the
// package's declarations (`tsc --noEmit --checkJs`, scripts/web.sh pack).
import * as splatgl from 'splatgl';

const canvas = /** @type {HTMLCanvasElement} */ (document.getElementById('view'));
const renderer = await splatgl.create(canvas);
const url = new URLSearchParams(location.search).get('url');
/** @type {splatgl.LoadInfo} */
const info = url
  ? await renderer.load(await (await fetch(url)).arrayBuffer(), url)
  : renderer.loadDefault();
const view = renderer.defaultView(canvas.width, canvas.height);
renderer.setCamera(
  splatgl.lookAt(view.eye, view.target, view.up),
  splatgl.perspective(view.fovDeg, canvas.width / canvas.height, 0.05, 1000),
);
const ms = renderer.draw([0, 0, 0]);
renderer.finish();
document.title = `splatgl: ${info.splats} splats (${info.format ?? 'built in'}), ${ms.toFixed(1)} ms`;
// For the package check (scripts/web/pack-check.mjs): what was drawn.
Object.assign(window, { splatglExample: { splats: info.splats, format: info.format } });
