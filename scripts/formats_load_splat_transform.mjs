// Read time of @playcanvas/splat-transform for the files `benches/formats_load.rs` writes
// (SPLATGL_BENCH_WRITE=DIR): one run per file, bytes already in memory (like splatgl's
// `load_bytes`), timed from `readFile` to a fully materialized `DataTable` (every column
// decoded; the readers are lazy, so `readFile` alone decodes nothing). No write is involved.
//
// Usage: node scripts/formats_load_splat_transform.mjs DIR [path/to/splat-transform/dist/index.mjs]
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const dir = process.argv[2];
const lib = process.argv[3] ?? '.npm-tools/node_modules/@playcanvas/splat-transform/dist/index.mjs';
const st = await import(pathToFileURL(path.resolve(lib)).href);
st.logger.setVerbosity('quiet');

for (const name of fs.readdirSync(dir).sort()) {
    const bytes = new Uint8Array(fs.readFileSync(path.join(dir, name)));
    const mfs = new st.MemoryReadFileSystem();
    mfs.set(name, bytes);
    const t0 = process.hrtime.bigint();
    const [source] = await st.readFile({ filename: name, inputFormat: st.getInputFormat(name), fileSystem: mfs });
    const table = await st.materializeToDataTable(source, st.createChunkDataPool());
    const ms = Number(process.hrtime.bigint() - t0) / 1e6;
    source.close?.();
    console.log(`${name}: ${table.numRows} splats, ${table.columns.length} columns, read ${ms.toFixed(0)} ms (${(table.numRows / ms / 1e3).toFixed(2)} M splats/s)`);
}
