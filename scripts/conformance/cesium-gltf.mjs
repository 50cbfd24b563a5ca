// What splatgl's SPZ-compressed glTF needs before CesiumJS 1.145 draws it (shared by
// cesium.mjs, one asset per tileset, and cesium-tileset.mjs, a tileset splatgl built).
//
// CesiumJS reads the SPZ colours and alphas into the COLOR_0 attribute only
// (GltfVertexBufferLoader.js line 444: the one semantic it knows) and counts the RC's
// KHR_gaussian_splatting:SH_DEGREE_0_COEF_0 and :OPACITY placeholders as SH coefficients
// (GaussianSplat3DTileContent.js line 646-661), so those two placeholders become one COLOR_0
// placeholder; the SPZ payload is not touched. And it multiplies `nodes[0].matrix`
// unconditionally (GaussianSplat3DTileContent.js line 481, GaussianSplatPrimitive.js line
// 1245-1249), so the splat node gets the matrix the caller chooses.

const PREFIX = 'KHR_gaussian_splatting:';

/** The identity, column-major. */
export const IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];

/**
 * SPZ's RUB payload back to glTF's axes: diag(−1, 1, −1), a 180° turn about y. splatgl writes
 * the payload in RUB as the extension's text asks (docs/formats.md, "glTF with SPZ
 * compression"); CesiumJS reads its numbers as they are (GltfSpzLoader.js line 237-239,
 * coordinateSystem "UNSPECIFIED"). As the node matrix it puts each splat where the tile's
 * bounding volume (written for the decoded, glTF-axis positions) says it is; being a rotation,
 * Cesium applies it to the splats' rotations and SH view directions too
 * (GaussianSplatPrimitive.js line 1275-1339, 1785-1807).
 */
export const RUB_TO_GLTF = [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1];

/**
 * Rewrites `json` (a glTF with one splat primitive) in place for CesiumJS: the COLOR_0
 * placeholder for the colour and opacity ones, and `matrix` on every mesh node without a
 * transform of its own. Returns the POSITION accessor.
 */
export function cesiumPlaceholders(json, matrix) {
  const prims = json.meshes.flatMap((m) => m.primitives);
  if (prims.length !== 1) throw new Error(`${prims.length} primitives (expected 1)`);
  const attrs = prims[0].attributes;
  const count = json.accessors[attrs.POSITION].count;
  delete attrs[`${PREFIX}OPACITY`];
  delete attrs[`${PREFIX}SH_DEGREE_0_COEF_0`];
  json.accessors.push({ componentType: 5121, normalized: true, count, type: 'VEC4' });
  attrs.COLOR_0 = json.accessors.length - 1;
  for (const n of json.nodes) if (n.mesh !== undefined && !n.matrix && !n.translation && !n.rotation && !n.scale) {
    n.matrix = [...matrix];
  }
  return json.accessors[attrs.POSITION];
}
