//! Texture layout of the splat data, uploaded once per cloud.
//!
//! Both textures are `W = 2^w` texels wide, the largest power of two ≤ min(8192,
//! `GL_MAX_TEXTURE_SIZE`) (so at least 2048 on any GLES 3.0 device; [`tex_width_log2`]); splat
//! `i`'s `k`-th texel is at linear index `i·T + k` (T texels per splat), i.e.
//! `(idx & (W − 1), idx >> w)`. Both use `NEAREST` filtering and are read with `texelFetch`.
//! Capacity: `W · GL_MAX_TEXTURE_SIZE / max(3, T_sh)` splats — 11.2M at SH degree 3 and 44.7M
//! at degree 0 with llvmpipe's 16384; [`SplatTextures::upload`] reports an error beyond.
//!
//! The layout constants (texels per splat, which geometry texel holds what) are
//! [`crate::profile`]'s; the shaders get them as `#define`s.
//!
//! | texture | format | texels/splat | content | bytes/splat |
//! |---|---|---|---|---|
//! | geometry | `RGBA32F` | 3 | (position.xyz, opacity), rotation xyzw, (scale.xyz, 0) | 48 |
//! | SH | `RGBA16F` | ⌈3·K/4⌉ | the K = (d+1)² RGB coefficients, packed tightly, zero-padded | 8, 24, 56, 96 for degree 0–3 |
//!
//! Total: **56 / 72 / 104 / 144 bytes per splat** for SH degree 0 / 1 / 2 / 3 (resident in
//! GPU memory), plus the 4-byte order index, the only data uploaded per frame.
//!
//! Geometry stays f32: positions need it for large scenes and scale/rotation feed the
//! covariance, where f16 would add ~1e-3 relative error to Σ'. SH is f16 (11-bit mantissa):
//! for coefficients |c| < 4 the colour error is below 0.282·2⁻¹⁰·4 ≈ 1.1e-3 for the DC term and
//! of the same order for all 16 terms together on typical data — under half an 8-bit step.
//! The f32 → f16 conversion is done by the GL (RGBA16F accepts `FLOAT` uploads in GLES 3.0).

use glow::HasContext;

use super::GlError;
use super::objects::{Creating, Owned};
use crate::cloud::SplatCloud;
use crate::profile::{
    GEOM_TEXEL_POSITION_OPACITY, GEOM_TEXEL_ROTATION, GEOM_TEXEL_SCALE, GEOM_TEXELS, sh_texels,
};

/// log2 of the widest data texture used (8192 texels).
const MAX_TEX_WIDTH_LOG2: u32 = 13;

/// log2 of the data textures' width for a context with this `GL_MAX_TEXTURE_SIZE`: the largest
/// power of two ≤ min(8192, max_texture_size), and at least 2048 (the GLES 3.0 minimum).
pub(crate) fn tex_width_log2(max_texture_size: i32) -> u32 {
    let m = max_texture_size.max(2048) as u32;
    (31 - m.leading_zeros()).min(MAX_TEX_WIDTH_LOG2)
}
/// GPU-resident bytes per splat for a cloud of SH degree `degree` (geometry + SH).
#[cfg(test)]
const fn bytes_per_splat(degree: u8) -> usize {
    GEOM_TEXELS * 16 + sh_texels(degree) * 8
}

/// Rows of a `width`-wide texture holding `n` splats of `per_splat` texels.
fn rows(n: usize, per_splat: usize, width: usize) -> usize {
    (n * per_splat).div_ceil(width).max(1)
}

/// The two data textures of an uploaded cloud.
#[derive(Debug)]
pub(crate) struct SplatTextures {
    /// Geometry texture (`RGBA32F`).
    pub(crate) geometry: glow::Texture,
    /// SH texture (`RGBA16F`).
    pub(crate) sh: glow::Texture,
    /// SH texels per splat.
    pub(crate) sh_texels: usize,
    /// Splats uploaded.
    pub(crate) len: usize,
    owned: Owned,
}

/// Writes splat `i`'s geometry texels (`GEOM_TEXELS` × 4 floats).
fn geometry_of(cloud: &SplatCloud, i: usize, out: &mut [f32]) {
    let [x, y, z] = cloud.positions[i];
    let [sx, sy, sz] = cloud.scales[i];
    // Splats the reference skips (non-finite data) get opacity 0: the shader culls them.
    let opacity = if cloud.is_drawable(i) {
        cloud.opacities[i]
    } else {
        0.0
    };
    let texel = |k: usize| 4 * k..4 * k + 4;
    out[texel(GEOM_TEXEL_POSITION_OPACITY)].copy_from_slice(&[x, y, z, opacity]);
    out[texel(GEOM_TEXEL_ROTATION)].copy_from_slice(&cloud.rotations[i]);
    out[texel(GEOM_TEXEL_SCALE)].copy_from_slice(&[sx, sy, sz, 0.0]);
}

/// Uploads a `width`-wide float texture whose linear texel stream is produced by `fill`
/// (called per splat with a slice of `per_splat · 4` floats), a few rows at a time so the
/// staging memory stays small for large clouds.
fn upload_texture(
    objects: &mut Creating<'_>,
    internal_format: u32,
    width: usize,
    n: usize,
    per_splat: usize,
    mut fill: impl FnMut(usize, &mut [f32]),
) -> Result<glow::Texture, GlError> {
    let height = rows(n, per_splat, width);
    let gl = objects.gl();
    let tex = objects.texture()?;
    // SAFETY: texture creation/allocation on the current context with sizes checked by the
    // caller against GL_MAX_TEXTURE_SIZE; sub-image uploads stay inside the allocated storage
    // (row ranges computed below) and read exactly width·rows·4 floats from `staging`.
    unsafe {
        gl.bind_texture(glow::TEXTURE_2D, Some(tex));
        gl.tex_storage_2d(
            glow::TEXTURE_2D,
            1,
            internal_format,
            width as i32,
            height as i32,
        );
        for (pname, v) in [
            (glow::TEXTURE_MIN_FILTER, glow::NEAREST),
            (glow::TEXTURE_MAG_FILTER, glow::NEAREST),
            (glow::TEXTURE_WRAP_S, glow::CLAMP_TO_EDGE),
            (glow::TEXTURE_WRAP_T, glow::CLAMP_TO_EDGE),
        ] {
            gl.tex_parameter_i32(glow::TEXTURE_2D, pname, v as i32);
        }
        // Whatever unpack state the host left must not offset or redirect the read of
        // `staging`: client memory, tight rows, no skipped rows or pixels.
        gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
        gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
        gl.pixel_store_i32(glow::UNPACK_ROW_LENGTH, 0);
        gl.pixel_store_i32(glow::UNPACK_SKIP_ROWS, 0);
        gl.pixel_store_i32(glow::UNPACK_SKIP_PIXELS, 0);
        const ROWS_PER_CHUNK: usize = 64;
        let floats_per_row = width * 4;
        let mut staging = vec![0.0f32; ROWS_PER_CHUNK * floats_per_row];
        let mut tmp = vec![0.0f32; per_splat * 4];
        let total_floats = n * per_splat * 4;
        let mut row = 0;
        while row < height {
            let chunk_rows = ROWS_PER_CHUNK.min(height - row);
            let start = row * floats_per_row;
            let end = start + chunk_rows * floats_per_row;
            staging[..chunk_rows * floats_per_row].fill(0.0);
            // Splats overlapping [start, end) of the linear float stream.
            let stride = per_splat * 4;
            let first = start / stride;
            let last = end.min(total_floats).div_ceil(stride);
            for i in first..last {
                fill(i, &mut tmp);
                let s0 = i * stride;
                let a = s0.max(start);
                let b = (s0 + stride).min(end);
                staging[a - start..b - start].copy_from_slice(&tmp[a - s0..b - s0]);
            }
            gl.tex_sub_image_2d(
                glow::TEXTURE_2D,
                0,
                0,
                row as i32,
                width as i32,
                chunk_rows as i32,
                glow::RGBA,
                glow::FLOAT,
                glow::PixelUnpackData::Slice(Some(bytemuck::cast_slice(
                    &staging[..chunk_rows * floats_per_row],
                ))),
            );
            row += chunk_rows;
        }
        gl.bind_texture(glow::TEXTURE_2D, None);
        Ok(tex)
    }
}

impl SplatTextures {
    /// Uploads a cloud into textures `2^width_log2` texels wide (checks the cloud's invariants
    /// and the texture size limit first).
    pub(crate) fn upload(
        gl: &glow::Context,
        cloud: &SplatCloud,
        width_log2: u32,
    ) -> Result<Self, GlError> {
        let width = 1usize << width_log2;
        cloud.check_lengths().map_err(GlError::Upload)?;
        super::clear_pending_errors(gl);
        let n = cloud.len();
        let sh_t = sh_texels(cloud.sh_degree);
        let k = cloud.coeffs_per_splat();
        // SAFETY: a plain integer query.
        let max_size = unsafe { gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE) } as usize;
        let need = rows(n, GEOM_TEXELS.max(sh_t), width);
        if need > max_size {
            return Err(GlError::Upload(format!(
                "{n} splats need {need} texture rows; GL_MAX_TEXTURE_SIZE is {max_size}"
            )));
        }
        let mut objects = Creating::new(gl);
        let geometry = upload_texture(
            &mut objects,
            glow::RGBA32F,
            width,
            n,
            GEOM_TEXELS,
            |i, out| geometry_of(cloud, i, out),
        )?;
        let sh = upload_texture(&mut objects, glow::RGBA16F, width, n, sh_t, |i, out| {
            out.fill(0.0);
            for (j, c) in cloud.sh[i * k..(i + 1) * k].iter().enumerate() {
                out[3 * j..3 * j + 3].copy_from_slice(c);
            }
        })?;
        super::check_error(gl, "uploading splat textures")?;
        Ok(SplatTextures {
            geometry,
            sh,
            sh_texels: sh_t,
            len: n,
            owned: objects.keep("SplatTextures"),
        })
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
        assert_eq!(rows(0, 3, 2048), 1);
        assert_eq!(rows(2048, 3, 2048), 3);
        assert_eq!(rows(2049, 3, 2048), 4);
        assert_eq!(tex_width_log2(16384), 13);
        assert_eq!(tex_width_log2(4096), 12);
        assert_eq!(tex_width_log2(3000), 11);
        assert_eq!(tex_width_log2(0), 11);
    }
}
