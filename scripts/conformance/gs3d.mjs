#!/usr/bin/env node
// Renders a splatgl conformance suite with GaussianSplats3D 0.4.7 in headless Chromium, so
// `splatgl conformance run SUITE --images OUT` grades a renderer splatgl did not write.
//
//   node scripts/conformance/gs3d.mjs SUITE OUT [--splatgl target/debug/splatgl] [--only ASSET]
//
// Each asset is converted to INRIA PLY with `splatgl convert --up y` (glTF axes kept; node
// transforms baked, which the RC's math allows), each camera of its cameras.json is set on a
// three.js PerspectiveCamera (fov from fy, znear from the suite), and the canvas is read
// back as PNG: OUT/ASSET/CAMERA.png. The npm packages come from .npm-tools/ (scripts/npm-tools.sh);
// the page is served from 127.0.0.1 only, and chromium is killed after the last image or
// after the time limit.
//
// The page works around two GaussianSplats3D 0.4.7 bugs that only tiny scenes like the
// suite's show (see gs3d.html: fixDrawRange, fixCovariances), and by default rolls each
// camera by GS3D_ROLL = 1e-4 rad about its view axis, which keeps GS3D's vertex shader off
// its degenerate eigenvector case (exactly axis-aligned footprints; gs3d.html explains).
// GS3D_ROLL=0 renders the cameras exactly, and that bug with them.
//
// Environment: GS3D_ROLL (radians, default 1e-4), GS3D_VIEW=ASSET/CAMERA (one view),
// GS3D_DEBUG=1 (page logs on stderr), GS3D_GL=1 (ANGLE on GL instead of SwiftShader),
// SPLATGL_ROOT (the splatgl checkout with target/debug/splatgl and .npm-tools/; default: the
// checkout this script is in). The conversion, the server and chromium: common.mjs.
import { renderSuite } from './common.mjs';

const roll = Number(process.env.GS3D_ROLL ?? '1e-4');
if (!Number.isFinite(roll)) { console.error('gs3d.mjs: GS3D_ROLL is not a number'); process.exit(2); }
renderSuite({
  name: 'gs3d',
  page: 'gs3d.html',
  required: ['three/build/three.module.js', '@mkkellogg/gaussian-splats-3d/build/gaussian-splats-3d.module.js'],
  prefix: 'GS3D',
  viewExtra: { roll },
  banner: roll !== 0 ? `gs3d.mjs: cameras rolled by ${roll} rad (GS3D_ROLL=0 for none)` : null,
});
