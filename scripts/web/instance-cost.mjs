#!/usr/bin/env node
// What the browser's WebGL2 (headless Chromium, SwiftShader: no GPU) pays per instance of an
// instanced draw: N one-pixel quads drawn as N instances of one quad and as ⌈N/B⌉ instances
// of B quads, same shaders, same pixels (scripts/web/bench/instances.html). The reason the
// renderer draws its quads in batches (src/gl/prepass.rs, docs/performance.md).
//
//   node scripts/web/instance-cost.mjs [N] [B]        (default 150000 256)
//
// A benchmark, not a test.
import { execFileSync } from 'node:child_process';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const [n = '150000', b = '256'] = process.argv.slice(2);
const page = `${pathToFileURL(path.join(here, 'bench', 'instances.html'))}?n=${n}&b=${b}`;
const dom = execFileSync('chromium', ['--headless', '--no-sandbox', '--use-angle=swiftshader',
  '--enable-unsafe-swiftshader', '--disable-extensions', '--no-first-run', '--dump-dom', page],
{ encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'], timeout: 300000 });
const m = /RESULT ([^<]*)/.exec(dom);
console.log(m ? m[1].split(' | ').join('\n') : 'no result (is chromium installed?)');
