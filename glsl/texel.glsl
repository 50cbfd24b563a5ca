// Linear texel index -> (x, y, layer) in the data and records textures (array textures
// TEX_WIDTH texels wide, LAYER_ROWS rows per full layer; src/gl/data.rs).
ivec3 texel_coord(int linear_index) {
    return ivec3(linear_index & (TEX_WIDTH - 1),
                 (linear_index >> TEX_WIDTH_LOG2) & (LAYER_ROWS - 1),
                 linear_index >> (TEX_WIDTH_LOG2 + LAYER_ROWS_LOG2));
}
