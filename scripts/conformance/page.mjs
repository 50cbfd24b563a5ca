// What every adapter page (gs3d.html, spark.html, cesium.html, playcanvas.html) shares, served
// by common.mjs as /page.mjs: talking to the adapter (log, result, done), waiting a frame, the
// loop over the suite's views, and the suite's camera as a GL-style camera → world matrix.

/** Sends a line to the adapter's stderr. */
export const log = (m) => fetch('/log', { method: 'POST', body: String(m) });

/** Pixels of `canvas` (any canvas the page may read) brighter than near-black (R+G+B > 30). */
export function litPixels(canvas) {
  const probe = document.createElement('canvas');
  probe.width = canvas.width; probe.height = canvas.height;
  const ctx = probe.getContext('2d');
  ctx.drawImage(canvas, 0, 0);
  const px = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
  let lit = 0;
  for (let i = 0; i < px.length; i += 4) if (px[i] + px[i + 1] + px[i + 2] > 30) lit++;
  return lit;
}

/** Resolves at the next animation frame. */
export const frame = () => new Promise((r) => requestAnimationFrame(r));

/** Posts `canvas` as view `v`'s image (OUT/ASSET/CAMERA.png). */
export const postImage = (v, canvas) => fetch('/result', {
  method: 'POST', body: JSON.stringify({ image: v.image, png: canvas.toDataURL('image/png') }),
});

/**
 * The view's camera → world matrix in GL axes (x right, y up, looking down −z), column-major
 * (16 numbers), from the suite's OpenCV one (`rotation` rows: x right, y down, z forward).
 */
export const cameraToWorld = (v) => {
  const r = v.rotation;
  return [
    r[0][0], r[1][0], r[2][0], 0,
    -r[0][1], -r[1][1], -r[2][1], 0,
    -r[0][2], -r[1][2], -r[2][2], 0,
    v.position[0], v.position[1], v.position[2], 1,
  ];
};

/** The view's vertical field of view in degrees (from fy). */
export const fovDeg = (v) => 2 * Math.atan(0.5 * v.height / v.fy) * 180 / Math.PI;

/** Renders every view of views.json with `renderView`, logging failures, then says done. */
export async function runViews(renderView) {
  const views = await (await fetch('/views.json')).json();
  for (const v of views) {
    try { await renderView(v); } catch (e) { await log(`${v.image}: ${e && e.stack || e}`); }
  }
  await fetch('/done', { method: 'POST', body: '' });
}
