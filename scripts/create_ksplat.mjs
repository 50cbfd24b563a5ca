// Writes a .ksplat from an INRIA PLY with mkkellogg GaussianSplats3D's own generator, for the
// cross-check in tests/it/splat_transform.rs (splat-transform reads .ksplat but cannot write it).
// Usage: node create_ksplat.mjs MODULE_JS IN.ply OUT.ksplat LEVEL SH_DEGREE
import * as fs from 'fs';
import { pathToFileURL } from 'url';

const [modulePath, input, output, level, shDegree] = process.argv.slice(2);
const G = await import(pathToFileURL(modulePath).href);
const data = fs.readFileSync(input);
const buffer = data.buffer.slice(data.byteOffset, data.byteOffset + data.byteLength);
const splats = G.PlyParser.parseToUncompressedSplatArray(buffer, parseInt(shDegree));
// Alpha threshold 1 (of 255), one section, the generator's default block and bucket sizes.
const generator = G.SplatBufferGenerator.getStandardGenerator(1, parseInt(level), 0);
const splatBuffer = generator.generateFromUncompressedSplatArray(splats);
fs.writeFileSync(output, Buffer.from(splatBuffer.bufferData));
