#!/usr/bin/env node
// Renders a splatgl conformance suite with Spark 2.2.0 (npm @sparkjsdev/spark, with three
// 0.180.0 installed as three-spark) in headless Chromium, so
// `splatgl conformance run SUITE --images OUT` grades a renderer splatgl did not write.
//
//   node scripts/conformance/spark.mjs SUITE OUT [--splatgl target/debug/splatgl] [--only ASSET]
//
// As gs3d.mjs (the shared part is common.mjs): each asset is converted to INRIA PLY with
// `splatgl convert --up y` (glTF axes kept; node transforms baked, which the RC's math
// allows), each camera of its cameras.json is set on a three.js PerspectiveCamera (fov from
// fy, znear from the suite), Spark draws the PLY as a SplatMesh through a SparkRenderer with
// its default options, and the canvas is read back as PNG: OUT/ASSET/CAMERA.png. The page
// (spark.html) works around nothing: the cameras are exact.
//
// Environment: SPARK_VIEW=ASSET/CAMERA (one view), SPARK_DEBUG=1 (page logs on stderr),
// SPARK_GL=1 (ANGLE on GL instead of SwiftShader), SPLATGL_ROOT (the splatgl checkout with
// target/debug/splatgl and .npm-tools/; default: the checkout this script is in). For
// experiments only (the test renders Spark's defaults): SPARK_RENDERER='{"maxStdDev":3}' and
// SPARK_MESH='{"extSplats":true}', JSON objects merged into the SparkRenderer and SplatMesh
// options (docs/conformance-engines.md, "Spark 2.2", lists what they showed).
import { renderSuite } from './common.mjs';

const json = (name) => {
  try { return JSON.parse(process.env[name] || '{}'); } catch (e) {
    console.error(`spark.mjs: ${name} is not JSON (${e.message})`);
    process.exit(2);
  }
};
const sparkRenderer = json('SPARK_RENDERER');
const splatMesh = json('SPARK_MESH');
const changed = Object.keys(sparkRenderer).length + Object.keys(splatMesh).length > 0;

renderSuite({
  name: 'spark',
  page: 'spark.html',
  required: ['three-spark/build/three.module.js', 'three-spark/examples/jsm/postprocessing/Pass.js',
             '@sparkjsdev/spark/dist/spark.module.js'],
  prefix: 'SPARK',
  viewExtra: { sparkRenderer, splatMesh },
  banner: changed ? `spark.mjs: not Spark's defaults: SparkRenderer ${JSON.stringify(sparkRenderer)}, SplatMesh ${JSON.stringify(splatMesh)}` : null,
});
