#!/usr/bin/env node
// Renders a splatgl conformance suite with PlayCanvas 2.23 (npm playcanvas), which reads
// KHR_gaussian_splatting glTF itself since 2.21, in headless Chromium, so
// `splatgl conformance run SUITE --images OUT` grades an engine splatgl did not write.
//
//   node scripts/conformance/playcanvas.mjs SUITE OUT [--splatgl target/debug/splatgl] [--only ASSET]
//
// Each asset's .glb / .gltf is loaded as an application would (a `container` asset, no
// conversion): PlayCanvas's glTF parser makes a gsplat component per KHR_gaussian_splatting
// primitive (build/playcanvas/src/framework/parsers/glb/extensions/khr-gaussian-splatting.js).
// The suite's camera nodes are left out (their camera components disabled); each camera of the
// asset's cameras.json is set on a camera entity of PlayCanvas's own (vertical fov from fy,
// znear from the suite), the frame is drawn until the splats' worker sort has landed, and the
// canvas is read back as PNG: OUT/ASSET/CAMERA.png. The page is playcanvas.html; the server,
// chromium and the files are common.mjs's.
//
// Environment: PC_VIEW=ASSET/CAMERA (one view), PC_DEBUG=1 (page logs on stderr), PC_GL=1
// (ANGLE on GL instead of SwiftShader), SPLATGL_ROOT (the splatgl checkout with
// target/debug/splatgl and .npm-tools/; default: the checkout this script is in).
import fs from 'node:fs';
import path from 'node:path';
import { renderSuite } from './common.mjs';

// The asset as it is: the suite's own file, served from /files/ASSET/.
const asIs = (a, { suite, dir }) => {
  const name = path.basename(a.file);
  fs.copyFileSync(path.join(suite, a.file), path.join(dir, name));
  return { gltf: `/files/${a.name}/${name}` };
};

renderSuite({
  name: 'playcanvas',
  page: 'playcanvas.html',
  required: ['playcanvas/build/playcanvas.mjs'],
  prefix: 'PC',
  prepare: asIs,
});
