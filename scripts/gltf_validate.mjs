// Runs the Khronos glTF-Validator (npm package `gltf-validator`, installed by .ci/run into
// .npm-tools/) on one .gltf/.glb file and prints its JSON report on stdout, with the issues it
// raises only because it predates KHR_gaussian_splatting removed and counted:
//   - MESH_PRIMITIVE_INVALID_ATTRIBUTE on a `KHR_gaussian_splatting:*` attribute semantic;
//   - UNSUPPORTED_EXTENSION for `KHR_gaussian_splatting` itself.
// Nothing else is filtered. Exit status: 0 when no error remains, 1 when some do, 2 when the
// validator could not run or read the file.
//
// usage: node scripts/gltf_validate.mjs FILE
import { readFile } from "node:fs/promises";
import { createRequire } from "node:module";
import path from "node:path";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(import.meta.url);
const modulePath =
  process.env.GLTF_VALIDATOR ??
  path.join(here, "..", ".npm-tools", "node_modules", "gltf-validator");

const file = process.argv[2];
if (!file) {
  console.error("usage: node scripts/gltf_validate.mjs FILE");
  process.exit(2);
}

let validator;
try {
  validator = require(modulePath);
} catch (e) {
  console.error(`gltf-validator not found at ${modulePath}: ${e.message}`);
  process.exit(2);
}

const EXT = "KHR_gaussian_splatting";
// An issue the validator raises only because it does not know the extension.
function predatesExtension(m) {
  if (m.code === "UNSUPPORTED_EXTENSION") {
    // The message is "Cannot validate an extension as it is not supported by the validator: 'NAME'."
    return m.message.endsWith(`'${EXT}'.`);
  }
  if (m.code === "MESH_PRIMITIVE_INVALID_ATTRIBUTE") {
    // The pointer ends in /attributes/<semantic>; the semantic must be the extension's.
    const last = m.pointer.split("/").pop() ?? "";
    return m.pointer.includes("/attributes/") && last.startsWith(`${EXT}:`);
  }
  return false;
}

try {
  const bytes = new Uint8Array(await readFile(file));
  const dir = path.dirname(path.resolve(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      readFile(path.resolve(dir, decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const kept = report.issues.messages.filter((m) => !predatesExtension(m));
  const filtered = report.issues.messages.length - kept.length;
  const count = (s) => kept.filter((m) => m.severity === s).length;
  report.issues.messages = kept;
  report.issues.numErrors = count(0);
  report.issues.numWarnings = count(1);
  report.issues.numInfos = count(2);
  report.issues.numHints = count(3);
  report.issues.filteredPredatingExtension = filtered;
  console.log(JSON.stringify(report, null, 2));
  process.exit(report.issues.numErrors === 0 ? 0 : 1);
} catch (e) {
  console.error(`${file}: ${e}`);
  process.exit(2);
}
