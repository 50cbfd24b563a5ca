//! The fragment-count prediction of the opacity-aware quads, and the pre-pass crossover.

use rayon::prelude::*;
use splatgl::profile::{
    CUTOFF_M2, FORMER_QUAD_MARGIN_PX, OPACITY_M2_MARGIN, QUAD_AXIS_FACTOR, QUAD_MARGIN_PX,
    opacity_cutoff_m2,
};
use splatgl::reference::{RenderOptions, footprints};

use super::{Bench, PathKind, Row, scene};
use splatgl::cull::CullBounds;

/// Pixel centres of a `w × h` image inside the quad the GL vertex stage builds for one
/// footprint `[u, v, a, b, c, opacity]` with Mahalanobis² extent `k2` (the rectangle along
/// Σ''s eigenvectors, half-axes `min(QUAD_AXIS_FACTOR·√(k2·λ) + margin, ⌈√(k2·λ₁')⌉)`, as in
/// `glsl/splat_project.glsl`).
fn quad_pixels(f: &[f32; 6], k2: f64, margin: f64, w: u32, h: u32) -> [u64; 3] {
    let [u, v, a, b, c, _] = f.map(f64::from);
    let mid = 0.5 * (a + c);
    let det = a * c - b * b;
    if det.is_nan() || det <= 0.0 {
        return [0; 3];
    }
    let l1 = mid + (mid * mid - det).max(0.0).sqrt();
    let l2 = det / l1;
    let lambda1 = mid + (mid * mid - det).max(0.1).sqrt();
    let radius = (k2 * lambda1).sqrt().ceil();
    let mut axis = if a >= c { [l1 - c, b] } else { [b, l1 - a] };
    let len = (axis[0] * axis[0] + axis[1] * axis[1]).sqrt();
    axis = if len > 0.0 {
        [axis[0] / len, axis[1] / len]
    } else {
        [1.0, 0.0]
    };
    let h1 = ((k2 * l1).sqrt() * QUAD_AXIS_FACTOR + margin).min(radius);
    let h2 = ((k2 * l2).sqrt() * QUAD_AXIS_FACTOR + margin).min(radius);
    let ext_x = h1 * axis[0].abs() + h2 * axis[1].abs();
    let ext_y = h1 * axis[1].abs() + h2 * axis[0].abs();
    let x0 = (u - ext_x - 0.5).ceil().max(0.0) as i64;
    let x1 = (u + ext_x - 0.5).floor().min(w as f64 - 1.0) as i64;
    let y0 = (v - ext_y - 0.5).ceil().max(0.0) as i64;
    let y1 = (v + ext_y - 0.5).floor().min(h as f64 - 1.0) as i64;
    let inside = |x: i64, y: i64| {
        let (dx, dy) = (x as f64 + 0.5 - u, y as f64 + 0.5 - v);
        let p1 = dx * axis[0] + dy * axis[1];
        let p2 = -dx * axis[1] + dy * axis[0];
        p1.abs() <= h1 && p2.abs() <= h2
    };
    // Pixels covered, 2×2 pixel quads touched (GPUs shade whole quads) and 4×4 blocks
    // touched (llvmpipe's fragment-shader unit): each as the fragments it costs.
    let mut out = [0u64; 3];
    for (g, o) in [1i64, 2, 4].into_iter().zip(&mut out) {
        for by in y0.div_euclid(g)..=y1.div_euclid(g) {
            for bx in x0.div_euclid(g)..=x1.div_euclid(g) {
                let mut n = 0;
                for y in (by * g).max(y0)..=((by + 1) * g - 1).min(y1) {
                    for x in (bx * g).max(x0)..=((bx + 1) * g - 1).min(x1) {
                        n += u64::from(inside(x, y));
                    }
                }
                *o += if n > 0 { (g * g) as u64 } else { 0 };
            }
        }
    }
    out
}

/// Predicted fragments of all footprints, `[pixels, 4 × 2×2 quads, 16 × 4×4 blocks]` each for
/// the former quads (3σ, 0.5 px) and the new ones (opacity-aware k, ⅛ px).
fn predicted(fp: &[[f32; 6]], w: u32, h: u32) -> [[u64; 3]; 2] {
    let add = |a: [u64; 3], b: [u64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    fp.par_iter()
        .map(|f| {
            let k2 = (opacity_cutoff_m2(f[5]) + OPACITY_M2_MARGIN).min(f64::from(CUTOFF_M2));
            [
                quad_pixels(f, 9.0, FORMER_QUAD_MARGIN_PX, w, h),
                quad_pixels(f, k2, QUAD_MARGIN_PX, w, h),
            ]
        })
        .reduce(|| [[0; 3]; 2], |a, b| [add(a[0], b[0]), add(a[1], b[1])])
}

/// The real scenes, framed: measured fragment-shader invocations of the former quads (3σ,
/// 0.5 px) and the new ones (opacity-aware, ⅛ px; same culled order, direct path) against
/// the prediction.
pub fn fragment_table(b: &mut Bench, _summary: &[(String, &str, usize, Vec<Row>)], scale: f32) {
    if b.query.is_none() {
        println!("\n(no fragment counter in this context: prediction table skipped)");
        return;
    }
    let (w, h) = b.size;
    println!(
        "\n{:>7} | {:>8} | {:>12} | {:>12} | {:>8} | {:>13} | {:>13} | {:>9} | {:>9} | {:>9}",
        "scene",
        "splats",
        "frags former",
        "frags new",
        "measured",
        "4×4 former",
        "4×4 new",
        "pred. 4×4",
        "pred. 2×2",
        "pred. px"
    );
    for name in ["biker", "guitar", "fox", "tower", "fruit"] {
        let Some((cloud, cam, target)) = scene(name, w, h, scale) else {
            continue;
        };
        b.upload(&cloud);
        let bounds = CullBounds::new(&cloud);
        let full = b.run(&cloud, &bounds, &cam, target, PathKind::Cull);
        let k = b.run(&cloud, &bounds, &cam, target, PathKind::Extent);
        // The same cameras as the measured frames (median of the per-frame predictions).
        let mut per_frame: Vec<[[u64; 3]; 2]> = (1..=b.frames)
            .map(|f| {
                let c = super::orbit(&cam, target, 0.004 * f as f32);
                predicted(&footprints(&cloud, &c, &RenderOptions::default()), w, h)
            })
            .collect();
        per_frame.sort();
        let [[px_f, q_f, b_f], [px_k, q_k, b_k]] = per_frame[per_frame.len() / 2];
        let (m_full, m_k) = (full.fragments.unwrap(), k.fragments.unwrap());
        let pct = |a: u64, b: u64| 100.0 * a as f64 / b as f64;
        println!(
            "{:>7} | {:>8} | {:>12} | {:>12} | {:>7.1}% | {:>13} | {:>13} | {:>8.1}% | {:>8.1}% | {:>8.1}%",
            name,
            cloud.len(),
            m_full,
            m_k,
            pct(m_k, m_full),
            b_f,
            b_k,
            pct(b_k, b_f),
            pct(q_k, q_f),
            pct(px_k, px_f)
        );
    }
}

/// Draw time direct vs pre-pass by splat count (SH 3, everything in view, splats of the 1M
/// scene's size whatever the count, so the per-splat work is what changes).
pub fn crossover(b: &mut Bench, sizes: &str, scale: f32) {
    if sizes == "none" {
        return;
    }
    let (w, h) = b.size;
    println!(
        "\n{:>8} | {:>14} | {:>14} | {:>10} | {:>12} | {:>12}",
        "splats", "direct draw ms", "pre-pass ms", "direct/pre", "direct CPU", "pre-pass CPU"
    );
    for n in sizes
        .split(',')
        .filter_map(|s| s.trim().parse::<usize>().ok())
    {
        let Some((mut cloud, cam, target)) = scene(&n.to_string(), w, h, scale) else {
            continue;
        };
        // Back to the 1M scene's splat size: × ((10⁵/10⁶) / (10⁵/n))^(1/3).
        let k = (n as f32 / 1e6).cbrt();
        for s in &mut cloud.scales {
            *s = s.map(|v| v * k);
        }
        b.upload(&cloud);
        let bounds = CullBounds::new(&cloud);
        let d = b.run(&cloud, &bounds, &cam, target, PathKind::Extent);
        let p = b.run(&cloud, &bounds, &cam, target, PathKind::PrePass);
        println!(
            "{:>8} | {:>14.2} | {:>14.2} | {:>9.2}× | {:>12.2} | {:>12.2}",
            n,
            d.draw,
            p.draw,
            d.draw / p.draw,
            d.draw_cpu,
            p.draw_cpu
        );
    }
}
