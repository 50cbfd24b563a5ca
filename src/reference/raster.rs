//! Tile binning and per-pixel blending (f32, back to front).

use super::project::Projected;
use crate::image::Image;
use crate::profile::{ALPHA_MAX, ALPHA_MIN, CUTOFF_M2};
use rayon::prelude::*;

/// Tile edge in pixels.
pub(crate) const TILE: u32 = 16;

/// Bin entries per tile row (how many (splat, tile) pairs each row of tiles holds), so the
/// caller can bin in bands of rows with bounded memory.
pub(crate) fn row_entries(splats: &[Projected], height: u32) -> Vec<u64> {
    let mut rows = vec![0u64; height.div_ceil(TILE) as usize];
    for s in splats {
        let [x0, x1, y0, y1] = s.bbox;
        let tiles_x = ((x1 - 1) / TILE - x0 / TILE + 1) as u64;
        for r in &mut rows[(y0 / TILE) as usize..=((y1 - 1) / TILE) as usize] {
            *r += tiles_x;
        }
    }
    rows
}

/// For each tile of the tile rows `rows` (row-major from `rows.start`), the positions in
/// `splats` (already in blending order) of the splats whose 3σ bounding box touches it, in
/// blending order.
pub(crate) fn bin(splats: &[Projected], width: u32, rows: std::ops::Range<u32>) -> Vec<Vec<u32>> {
    let tw = width.div_ceil(TILE);
    let mut tiles = vec![Vec::new(); (tw * (rows.end - rows.start)) as usize];
    for (k, s) in splats.iter().enumerate() {
        let [x0, x1, y0, y1] = s.bbox;
        let (ty0, ty1) = (
            (y0 / TILE).max(rows.start),
            ((y1 - 1) / TILE + 1).min(rows.end),
        );
        for ty in ty0..ty1 {
            for tx in x0 / TILE..=(x1 - 1) / TILE {
                tiles[((ty - rows.start) * tw + tx) as usize].push(k as u32);
            }
        }
    }
    tiles
}

/// Blends one splat over one pixel `px` (RGBA, RGB composited, A = 1 − T) at pixel centre
/// offset `(dx, dy)` from the mean; the exact per-pixel rule of the reference.
#[inline]
pub(crate) fn blend(px: &mut [f32; 4], s: &Projected, dx: f32, dy: f32) {
    let [a, b, c] = s.conic;
    let m2 = a * dx * dx + 2.0 * b * dx * dy + c * dy * dy;
    // Written so that NaN (and a negative m², impossible for a positive-definite conic) skip.
    if !(0.0..=CUTOFF_M2.min(s.m2_max)).contains(&m2) {
        return;
    }
    let alpha = (s.opacity * (-0.5 * m2).exp()).min(ALPHA_MAX);
    if alpha < ALPHA_MIN {
        return;
    }
    let keep = 1.0 - alpha;
    for (p, c) in px[..3].iter_mut().zip(s.color) {
        *p = c * alpha + *p * keep;
    }
    px[3] = alpha + px[3] * keep;
}

/// Rasterizes the splats binned for tile rows `rows` (see [`bin`]) into `image` (already
/// filled with the background, A = 0). Bands of one tile row run in parallel; every pixel sees
/// its splats in the same order whatever the thread count, so the result is bit-identical
/// across runs and thread counts.
pub(crate) fn rasterize(
    image: &mut Image,
    splats: &[Projected],
    tiles: &[Vec<u32>],
    rows: std::ops::Range<u32>,
) {
    let w = image.width;
    let tw = w.div_ceil(TILE);
    let band_len = (w * TILE) as usize;
    let first = rows.start as usize * band_len;
    let last = (rows.end as usize * band_len).min(image.pixels.len());
    image.pixels[first..last]
        .par_chunks_mut(band_len)
        .enumerate()
        .for_each(|(ty, band)| {
            let ty = ty as u32; // tile row relative to `rows.start`
            let band_rows = (band.len() / w as usize) as u32;
            let y_base = (rows.start + ty) * TILE;
            for tx in 0..tw {
                let x_base = tx * TILE;
                let x_end = (x_base + TILE).min(w);
                for &k in &tiles[(ty * tw + tx) as usize] {
                    let s = &splats[k as usize];
                    let [x0, x1, y0, y1] = s.bbox;
                    let (ya, yb) = (y0.max(y_base), y1.min(y_base + band_rows));
                    let (xa, xb) = (x0.max(x_base), x1.min(x_end));
                    for y in ya..yb {
                        let dy = (y as f32 + 0.5) - s.mean[1];
                        let row = ((y - y_base) * w) as usize;
                        for x in xa..xb {
                            let dx = (x as f32 + 0.5) - s.mean[0];
                            blend(&mut band[row + x as usize], s, dx, dy);
                        }
                    }
                }
            }
        });
}
