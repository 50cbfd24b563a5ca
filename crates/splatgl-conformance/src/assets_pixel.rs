//! The suite's assets, part 3: the per-pixel rules and the erratum-specific assets.

use super::Erratum;
use super::assets::{AssetSpec, CameraSpec, ID, cam, palette, prim, quat, single, splat};
use super::model::Variant;
use splatgl::cloud::SplatCloud;

fn near_plane() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    splat(
        &mut c,
        [0.0, 0.0, 0.0],
        [0.5, 0.3, 0.3],
        ID,
        // Half opaque: its 2.83σ–3σ ring (erratum f) stays clearly within the bound, so f is
        // the cut-off asset's to catch, not a verdict within the margin here.
        0.5,
        [0.2, 0.5, 0.9],
    );
    // Depth 0.35 from the camera, extent ±0.75 in depth: crosses the near plane (0.2).
    splat(
        &mut c,
        [0.05, 0.03, 2.65],
        [0.25, 0.2, 0.25],
        ID,
        0.3,
        [0.9, 0.6, 0.2],
    );
    // Depth 0.15: in front of the near plane, culled by every renderer.
    splat(
        &mut c,
        [0.0, 0.0, 2.85],
        [0.05; 3],
        ID,
        0.9,
        [1.0, 0.0, 0.0],
    );
    AssetSpec::new(
        "near_plane_crossing",
        "a splat whose mean is 0.35 in front of the camera but whose 3σ extent crosses the near plane (znear 0.2) is drawn whole; one whose mean is nearer than znear is not drawn",
        "RC Splat Projection; profile §3 (cull by the mean's depth, 3DGS: 0.2)",
        "a red blob: splats in front of the near plane are drawn; a missing or clipped orange veil: splats are clipped per fragment at the near plane",
        single(vec![prim(c)]),
        vec![CameraSpec {
            znear: 0.2,
            ..cam("front", [0.0, 0.0, 3.0])
        }],
    )
    // The RC never mentions a near plane: the cull depth is 3DGS's choice.
    .profile()
}

fn screen_border() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    // Means just inside and just outside the image edges (|x/z| within 1.3·tan, so the J clamp
    // is not involved), footprints crossing the border.
    let (tx, ty) = (0.621_744 * 3.0, 0.466_308 * 3.0);
    for (k, (x, y)) in [
        (1.04, 0.3),
        (-0.97, -0.2),
        (0.2, 1.05),
        (-0.3, -0.96),
        (1.02, 1.02),
    ]
    .into_iter()
    .enumerate()
    {
        splat(
            &mut c,
            [x * tx, y * ty, 0.0],
            [0.3, 0.2, 0.2],
            quat(0.0, 0.0, 20.0 * k as f32),
            0.9,
            [0.9 - 0.15 * k as f64, 0.3 + 0.1 * k as f64, 0.5],
        );
    }
    AssetSpec::new(
        "screen_border_crossing",
        "splats whose footprints cross the image border, with means just inside and just outside it",
        "RC Splat Projection; profile §3 (no lateral cull besides the 3σ box)",
        "missing border splats: splats are culled by their mean instead of their 3σ extent",
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 3.0])],
    )
}

fn subpixel() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for j in 0..4 {
        for i in 0..6 {
            let p = [
                i as f32 * 0.5 - 1.25 + 0.013 * j as f32,
                j as f32 * 0.5 - 0.75 + 0.007 * i as f32,
                0.0,
            ];
            splat(&mut c, p, [0.002; 3], ID, 1.0, [1.0, 0.95, 0.8]);
        }
    }
    AssetSpec::new(
        "subpixel_dilation",
        "sub-pixel splats (σ ≈ 0.05 px): Σ' is dilated by 0.3 px² before the cut-off, so each draws a ~1.6 px dot",
        "profile §3 (3DGS low-pass dilation; the RC's Σ' is what 3DGS trains with)",
        "dots missing or aliased: Σ' is not dilated",
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 4.0])],
    )
    .catches(&[Erratum::I])
    // GaussianSplats3D's floor drops these splats (their smaller eigenvalue is ≤ 0).
    .detects(&[Variant::EigenvalueFloor])
    // The RC leaves Σ' to "the same forward pass algorithm used during training".
    .profile()
}

fn needles() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for k in 0..3 {
        let p = [0.0, k as f32 * 0.35 - 0.35, 0.1 * k as f32];
        splat(
            &mut c,
            p,
            [0.8, 0.02, 0.02],
            quat(0.0, 0.0, 10.0 * k as f32),
            0.95,
            [0.95, 0.6 + 0.15 * k as f64, 0.2],
        );
    }
    AssetSpec::new(
        "thin_needles",
        "thin needles (scale ratio 40:1, about 0.7 px wide) seen side-on and nearly end-on: Σ' stays positive definite",
        "RC Splat Projection (Σ' = J W Σ Wᵀ Jᵀ)",
        "needles missing or exploding seen end-on: det Σ' loses its digits in f32 (a·c − b²) and goes ≤ 0",
        single(vec![prim(c)]),
        vec![
            cam("side", [0.0, 0.0, 3.0]),
            cam("end_on", [3.0, 0.25, 0.4]),
        ],
    )
}

fn faint() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    splat(
        &mut c,
        [0.0, 0.0, 0.0],
        [0.6, 0.4, 0.3],
        ID,
        0.6,
        [0.3, 0.4, 0.8],
    );
    for (k, o) in [0.003f32, 0.02, 0.02].into_iter().enumerate() {
        splat(
            &mut c,
            [0.3 * k as f32 - 0.3, 0.1, 0.5],
            [0.35; 3],
            ID,
            o,
            [1.0, 1.0, 0.9],
        );
    }
    AssetSpec::new(
        "alpha_below_threshold",
        "faint splats (opacity 0.003 and 0.02) over an opaque one: contributions below α = 1/255 may be skipped (3DGS) or drawn, nothing else changes",
        "profile §3 (3DGS skips α < 1/255; the RC is silent)",
        "visible veils: faint splats are boosted (e.g. an opacity decoded as a logit); holes: skipping removes more than α < 1/255",
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 3.0])],
    )
    .profile()
}

fn opaque() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for (k, rgb) in [[0.9, 0.2, 0.2], [0.2, 0.85, 0.3], [0.25, 0.3, 0.95]]
        .into_iter()
        .enumerate()
    {
        splat(
            &mut c,
            [0.35 * k as f32 - 0.35, 0.1 * k as f32, 0.3 * k as f32],
            [0.3; 3],
            ID,
            1.0,
            rgb,
        );
    }
    AssetSpec::new(
        "opacity_one_cap",
        "opacity exactly 1: overlapping splats hide what is behind (3DGS caps α at 0.99, letting 1% through; the tolerance allows α = 1 too)",
        "RC Attributes (OPACITY ∈ [0, 1]); profile §3 (α cap)",
        "black holes or NaN: α = 1 breaks the compositing (division by 1 − α, or T reaching 0 in a front-to-back loop)",
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 3.0])],
    )
}

fn cutoff() -> AssetSpec {
    // σ' chosen so that 9σ'² = 1301.5 px² while the pixel centres' squared distances from the
    // centre are 2n + 0.5: no pixel lies within rounding of the 3σ ellipse (no cut term).
    let fy = 0.5 * super::HEIGHT as f64 / (25f64.to_radians()).tan();
    let sigma_px = (1301.5 / 9.0 - splatgl::profile::DILATION_PX2).sqrt();
    let s = (sigma_px * 3.0 / fy) as f32;
    let mut c = SplatCloud::new(0);
    splat(&mut c, [0.0; 3], [s; 3], ID, 0.9, [1.0, 1.0, 1.0]);
    AssetSpec::new(
        "cutoff_three_sigma",
        "one large splat (σ ≈ 12 px, opacity 0.9): it ends exactly at Mahalanobis distance 3, where α is still 0.9·e^−4.5 = 0.011",
        "RC Ellipse Kernel Rendering (3σ cut-off)",
        "a missing faint ring: the cut is at 2.83σ (power > 4, the review draft's shader); a wider halo: no cut or a larger one",
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 3.0])],
    )
    .catches(&[Erratum::F])
    .detects(&[Variant::BoxCut, Variant::SquareCut])
}

fn blend_order() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for k in 0..5 {
        let p = [
            0.18 * k as f32 - 0.36,
            0.06 * k as f32 - 0.12,
            0.35 * k as f32 - 0.7,
        ];
        splat(
            &mut c,
            p,
            [0.35, 0.3, 0.3],
            ID,
            0.5 + 0.08 * k as f32,
            palette(k),
        );
    }
    AssetSpec::new(
        "blend_premultiplied_order",
        "five overlapping translucent splats: back to front, C ← c·α + C·(1 − α) (premultiplied, ONE / ONE_MINUS_SRC_ALPHA)",
        "RC Splat Composition",
        "colours too dark or the wrong splat on top: α applied twice (SRC_ALPHA on premultiplied colour), or front-to-back order with back-to-front blending",
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 3.0])],
    )
    .catches(&[Erratum::G])
}

fn jacobian_clamp() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for (k, x) in [-3.2f32, 3.4, 0.0].into_iter().enumerate() {
        let s = if x == 0.0 { [0.2; 3] } else { [1.6, 0.5, 0.5] };
        let q = glam::Quat::from_rotation_z(0.3 * k as f32).to_array();
        splat(&mut c, [x, 0.2, 0.0], s, q, 0.8, [0.9, 0.8, 0.3]);
    }
    AssetSpec::new(
        "jacobian_clamp_offscreen",
        "large splats whose means lie far outside the view (|x/z| > 1.3·tan(half fov)) reach into the image; J uses x/z clamped to ±1.3·tan",
        "RC Splat Projection (J); profile §2 (3DGS computeCov2D clamp)",
        "huge smeared streaks from the sides: J is evaluated at the unclamped x/z",
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 2.0])],
    )
    .catches(&[Erratum::K])
    // The clamp is 3DGS's computeCov2D; the RC does not name it.
    .profile()
}

fn pixel_mapping() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for j in 0..3 {
        for i in 0..3 {
            let p = [i as f32 * 1.1 - 1.1, j as f32 * 0.8 - 0.8, 0.0];
            splat(
                &mut c,
                p,
                [0.09, 0.05, 0.05],
                quat(0.0, 0.0, 40.0 * (i + j) as f32),
                0.9,
                palette(i + 3 * j),
            );
        }
    }
    AssetSpec::new(
        "projection_pixel_mapping",
        "a grid of small splats under a 60° camera: the mean maps to (fx·x/z + cx, fy·y/z + cy) and the footprint is sized in pixels",
        "RC Splat Projection",
        "grid squeezed towards a corner or splats cut square: the quad offset or centre is not converted to pixels (the review draft's shader is right only at 90°)",
        single(vec![prim(c)]),
        vec![CameraSpec {
            yfov_deg: 60.0,
            ..cam("front", [0.0, 0.0, 3.0])
        }],
    )
    .catches(&[Erratum::D])
}

fn overbright() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    // Behind: red 3.0 and green 1.5 at α 0.6 (c·α = 1.8 and 0.9; blue 0.8 stays below 1);
    // in front, half over it, a dark splat at α 0.6. Float blending keeps 0.4 × 1.8 = 0.72 of
    // the red under it; an 8-bit target clamps the red sum to 1 first (0.4), a per-splat
    // clamp the colour (0.24). 1.0 apart in depth: no order is in doubt.
    splat(
        &mut c,
        [-0.2, 0.0, -0.5],
        [0.3; 3],
        ID,
        0.6,
        [3.0, 1.5, 0.8],
    );
    splat(
        &mut c,
        [0.25, 0.05, 0.5],
        [0.25; 3],
        ID,
        0.6,
        [0.1, 0.1, 0.1],
    );
    AssetSpec::new(
        "overbright_blending",
        "colours above 1 (red 3.0, green 1.5) under a translucent splat: blended in floating point (the RC's note: \"blending should be performed using floating-point color buffer formats\"), only the final colour clamped",
        "RC Splat Composition (the final colour MUST be clamped; float buffers a note's \"should\"): profile",
        "a dull red under the dark splat: the colour sum is clamped to 1 between blends (8-bit target) or each splat's colour is clamped before blending",
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 3.0])],
    )
    .detects(&[
        Variant::ColourClamped,
        Variant::Unorm8Blending,
        Variant::Colour8Bit,
    ])
    .profile()
}

/// The assets of this file, in manifest order.
pub(super) fn all() -> Vec<AssetSpec> {
    vec![
        near_plane(),
        screen_border(),
        subpixel(),
        needles(),
        faint(),
        opaque(),
        overbright(),
        cutoff(),
        blend_order(),
        jacobian_clamp(),
        pixel_mapping(),
    ]
}
