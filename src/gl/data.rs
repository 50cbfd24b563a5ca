//! Texture layout of the splat data, uploaded once per cloud (or scene).
//!
//! Both data textures are `TEXTURE_2D_ARRAY`s `W = 2^w` texels wide, the largest power of two
//! ≤ min(8192, `GL_MAX_TEXTURE_SIZE`), whose full layers are `H = 2^h` rows high (the largest
//! power of two ≤ `GL_MAX_TEXTURE_SIZE`); a cloud that fits one layer gets a single layer just
//! as high as it needs. Splat `i`'s `k`-th texel is at linear index `idx = i·T + k` (T texels
//! per splat): `(idx & (W − 1), (idx >> w) & (H − 1), idx >> (w + h))` — x, y, layer. Both use
//! `NEAREST` filtering and are read with `texelFetch`. [`TextureLayout`] holds W, H and the
//! layer limit; the shader gets them as `#define`s.
//!
//! Capacity: `W · H · GL_MAX_ARRAY_TEXTURE_LAYERS / max(3, T_sh)` splats — with llvmpipe's
//! 16384 and 2048 layers far beyond memory; on a GLES 3.0 device with 2048 and 256 layers,
//! 89M (SH 0) or 22M (SH 3) splats where one 2048² texture would hold 1.4M. Beyond it
//! [`SplatTextures::upload`] fails with [`GlError::Capacity`], naming the limits and the count
//! that fits.
//!
//! The layout constants (texels per splat, which geometry texel holds what) are
//! [`crate::profile`]'s; the shaders get them as `#define`s.
//!
//! | texture | format | texels/splat | content | bytes/splat |
//! |---|---|---|---|---|
//! | geometry | `RGBA32F` | 3 | (position.xyz, opacity), rotation xyzw, (scale.xyz, model index) | 48 |
//! | SH | `RGBA16F` | ⌈3·K/4⌉ | the K = (d+1)² RGB coefficients, packed tightly, zero-padded | 8, 24, 56, 96 for degree 0–3 |
//!
//! Total: **56 / 72 / 104 / 144 bytes per splat** for SH degree 0 / 1 / 2 / 3 (resident in
//! GPU memory), plus the 4-byte order index, the only data uploaded per frame. The model index
//! (the cloud's entry in a [`SplatScene`](super::SplatScene), 0 for a single cloud) is a small
//! integer stored as a float, exact.
//!
//! Geometry stays f32: positions need it for large scenes and scale/rotation feed the
//! covariance, where f16 would add ~1e-3 relative error to Σ'. SH is f16 (11-bit mantissa):
//! for coefficients |c| < 4 the colour error is below 0.282·2⁻¹⁰·4 ≈ 1.1e-3 for the DC term and
//! of the same order for all 16 terms together on typical data — under half an 8-bit step.
//! The f32 → f16 conversion is done by the GL (RGBA16F accepts `FLOAT` uploads in GLES 3.0).

use glow::HasContext;

use super::GlError;
use super::caps::{self, injected};
use super::objects::{Creating, Owned};
use crate::cloud::SplatCloud;
pub use crate::profile::PAGE_SPLATS;
use crate::profile::{
    GEOM_TEXEL_POSITION_OPACITY, GEOM_TEXEL_ROTATION, GEOM_TEXEL_SCALE, GEOM_TEXELS, sh_texels,
};

/// log2 of the widest data texture used (8192 texels).
const MAX_TEX_WIDTH_LOG2: u32 = 13;

// Each page is whole rows of both textures, so writing one never touches another.
const _: () = assert!(PAGE_SPLATS.is_multiple_of(1 << MAX_TEX_WIDTH_LOG2));

/// Width, full-layer height and layer limit of the data textures on one context (fixed when
/// the renderer is created: the shader is compiled with them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct TextureLayout {
    /// log2 of the width W.
    pub(crate) width_log2: u32,
    /// log2 of the rows H of a full layer.
    pub(crate) layer_rows_log2: u32,
    /// `GL_MAX_ARRAY_TEXTURE_LAYERS`.
    pub(crate) max_layers: usize,
    /// `GL_MAX_TEXTURE_SIZE` (for the error message).
    max_size: usize,
}

/// log2 of the largest power of two ≤ `v` (0 for `v` ≤ 1).
fn floor_log2(v: usize) -> u32 {
    usize::BITS - 1 - v.max(1).leading_zeros()
}

impl TextureLayout {
    /// The layout for these limits.
    pub(crate) fn for_limits(max_texture_size: i32, max_layers: i32) -> Self {
        let max_size = max_texture_size.max(1) as usize;
        TextureLayout {
            width_log2: floor_log2(max_size).min(MAX_TEX_WIDTH_LOG2),
            layer_rows_log2: floor_log2(max_size),
            max_layers: max_layers.max(1) as usize,
            max_size,
        }
    }

    /// The layout for the context's limits (as lowered by the fault hooks, if injected).
    pub(crate) fn for_context(gl: &glow::Context) -> Self {
        let size = caps::limit(gl, glow::MAX_TEXTURE_SIZE);
        let layers = caps::limit(gl, glow::MAX_ARRAY_TEXTURE_LAYERS);
        Self::for_limits(size, layers)
    }

    pub(crate) fn width(&self) -> usize {
        1 << self.width_log2
    }

    pub(crate) fn layer_rows(&self) -> usize {
        1 << self.layer_rows_log2
    }

    /// The most splats of `per_splat` texels that fit (the shader's texel indices are `int`s:
    /// at most 2³¹ − 1 texels).
    pub(crate) fn capacity(&self, per_splat: usize) -> usize {
        // In u64: on 32-bit targets (wasm32) the product overflows usize.
        let texels = self.width() as u64 * self.layer_rows() as u64 * self.max_layers as u64;
        (texels.min(i32::MAX as u64) / per_splat.max(1) as u64) as usize
    }

    /// `(rows per layer, layers)` of a texture holding `n` splats of `per_splat` texels.
    pub(crate) fn shape(&self, n: usize, per_splat: usize) -> (usize, usize) {
        let rows = (n * per_splat).div_ceil(self.width()).max(1);
        if rows <= self.layer_rows() {
            (rows, 1)
        } else {
            (self.layer_rows(), rows.div_ceil(self.layer_rows()))
        }
    }

    /// [`GlError::Capacity`] unless `n` splats of `per_splat` texels fit.
    pub(crate) fn check(&self, n: usize, per_splat: usize) -> Result<(), GlError> {
        let fits = self.capacity(per_splat);
        if n <= fits {
            return Ok(());
        }
        Err(GlError::Capacity {
            splats: n,
            fits,
            limits: format!(
                "{} layers (GL_MAX_ARRAY_TEXTURE_LAYERS) of {}×{} texels (GL_MAX_TEXTURE_SIZE \
                 {}), at most 2^31 texels, at {per_splat} texels per splat",
                self.max_layers,
                self.width(),
                self.layer_rows(),
                self.max_size
            ),
        })
    }
}

/// GPU-resident bytes per splat for a cloud of SH degree `degree` (geometry + SH).
#[cfg(test)]
const fn bytes_per_splat(degree: u8) -> usize {
    GEOM_TEXELS * 16 + sh_texels(degree) * 8
}

/// The clouds uploaded together: splat `i` of the whole is splat `i − start[k]` of cloud `k`
/// (the model index of its splats).
pub(crate) struct CloudSet<'a> {
    clouds: &'a [&'a SplatCloud],
    /// First global index of each cloud, then the total.
    starts: Vec<usize>,
    /// SH degree of the set (the highest; lower clouds are zero-padded, which adds nothing).
    pub(crate) sh_degree: u8,
}

impl<'a> CloudSet<'a> {
    /// The set (checks every cloud's invariants).
    pub(crate) fn new(clouds: &'a [&'a SplatCloud]) -> Result<Self, GlError> {
        let mut starts = Vec::with_capacity(clouds.len() + 1);
        let mut total = 0;
        for (k, c) in clouds.iter().enumerate() {
            c.check_lengths()
                .map_err(|e| GlError::Upload(format!("cloud {k}: {e}")))?;
            starts.push(total);
            total += c.len();
        }
        starts.push(total);
        let sh_degree = clouds.iter().map(|c| c.sh_degree).max().unwrap_or(0);
        Ok(CloudSet {
            clouds,
            starts,
            sh_degree,
        })
    }

    /// Splats in all clouds.
    pub(crate) fn len(&self) -> usize {
        self.starts.last().copied().unwrap_or(0)
    }

    /// `(cloud, index in it)` of global splat `i`.
    fn locate(&self, i: usize) -> (usize, usize) {
        let k = self.starts.partition_point(|&s| s <= i) - 1;
        (k, i - self.starts[k])
    }

    /// Writes splat `i`'s geometry texels (`GEOM_TEXELS` × 4 floats).
    fn geometry(&self, i: usize, out: &mut [f32]) {
        let (k, j) = self.locate(i);
        let cloud = self.clouds[k];
        let [x, y, z] = cloud.positions[j];
        let [sx, sy, sz] = cloud.scales[j];
        // Splats the reference skips (non-finite data) get opacity 0: the shader culls them.
        let opacity = if cloud.is_drawable(j) {
            cloud.opacities[j]
        } else {
            0.0
        };
        let texel = |t: usize| 4 * t..4 * t + 4;
        out[texel(GEOM_TEXEL_POSITION_OPACITY)].copy_from_slice(&[x, y, z, opacity]);
        out[texel(GEOM_TEXEL_ROTATION)].copy_from_slice(&cloud.rotations[j]);
        out[texel(GEOM_TEXEL_SCALE)].copy_from_slice(&[sx, sy, sz, k as f32]);
    }

    /// Writes splat `i`'s SH texels (its coefficients, zero-padded to the set's degree).
    fn sh(&self, i: usize, out: &mut [f32]) {
        let (k, j) = self.locate(i);
        out.fill(0.0);
        for (t, c) in self.clouds[k].sh_of(j).iter().enumerate() {
            out[3 * t..3 * t + 3].copy_from_slice(c);
        }
    }
}

/// A float array texture in `layout` with storage for `n` splats of `per_splat` texels
/// (contents undefined), bound to `TEXTURE_2D_ARRAY`; returns it with its rows.
fn allocate_texture(
    objects: &mut Creating<'_>,
    internal_format: u32,
    layout: &TextureLayout,
    n: usize,
    per_splat: usize,
) -> Result<(glow::Texture, RowTarget), GlError> {
    let (mut height, mut layers) = layout.shape(n, per_splat);
    let mut rows_total = height * layers;
    if let Some(l) = injected!(i32, |f| f.oversize_layers) {
        (height, layers) = (layout.layer_rows(), l as usize);
        rows_total = height;
    }
    let gl = objects.gl();
    let tex = objects.texture()?;
    // SAFETY: texture creation/allocation on the current context with sizes checked by the
    // caller against the limits.
    unsafe {
        gl.bind_texture(glow::TEXTURE_2D_ARRAY, Some(tex));
        let (w, h, d) = (layout.width() as i32, height as i32, layers as i32);
        gl.tex_storage_3d(glow::TEXTURE_2D_ARRAY, 1, internal_format, w, h, d);
        nearest_texel_reads(gl);
    }
    Ok((tex, RowTarget { height, rows_total }))
}

/// Where a write goes: the texture bound to `TEXTURE_2D_ARRAY`, `height` rows a layer, of
/// which it may touch rows below `rows_total`.
/// The bound `TEXTURE_2D_ARRAY` read texel by texel: `NEAREST`, clamped to its edges (the
/// data and records textures are read with `texelFetch`; RGBA32F is not filterable on ES 3.0).
pub(crate) fn nearest_texel_reads(gl: &glow::Context) {
    for (pname, v) in [
        (glow::TEXTURE_MIN_FILTER, glow::NEAREST),
        (glow::TEXTURE_MAG_FILTER, glow::NEAREST),
        (glow::TEXTURE_WRAP_S, glow::CLAMP_TO_EDGE),
        (glow::TEXTURE_WRAP_T, glow::CLAMP_TO_EDGE),
    ] {
        // SAFETY: a texture parameter of the bound 2D array texture, valid enums.
        unsafe { gl.tex_parameter_i32(glow::TEXTURE_2D_ARRAY, pname, v as i32) };
    }
}

#[derive(Debug, Clone, Copy)]
struct RowTarget {
    height: usize,
    rows_total: usize,
}

/// Writes splats `first .. first + n` (global indices; `first · per_splat` a whole number of
/// rows) of the bound texture, whose texel stream is produced by `fill` (called per splat with
/// a slice of `per_splat · 4` floats), a few rows at a time so the staging memory stays small;
/// the rest of the last row is zeroed. The caller has set the unpack state to tight
/// client-memory rows.
fn write_rows(
    gl: &glow::Context,
    layout: &TextureLayout,
    target: &RowTarget,
    (first, n): (usize, usize),
    per_splat: usize,
    mut fill: impl FnMut(usize, &mut [f32]),
) {
    let width = layout.width();
    let height = target.height;
    debug_assert!(
        (first * per_splat).is_multiple_of(width),
        "writes start on a row"
    );
    const ROWS_PER_CHUNK: usize = 64;
    let floats_per_row = width * 4;
    let mut staging = vec![0.0f32; ROWS_PER_CHUNK.min(height) * floats_per_row];
    let mut tmp = vec![0.0f32; per_splat * 4];
    let stride = per_splat * 4;
    // Floats of the written splats, counted from the first written row.
    let total_floats = n * stride;
    let row0 = first * per_splat / width;
    let rows_used = (n * per_splat).div_ceil(width).max(1);
    let mut row = 0; // rows from row0
    while row < rows_used && row0 + row < target.rows_total {
        let global = row0 + row;
        let (layer, y) = (global / height, global % height);
        let chunk_rows = ROWS_PER_CHUNK
            .min(height - y)
            .min(rows_used - row)
            .min(target.rows_total - global);
        let start = row * floats_per_row;
        let end = start + chunk_rows * floats_per_row;
        staging[..chunk_rows * floats_per_row].fill(0.0);
        // Splats overlapping [start, end) of the written float stream.
        for i in start / stride..end.min(total_floats).div_ceil(stride) {
            fill(first + i, &mut tmp);
            let s0 = i * stride;
            let a = s0.max(start);
            let b = (s0 + stride).min(end);
            staging[a - start..b - start].copy_from_slice(&tmp[a - s0..b - s0]);
        }
        // SAFETY: the rows written lie inside the bound texture's storage (`y + chunk_rows ≤
        // height`, `global < rows_total`), reading exactly width·chunk_rows·4 floats.
        unsafe {
            gl.tex_sub_image_3d(
                glow::TEXTURE_2D_ARRAY,
                0,
                0,
                y as i32,
                layer as i32,
                width as i32,
                chunk_rows as i32,
                1,
                glow::RGBA,
                glow::FLOAT,
                glow::PixelUnpackData::Slice(Some(bytemuck::cast_slice(
                    &staging[..chunk_rows * floats_per_row],
                ))),
            );
        }
        row += chunk_rows;
    }
}

/// The two data textures of an uploaded cloud or scene.
#[derive(Debug)]
pub(crate) struct SplatTextures {
    /// Geometry texture (`RGBA32F` array).
    pub(crate) geometry: glow::Texture,
    /// SH texture (`RGBA16F` array).
    pub(crate) sh: glow::Texture,
    /// SH texels per splat.
    pub(crate) sh_texels: usize,
    /// SH degree the storage holds.
    pub(crate) sh_degree: u8,
    /// Splats uploaded (or slots allocated).
    pub(crate) len: usize,
    rows: [RowTarget; 2],
    owned: Owned,
}

impl SplatTextures {
    /// Storage for `n` splats of SH degree up to `sh_degree` in `layout` (checks the capacity
    /// first; contents undefined). The caller holds the error scope and the unpack / binding
    /// state (see `state::UploadState`).
    pub(crate) fn allocate(
        gl: &glow::Context,
        n: usize,
        sh_degree: u8,
        layout: &TextureLayout,
    ) -> Result<Self, GlError> {
        let sh_t = sh_texels(sh_degree);
        layout.check(n, GEOM_TEXELS.max(sh_t))?;
        let mut objects = Creating::new(gl);
        let (geometry, g) = allocate_texture(&mut objects, glow::RGBA32F, layout, n, GEOM_TEXELS)?;
        let (sh, h) = allocate_texture(&mut objects, glow::RGBA16F, layout, n, sh_t)?;
        Ok(SplatTextures {
            geometry,
            sh,
            sh_texels: sh_t,
            sh_degree,
            len: n,
            rows: [g, h],
            owned: objects.keep("SplatTextures"),
        })
    }

    /// Uploads a set of clouds in `layout` (as [`SplatTextures::allocate`], then writes them).
    pub(crate) fn upload(
        gl: &glow::Context,
        set: &CloudSet<'_>,
        layout: &TextureLayout,
    ) -> Result<Self, GlError> {
        let t = Self::allocate(gl, set.len(), set.sh_degree, layout)?;
        t.write(gl, layout, 0, set, 0..set.len());
        Ok(t)
    }

    /// Writes splats `range` of `set` into slots `first ..` (`first` a multiple of the texture
    /// width, e.g. of [`PAGE_SPLATS`]; the set's degree at most the storage's, the slots within
    /// [`SplatTextures::len`]: checked by the caller). Binds `TEXTURE_2D_ARRAY`.
    pub(crate) fn write(
        &self,
        gl: &glow::Context,
        layout: &TextureLayout,
        first: usize,
        set: &CloudSet<'_>,
        range: std::ops::Range<usize>,
    ) {
        let n = range.len();
        let at = |i: usize| i - first + range.start;
        // SAFETY: binds the renderer's own textures; the caller restores the binding.
        unsafe { gl.bind_texture(glow::TEXTURE_2D_ARRAY, Some(self.geometry)) };
        write_rows(
            gl,
            layout,
            &self.rows[0],
            (first, n),
            GEOM_TEXELS,
            |i, o| set.geometry(at(i), o),
        );
        // SAFETY: as above.
        unsafe { gl.bind_texture(glow::TEXTURE_2D_ARRAY, Some(self.sh)) };
        write_rows(
            gl,
            layout,
            &self.rows[1],
            (first, n),
            self.sh_texels,
            |i, o| set.sh(at(i), o),
        );
    }

    /// Deletes both textures (once).
    pub(crate) fn destroy(&mut self, gl: &glow::Context) {
        self.owned.destroy(gl);
    }

    /// Forgets the textures without GL calls (their context is already gone).
    pub(crate) fn abandon(&mut self) {
        self.owned.abandon();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_sizes() {
        assert_eq!([0, 1, 2, 3].map(bytes_per_splat), [56, 72, 104, 144]);
        let l = TextureLayout::for_limits(2048, 256);
        assert_eq!((l.width(), l.layer_rows()), (2048, 2048));
        assert_eq!(l.shape(0, 3), (1, 1));
        assert_eq!(l.shape(2048, 3), (3, 1));
        assert_eq!(l.shape(2049, 3), (4, 1));
        // One full layer holds 2048²/3 splats; one more needs a second layer.
        let per_layer = 2048 * 2048 / 3;
        assert_eq!(l.shape(per_layer, 3), (2048, 1));
        assert_eq!(l.shape(per_layer + 1, 3), (2048, 2));
        assert_eq!(l.capacity(12), 2048 * 2048 * 256 / 12);
        assert_eq!(TextureLayout::for_limits(16384, 2048).width_log2, 13);
        assert_eq!(TextureLayout::for_limits(16384, 2048).layer_rows_log2, 14);
        assert_eq!(TextureLayout::for_limits(4096, 1).width_log2, 12);
        assert_eq!(TextureLayout::for_limits(3000, 1).width_log2, 11);
        assert_eq!(TextureLayout::for_limits(64, 1).width_log2, 6);
    }

    #[test]
    fn over_capacity_names_limits_and_what_fits() {
        let l = TextureLayout::for_limits(64, 2);
        assert!(l.check(64 * 64 * 2 / 12, 12).is_ok());
        let e = l.check(64 * 64 * 2 / 12 + 1, 12).unwrap_err().to_string();
        assert!(e.contains("683 splats do not fit"), "{e}");
        assert!(e.contains("at most 682 splats"), "{e}");
        assert!(
            e.contains("2 layers (GL_MAX_ARRAY_TEXTURE_LAYERS) of 64×64"),
            "{e}"
        );
    }
}
