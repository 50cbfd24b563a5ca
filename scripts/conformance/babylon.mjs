#!/usr/bin/env node
// Renders a splatgl conformance suite with Babylon.js 9 (npm @babylonjs/core and
// @babylonjs/loaders 9.28), whose glTF loader reads KHR_gaussian_splatting itself, in headless
// Chromium, so `splatgl conformance run SUITE --images OUT` grades an engine splatgl did not
// write.
//
//   node scripts/conformance/babylon.mjs SUITE OUT [--splatgl target/debug/splatgl] [--only ASSET]
//
// Each asset's .glb / .gltf is appended to a scene as an application would (SceneLoader, no
// conversion): the loader's extension (loaders/glTF/2.0/Extensions/KHR_gaussian_splatting.pure.js)
// makes a GaussianSplattingMesh per KHR_gaussian_splatting primitive. The scene is right-handed
// (glTF's axes, no flipping root); the suite's cameras are left unused and each camera of the
// asset's cameras.json is set as the active camera (view matrix = the camera's inverse pose,
// vertical fov from fy, znear from the suite), the frame is drawn until the splats' worker sort
// has landed, and the canvas is read back as PNG: OUT/ASSET/CAMERA.png. The page is
// babylon.html; the server, chromium and the files are common.mjs's.
//
// Environment: BJS_VIEW=ASSET/CAMERA (one view), BJS_DEBUG=1 (page logs on stderr), BJS_GL=1
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
  name: 'babylon',
  page: 'babylon.html',
  required: ['@babylonjs/core/Engines/engine.js', '@babylonjs/loaders/glTF/index.js'],
  prefix: 'BJS',
  prepare: asIs,
});
