//! The suite's assets, part 1: attribute types, orientation, nodes, sorting, colour spaces.

use super::Erratum;
use super::assets::{
    AssetSpec, CameraSpec, ID, add_quantized, cam, palette, prim, quat, single, splat,
};
use super::model::Variant;
use glam::DQuat;
use splatgl::cloud::{Known, SplatCloud};
use splatgl::write::scene::{NodeTransform, SceneDoc, SceneNode, SplatPrimitive};
use splatgl::write::{Comp, GltfWriteOptions};

pub(super) fn attr_positions() -> AssetSpec {
    let mut d = SceneDoc::default();
    for (k, comp) in splatgl::write::POSITION_TYPES.into_iter().enumerate() {
        let (cx, cy) = ((k % 3) as f32 * 1.2 - 1.2, (k / 3) as f32 * 0.85 - 0.85);
        let mut c = SplatCloud::new(0);
        for (j, (dx, dy)) in [(-0.2, -0.1), (0.2, -0.12), (0.0, 0.17)]
            .into_iter()
            .enumerate()
        {
            let q = quat(0.0, 0.0, 25.0 * j as f32);
            splat(
                &mut c,
                [cx + dx, cy + dy, 0.1 * j as f32],
                [0.12, 0.06, 0.06],
                q,
                0.85,
                palette(k),
            );
        }
        add_quantized(&mut d, &c, comp, Comp::F32, Comp::F32, Comp::F32);
    }
    AssetSpec::new(
        "attr_position_types",
        "POSITION in float and every KHR_mesh_quantization type (i8, i8n, u8, u8n, i16, i16n, u16, u16n) with a dequantization node matrix",
        "RC Attributes (POSITION: inherited from glTF); KHR_mesh_quantization",
        "a cell missing or misplaced: that component type (or normalization) is decoded wrongly, or the node matrix is not applied to splats",
        d,
        vec![cam("front", [0.0, 0.0, 4.0])],
    )
}

pub(super) fn attr_rotations() -> AssetSpec {
    let mut d = SceneDoc::default();
    for (k, comp) in splatgl::write::ROTATION_TYPES.into_iter().enumerate() {
        let mut c = SplatCloud::new(0);
        let x = k as f32 * 1.3 - 1.3;
        splat(
            &mut c,
            [x, 0.35, 0.0],
            [0.45, 0.06, 0.12],
            quat(20.0, 35.0, 50.0),
            0.9,
            palette(k),
        );
        splat(
            &mut c,
            [x, -0.4, 0.0],
            [0.08, 0.4, 0.05],
            quat(-30.0, 10.0, 70.0),
            0.9,
            palette(k + 3),
        );
        add_quantized(&mut d, &c, Comp::F32, comp, Comp::F32, Comp::F32);
    }
    AssetSpec::new(
        "attr_rotation_types",
        "ROTATION as float, signed byte normalized and signed short normalized (xyzw)",
        "RC Attributes (ROTATION)",
        "needles of one column turned: that rotation type is decoded wrongly (normalization, xyzw order)",
        d,
        vec![cam("front", [0.0, 0.0, 4.0]), cam("oblique", [2.0, 1.5, 3.0])],
    )
    .catches(&[Erratum::A])
}

pub(super) fn attr_scales() -> AssetSpec {
    let mut d = SceneDoc::default();
    for (k, comp) in splatgl::write::SCALE_TYPES.into_iter().enumerate() {
        let mut c = SplatCloud::new(0);
        let x = k as f32 * 0.8 - 1.6;
        splat(
            &mut c,
            [x, 0.3, 0.0],
            [0.2, 0.07, 0.1],
            quat(0.0, 0.0, 30.0),
            0.9,
            palette(k),
        );
        splat(
            &mut c,
            [x, -0.35, 0.0],
            [0.06, 0.25, 0.1],
            ID,
            0.9,
            palette(k + 4),
        );
        add_quantized(&mut d, &c, Comp::F32, Comp::F32, comp, Comp::F32);
    }
    AssetSpec::new(
        "attr_scale_types",
        "SCALE as float, unsigned byte (normalized or not) and unsigned short (normalized or not), linear, scaled by the node matrix",
        "RC Attributes (SCALE: linear, MUST NOT be negative); Splat Reconstruction (Σ = M C Cᵀ Mᵀ)",
        "a column too big, too small or round: that scale type is decoded wrongly, read as log scale, or the node scale is not applied to Σ",
        d,
        vec![cam("front", [0.0, 0.0, 4.0])],
    )
}

pub(super) fn attr_opacities() -> AssetSpec {
    let mut d = SceneDoc::default();
    for (k, comp) in splatgl::write::OPACITY_TYPES.into_iter().enumerate() {
        let mut c = SplatCloud::new(0);
        let x = k as f32 * 1.3 - 1.3;
        for (j, o) in [0.25f32, 0.55, 0.9].into_iter().enumerate() {
            let y = 0.45 - 0.45 * j as f32;
            splat(&mut c, [x, y, 0.0], [0.22, 0.22, 0.22], ID, o, palette(k));
        }
        add_quantized(&mut d, &c, Comp::F32, Comp::F32, Comp::F32, comp);
    }
    AssetSpec::new(
        "attr_opacity_types",
        "OPACITY as float, unsigned byte normalized and unsigned short normalized, linear (no sigmoid)",
        "RC Attributes (OPACITY: normalized linear value)",
        "one column brighter or darker: that opacity type is decoded wrongly, or a sigmoid is applied",
        d,
        vec![cam("front", [0.0, 0.0, 4.0])],
    )
}

pub(super) fn accessor_layout() -> AssetSpec {
    let mut c = SplatCloud::new(1);
    for k in 0..6 {
        let x = k as f32 * 0.55 - 1.4;
        let o = if k % 3 == 2 { 0.0 } else { 0.8 };
        splat(
            &mut c,
            [x, 0.1 * k as f32 - 0.25, 0.0],
            [0.18, 0.1, 0.1],
            quat(0.0, 0.0, 15.0 * k as f32),
            o,
            palette(k),
        );
        c.sh[4 * k + 2] = [0.3, -0.2, 0.1];
    }
    let p = SplatPrimitive {
        cloud: c,
        options: GltfWriteOptions {
            padding: 4,
            sparse_opacity: true,
            ..Default::default()
        },
    };
    AssetSpec::new(
        "accessor_stride_sparse",
        "attributes read through byteStride and a sparse OPACITY accessor without bufferView (zeros plus overrides)",
        "glTF 2.0 §3.6.2 (accessors, sparse); RC Attributes",
        "garbled splats: byteStride ignored; splats missing or extra: the sparse accessor is not applied (or the zero fill is wrong)",
        single(vec![p]),
        vec![cam("front", [0.0, 0.0, 4.0])],
    )
}

pub(super) fn cube_corners() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for k in 0..8 {
        let b = [k & 1, (k >> 1) & 1, (k >> 2) & 1];
        let p = b.map(|v| if v == 1 { 0.5 } else { -0.5 });
        let rgb = b.map(|v| 0.15 + 0.8 * v as f64);
        splat(&mut c, p, [0.11; 3], ID, 0.9, rgb);
    }
    AssetSpec::new(
        "orientation_cube_corners",
        "unit-cube corners coloured by their signs (red +X, green +Y, blue +Z): glTF +Y up, right-handed, cameras looking down their −Z",
        "glTF 2.0 §3.4 coordinate system; RC Splat Projection",
        "corners swapped or mirrored: an axis flip, handedness or camera convention error (e.g. OpenCV vs glTF camera axes)",
        single(vec![prim(c)]),
        vec![
            cam("front", [0.0, 0.0, 3.2]),
            cam("oblique", [2.2, 1.6, 2.4]),
        ],
    )
}

pub(super) fn long_axes() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    splat(
        &mut c,
        [-0.9, 0.0, 0.0],
        [0.5, 0.04, 0.04],
        quat(0.0, 0.0, 40.0),
        0.95,
        palette(0),
    );
    splat(
        &mut c,
        [0.0, 0.0, 0.0],
        [0.04, 0.5, 0.04],
        quat(0.0, 0.0, -35.0),
        0.95,
        palette(1),
    );
    splat(
        &mut c,
        [0.9, 0.0, 0.0],
        [0.5, 0.04, 0.04],
        quat(30.0, 45.0, 60.0),
        0.95,
        palette(2),
    );
    AssetSpec::new(
        "orientation_long_axes",
        "needles with known long axes: local X turned +40° about Z, local Y turned −35° about Z, and an XYZ Euler turn",
        "RC Splat Reconstruction (C = R(q)·S, q = xyzw)",
        "needles tilted the wrong way: the rotation matrix is transposed (Σ = Rᵀ S² R) or the quaternion order is wxyz",
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 3.5]), cam("oblique", [1.5, 1.2, 3.0])],
    )
    .catches(&[Erratum::A])
}

pub(super) fn oblique_view() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for (k, x) in [-0.8f32, 0.0, 0.8].into_iter().enumerate() {
        let q = quat(23.0 * k as f32 + 17.0, 52.0, 34.0);
        splat(
            &mut c,
            [x, 0.0, 0.0],
            [0.35, 0.04, 0.1],
            q,
            0.9,
            palette(k + 3),
        );
    }
    AssetSpec::new(
        "covariance_oblique_view",
        "anisotropic splats seen by an oblique camera: Σ' = J W Σ Wᵀ Jᵀ with W the world → camera rotation",
        "RC Splat Projection",
        "footprints sheared or turned: the view rotation is transposed or the camera frame is wrong",
        single(vec![prim(c)]),
        vec![cam("oblique", [2.0, 1.5, 2.0])],
    )
    .catches(&[Erratum::B])
}

pub(super) fn node_hierarchy() -> AssetSpec {
    let mut c = SplatCloud::new(1);
    for k in 0..4 {
        let p = [k as f32 * 0.5 - 0.75, 0.2 * (k % 2) as f32, 0.0];
        splat(
            &mut c,
            p,
            [0.2, 0.06, 0.1],
            quat(0.0, 20.0 * k as f32, 30.0),
            0.9,
            palette(k),
        );
        c.sh[4 * k + 3] = [0.35, 0.0, -0.35];
    }
    let mut d = SceneDoc::default();
    let m = d.add_mesh(vec![prim(c)]);
    let child = d.add_node(SceneNode {
        mesh: Some(m),
        transform: NodeTransform::Trs {
            translation: [0.3, -0.2, 0.1],
            rotation: [0.0, 0.0, 0.0, 1.0],
            scale: [1.5, 0.6, 1.0],
        },
        ..Default::default()
    });
    let r =
        DQuat::from_rotation_y(40f64.to_radians()) * DQuat::from_rotation_x(-20f64.to_radians());
    let root = d.add_node(SceneNode {
        children: vec![child],
        transform: NodeTransform::Trs {
            translation: [0.0, 0.1, 0.0],
            rotation: r.to_array(),
            scale: [1.0; 3],
        },
        ..Default::default()
    });
    d.roots.push(root);
    AssetSpec::new(
        "node_hierarchy_trs",
        "a parent rotation over a child with non-uniform scale and translation: means by the global matrix, Σ = M C Cᵀ Mᵀ, SH rotated",
        "RC Splat Reconstruction (global transformation matrix)",
        "splats in the wrong place or shape: node transforms not composed (parent × child), non-uniform scale not applied to Σ, or SH not rotated",
        d,
        vec![
            cam("front", [0.0, 0.0, 4.0]),
            cam("oblique", [2.5, 1.5, 2.5]),
        ],
    )
}

pub(super) fn instanced_mesh() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for k in 0..3 {
        splat(
            &mut c,
            [0.25 * k as f32 - 0.25, 0.0, 0.0],
            [0.12, 0.05, 0.05],
            quat(0.0, 0.0, 30.0 * k as f32),
            0.9,
            palette(k),
        );
    }
    let mut d = SceneDoc::default();
    let m = d.add_mesh(vec![prim(c)]);
    for (k, t) in [[-1.0, 0.5, 0.0], [1.0, 0.4, -0.5], [0.0, -0.6, 0.5]]
        .into_iter()
        .enumerate()
    {
        let r = DQuat::from_rotation_z((60.0 * k as f64).to_radians());
        let n = d.add_node(SceneNode {
            mesh: Some(m),
            transform: NodeTransform::Trs {
                translation: t,
                rotation: r.to_array(),
                scale: [1.0 + 0.3 * k as f64; 3],
            },
            ..Default::default()
        });
        d.roots.push(n);
    }
    AssetSpec::new(
        "node_instanced_mesh",
        "one splat mesh instanced by three nodes (translated, rotated, uniformly scaled)",
        "RC Splat Reconstruction; glTF 2.0 §3.5 (nodes)",
        "only one copy, or copies in the wrong place: mesh instancing is not supported for splats",
        d,
        vec![cam("front", [0.0, 0.0, 4.0])],
    )
}

/// Isotropic splats: the asset is about the order, so the covariance errata (a, b) leave it.
pub(super) fn interleaved_primitives() -> AssetSpec {
    let (mut a, mut b) = (SplatCloud::new(0), SplatCloud::new(0));
    for k in 0..3 {
        let z = 0.6 - 0.6 * k as f32;
        splat(
            &mut a,
            [0.15 * k as f32 - 0.15, 0.0, z],
            [0.32; 3],
            ID,
            0.7,
            [0.9, 0.15, 0.1],
        );
    }
    for k in 0..2 {
        let z = 0.3 - 0.6 * k as f32;
        splat(
            &mut b,
            [0.1 - 0.2 * k as f32, 0.1, z],
            [0.32; 3],
            ID,
            0.7,
            [0.1, 0.3, 0.95],
        );
    }
    AssetSpec::new(
        "primitives_interleaved_depth",
        "two splat primitives whose splats interleave in depth: one global back-to-front sort over all primitives",
        "RC Sorting Method; Splat Composition",
        "red and blue layered wrongly: each primitive is sorted and drawn separately instead of one global sort",
        single(vec![prim(a), prim(b)]),
        vec![cam("front", [0.4, 0.3, 3.0])],
    )
}

pub(super) fn distance_vs_depth() -> AssetSpec {
    let mut c = SplatCloud::new(0);
    // A on the axis: depth 3, distance 3. B off axis: depth 2.4 (nearer) but distance 3.26
    // (farther). cameraDistance draws B first, A over it; a view-depth sort does the opposite.
    splat(
        &mut c,
        [0.0, 0.0, -3.0],
        [1.1, 0.55, 0.2],
        ID,
        0.8,
        [0.9, 0.2, 0.15],
    );
    splat(
        &mut c,
        [-2.2, 0.0, -2.4],
        [1.2, 0.5, 0.2],
        quat(0.0, -40.0, 0.0),
        0.8,
        [0.15, 0.85, 0.2],
    );
    AssetSpec::new(
        "sort_distance_not_depth",
        "two overlapping splats whose camera-distance order and view-depth order disagree: sort by distance to the camera",
        "RC Sorting Method (cameraDistance)",
        "green over red: the renderer sorts by view-space depth instead of the distance to the camera",
        single(vec![prim(c)]),
        vec![CameraSpec {
            target: [0.0, 0.0, -1.0],
            yfov_deg: 70.0,
            ..cam("front", [0.0, 0.0, 0.0])
        }],
    )
    .detects(&[Variant::ViewDepthOrder])
}

pub(super) fn color_space(linear: bool) -> AssetSpec {
    let mut c = SplatCloud::new(0);
    for (k, (x, y)) in [(-0.3, 0.2), (0.3, 0.2), (0.0, -0.25)]
        .into_iter()
        .enumerate()
    {
        splat(
            &mut c,
            [x, y, 0.1 * k as f32],
            [0.4, 0.4, 0.4],
            ID,
            0.6,
            palette(k),
        );
    }
    splat(&mut c, [0.0, 0.0, 0.5], [0.15; 3], ID, 0.5, [0.5, 0.5, 0.5]);
    if linear {
        c.meta.color_space = Known::Known(splatgl::cloud::ColorSpace::LinRec709Display);
    }
    let (name, rule, fail) = if linear {
        (
            "color_space_linear",
            "colorSpace lin_rec709_display: blend the linear values, then encode to sRGB for display",
            "too dark or wrong overlaps: the colour space is ignored, or the transfer function is applied per splat before blending",
        )
    } else {
        (
            "color_space_srgb",
            "colorSpace srgb_rec709_display: blend the values as stored and display them as they are",
            "too bright or wrong overlaps: the values are decoded/encoded although they are display values",
        )
    };
    let spec = AssetSpec::new(
        name,
        rule,
        "RC Color Space (all blending before any transfer-function conversion)",
        fail,
        single(vec![prim(c)]),
        vec![cam("front", [0.0, 0.0, 3.0])],
    );
    if linear {
        spec.detects(&[Variant::ColorSpaceIgnored])
    } else {
        spec
    }
}
