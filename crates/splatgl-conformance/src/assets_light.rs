//! The suite's assets, part 2: lighting (SH) and fallbacks.

use super::Erratum;
use super::assets::{AssetSpec, CameraSpec, ID, cam, prim, quat, single, splat};
use glam::DQuat;
use splatgl::cloud::{Known, SplatCloud};
use splatgl::write::GltfWriteOptions;
use splatgl::write::scene::{NodeTransform, SceneDoc, SceneNode, SplatPrimitive};

const TOP: CameraSpec = CameraSpec {
    up: [0.0, 0.0, -1.0],
    ..cam("top", [0.0, 4.0, 0.0])
};

fn sh_degree(l: usize) -> AssetSpec {
    let mut c = SplatCloud::new(l as u8);
    if l == 0 {
        let cols = [
            [0.9, 0.2, 0.1],
            [0.1, 0.7, 0.3],
            [0.25, 0.3, 0.95],
            [0.75, 0.75, 0.2],
        ];
        // Well apart (6σ): no splat overlaps another, so neither the blending order (two
        // splats equally far from the front camera) nor the extent decides a judged pixel.
        for (k, rgb) in cols.into_iter().enumerate() {
            splat(
                &mut c,
                [k as f32 * 1.2 - 1.8, 0.0, 0.0],
                [0.2; 3],
                ID,
                0.9,
                rgb,
            );
        }
    } else {
        // One splat per coefficient m = −l..l, only that coefficient set: (a, −a, a/2) on a
        // grey base (DC 0 → 0.5). |Y| ≤ 0.75 for every degree here, so colours stay in
        // 0.5 ± 0.3 from every direction. 6σ apart in a row (degree 3: two rows, the second
        // shifted by half a step so that they do not line up seen from above): no two overlap
        // from the front or the back, so neither the blending order nor the extent decides a
        // judged pixel.
        let n = 2 * l + 1;
        for j in 0..n {
            let (x, y) = match (n, j) {
                (7, 0..=3) => ((j as f32 - 1.5) * 0.96, 0.55),
                (7, _) => ((j as f32 - 5.0) * 0.96, -0.55),
                _ => ((j as f32 - (n - 1) as f32 / 2.0) * 0.96, 0.0),
            };
            splat(&mut c, [x, y, 0.0], [0.16; 3], ID, 0.9, [0.5; 3]);
            let k = c.coeffs_per_splat();
            c.sh[j * k + l * l + j] = [0.4, -0.4, 0.2];
        }
    }
    let names = ["sh_degree_0", "sh_degree_1", "sh_degree_2", "sh_degree_3"];
    let rules = [
        "SH degree 0 only: colour = SH_C0·DC + 0.5 (no sigmoid)",
        "SH degree 1, one coefficient per splat (m = −1, 0, 1), seen from the front, the back and above: RC basis with the Condon–Shortley signs",
        "SH degree 2, one coefficient per splat (m = −2..2): RC basis with the Condon–Shortley signs",
        "SH degree 3, one coefficient per splat (m = −3..3): RC basis, including 1.445 for Y₃,₂",
    ];
    AssetSpec::new(
        names[l],
        rules[l],
        "RC Lighting (spherical harmonics); Appendix A (basis)",
        "a splat with the wrong tint from one side: that coefficient's sign or constant is wrong (the review draft dropped the Condon–Shortley phase), coefficients are read in the wrong order, or a sigmoid is applied",
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 4.0]), cam("back", [0.0, 0.0, -4.0]), TOP],
    )
    .catches(&[Erratum::E])
}

fn sh_rotated_node() -> AssetSpec {
    let mut c = SplatCloud::new(3);
    for j in 0..3 {
        splat(
            &mut c,
            [j as f32 * 0.6 - 0.6, 0.0, 0.0],
            [0.2; 3],
            ID,
            0.9,
            [0.5; 3],
        );
        let s = &mut c.sh[16 * j..16 * (j + 1)];
        s[1 + j] = [0.3, -0.25, 0.1];
        s[9 + 2 * j] = [-0.2, 0.2, 0.25];
    }
    let mut d = SceneDoc::default();
    let m = d.add_mesh(vec![prim(c)]);
    let r = DQuat::from_rotation_x(30f64.to_radians()) * DQuat::from_rotation_y(90f64.to_radians());
    let n = d.add_node(SceneNode {
        mesh: Some(m),
        transform: NodeTransform::Trs {
            translation: [0.0; 3],
            rotation: r.to_array(),
            scale: [1.0; 3],
        },
        ..Default::default()
    });
    d.roots.push(n);
    AssetSpec::new(
        "sh_rotated_node",
        "SH of degrees 1 and 3 under a rotated node: the view direction is taken in the splat's rotated frame (SH rotated with the node)",
        "RC Splat Reconstruction and Lighting (node transforms; view direction camera → global mean)",
        "tints wrong from every side: the SH are evaluated in the mesh's local frame without the node rotation",
        d,
        vec![cam("front", [0.0, 0.0, 4.0]), cam("side", [4.0, 0.0, 0.3])],
    )
    .catches(&[Erratum::E])
}

fn color0() -> AssetSpec {
    let mut c = SplatCloud::new(1);
    for (k, rgb) in [[0.25, 0.35, 0.6], [0.6, 0.3, 0.2], [0.3, 0.55, 0.3]]
        .into_iter()
        .enumerate()
    {
        splat(
            &mut c,
            [k as f32 * 0.7 - 0.7, 0.0, 0.0],
            [0.25; 3],
            ID,
            0.85,
            rgb,
        );
        c.sh[4 * k + 2] = [0.25, 0.1, -0.2];
    }
    let p = SplatPrimitive {
        cloud: c,
        options: GltfWriteOptions {
            color0: true,
            ..Default::default()
        },
    };
    AssetSpec::new(
        "color0_fallback",
        "COLOR_0 present (the RC's fallback, linear = sRGB-decoded SH0 colour): a splat renderer ignores it and uses the SH",
        "RC Fallback Behavior",
        "darker or without view dependence: COLOR_0 is used instead of the SH (it is linear and has no view-dependent part)",
        single(vec![p]),
        vec![cam("front", [0.0, 0.6, 3.0])],
    )
}

fn unknown(kernel: bool) -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for k in 0..3 {
        splat(
            &mut c,
            [k as f32 * 0.6 - 0.6, 0.0, 0.1 * k as f32],
            [0.3, 0.15, 0.15],
            quat(0.0, 0.0, 30.0 * k as f32),
            0.7,
            [0.8, 0.4 + 0.2 * k as f64, 0.2],
        );
    }
    if kernel {
        c.meta.kernel = Known::Unknown("customShape".into());
        c.meta.sorting_method = Known::Unknown("customSort".into());
    } else {
        c.meta.color_space = Known::Unknown("custom_space_display".into());
    }
    let mut a = if kernel {
        AssetSpec::new(
            "unknown_kernel",
            "kernel \"customShape\" and sortingMethod \"customSort\" (no extension that defines them): fall back to ellipse and cameraDistance",
            "RC Kernel, Sorting Method; Example: Adding additional Kernel Types",
            "nothing drawn or an error: unknown enum values must fall back to the base extension's, not reject the file",
            single(vec![prim(c)]),
            vec![cam("front", [0.0, 0.0, 3.0])],
        )
    } else {
        AssetSpec::new(
            "unknown_color_space",
            "colorSpace \"custom_space_display\": splatgl falls back to srgb_rec709_display (the RC names no fallback; optional)",
            "RC Color Space (extensible values)",
            "a different fallback (e.g. linear) or a rejected file; the RC leaves the fallback open",
            single(vec![prim(c)]),
            vec![cam("front", [0.0, 0.0, 3.0])],
        )
    };
    a.optional = !kernel;
    if kernel {
        // The RC's fallback for an unknown kernel is a lowercase "should", in an example
        // section ("Adding additional Kernel Types"): a recommendation, not a rule.
        a = a.profile();
    }
    a
}

fn legacy_log_scale() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for k in 0..4 {
        let s = [0.3 - 0.05 * k as f32, 0.08, 0.12];
        splat(
            &mut c,
            [k as f32 * 0.55 - 0.8, 0.1 * k as f32, 0.0],
            s,
            quat(0.0, 0.0, 25.0 * k as f32),
            0.85,
            [0.3 + 0.2 * k as f64, 0.5, 0.8 - 0.15 * k as f64],
        );
    }
    let p = SplatPrimitive {
        cloud: c,
        options: GltfWriteOptions {
            legacy_log_scale: true,
            ..Default::default()
        },
    };
    let mut a = AssetSpec::new(
        "legacy_log_scale",
        "a review-draft file: SCALE stored as ln(scale) (negative floats); readers of legacy files apply exp (optional; not RC-valid)",
        "review draft (SCALE in log space); RC Attributes forbid negative scales",
        "splats vanish or are tiny: the file is read as RC linear scale (clamping negatives) instead of being recognised as a legacy draft file",
        single(vec![p]),
        vec![cam("front", [0.0, 0.0, 3.5])],
    );
    a.optional = true;
    a.rc_valid = false;
    a.json = true;
    a
}

/// The assets of this file, in manifest order.
pub(super) fn all() -> Vec<AssetSpec> {
    vec![
        sh_degree(0),
        sh_degree(1),
        sh_degree(2),
        sh_degree(3),
        sh_rotated_node(),
        color0(),
        unknown(true),
        unknown(false),
        legacy_log_scale(),
    ]
}
