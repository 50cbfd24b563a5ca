//! The suite's assets: each a small glTF document checking one rule, with its cameras.
//!
//! Every asset is built here from explicit numbers (no randomness), in glTF axes (+Y up, the
//! cameras look at the origin from +Z unless said otherwise), colours in [0, 1] for every view
//! direction (so no term for over-bright colours is needed), on a black background.
//! `docs/conformance.md` lists them with the rule and the RC section each checks.

use super::Erratum;
use super::manifest::Checks;
use super::model::Variant;
use glam::Quat;
use splatgl::cloud::SplatCloud;
use splatgl::sh::dc_from_color;
use splatgl::write::quantize::dequantize_node;
use splatgl::write::scene::{NodeTransform, SceneDoc, SceneNode, SplatPrimitive};
use splatgl::write::{Comp, GltfWriteOptions};

/// A camera of an asset: look-at, vertical field of view, near plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraSpec {
    /// Name (the image's file stem).
    pub name: &'static str,
    /// Camera centre.
    pub eye: [f64; 3],
    /// Point at the image centre.
    pub target: [f64; 3],
    /// Roughly up in the image.
    pub up: [f64; 3],
    /// Vertical field of view, degrees.
    pub yfov_deg: f64,
    /// Near plane (`znear`).
    pub znear: f64,
}

/// A camera at `eye` looking at the origin, +Y up, 50° vertical fov.
pub const fn cam(name: &'static str, eye: [f64; 3]) -> CameraSpec {
    CameraSpec {
        name,
        eye,
        target: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        yfov_deg: 50.0,
        znear: 0.05,
    }
}

/// One asset of the suite.
#[derive(Debug, Clone)]
pub struct AssetSpec {
    /// File stem; names the rule.
    pub name: &'static str,
    /// The rule it checks.
    pub rule: &'static str,
    /// The RC section (or profile section) the rule comes from.
    pub section: &'static str,
    /// What a failure usually means.
    pub failure_means: &'static str,
    /// The document (cameras are added by the generator).
    pub doc: SceneDoc,
    /// Its cameras.
    pub cameras: Vec<CameraSpec>,
    /// A rule of the RC, or a choice the RC leaves open (splatgl's profile).
    pub checks: Checks,
    /// Errata the asset is designed to catch (the generator checks that it does).
    pub designed_for: &'static [Erratum],
    /// Implementation variants the asset is designed to detect (its bound does not admit
    /// them; the generator checks that it detects them).
    pub detects: &'static [Variant],
    /// Not required of an RC implementation (legacy compatibility).
    pub optional: bool,
    /// Whether the file is valid per the RC (`splatgl validate` passes it).
    pub rc_valid: bool,
    /// Written as `.gltf` (JSON) instead of `.glb`.
    pub json: bool,
}

impl AssetSpec {
    pub(crate) fn new(
        name: &'static str,
        rule: &'static str,
        section: &'static str,
        failure_means: &'static str,
        doc: SceneDoc,
        cameras: Vec<CameraSpec>,
    ) -> Self {
        AssetSpec {
            name,
            rule,
            section,
            failure_means,
            doc,
            cameras,
            checks: Checks::Rc,
            designed_for: &[],
            detects: &[],
            optional: false,
            rc_valid: true,
            json: false,
        }
    }
    pub(crate) fn catches(mut self, e: &'static [Erratum]) -> Self {
        self.designed_for = e;
        self
    }
    /// What of the choices the judged region leaves out this asset tests: the extent when it
    /// detects a cut-off shape (or catches erratum f by design), the order when it detects
    /// view-depth order, the dilation when it catches erratum i by design or detects the
    /// eigenvalue floor.
    pub(crate) fn tested(&self) -> super::judge::Tested {
        super::judge::Tested {
            extent: self.designed_for.contains(&Erratum::F)
                || self
                    .detects
                    .iter()
                    .any(|v| matches!(v, Variant::BoxCut | Variant::SquareCut)),
            order: self.detects.contains(&Variant::ViewDepthOrder),
            dilation: self.designed_for.contains(&Erratum::I)
                || self.detects.contains(&Variant::EigenvalueFloor),
        }
    }

    /// Variants the asset is designed to detect.
    pub(crate) fn detects(mut self, v: &'static [Variant]) -> Self {
        self.detects = v;
        self
    }
    /// Marks the asset as checking a choice the RC leaves open (reported apart, never fails).
    pub(crate) fn profile(mut self) -> Self {
        self.checks = Checks::Profile;
        self
    }
}

/// Quaternion `[x, y, z, w]` from Euler angles (degrees, XYZ order).
pub(crate) fn quat(x: f32, y: f32, z: f32) -> [f32; 4] {
    let (x, y, z) = (x.to_radians(), y.to_radians(), z.to_radians());
    Quat::from_euler(glam::EulerRot::XYZ, x, y, z).to_array()
}

/// Appends a splat with DC colour `rgb` (higher coefficients zero).
pub(crate) fn splat(
    c: &mut SplatCloud,
    p: [f32; 3],
    s: [f32; 3],
    q: [f32; 4],
    o: f32,
    rgb: [f64; 3],
) {
    let mut sh = vec![[0.0f32; 3]; c.coeffs_per_splat()];
    sh[0] = rgb.map(dc_from_color);
    c.push(p, s, q, o, &sh);
}

pub(crate) const ID: [f32; 4] = [0.0, 0.0, 0.0, 1.0];

/// A primitive with default (float) options.
pub(crate) fn prim(cloud: SplatCloud) -> SplatPrimitive {
    SplatPrimitive {
        cloud,
        options: GltfWriteOptions::default(),
    }
}

/// A document with one root node holding one mesh of `prims`.
pub(crate) fn single(prims: Vec<SplatPrimitive>) -> SceneDoc {
    let mut d = SceneDoc::default();
    let m = d.add_mesh(prims);
    let n = d.add_node(SceneNode {
        mesh: Some(m),
        ..Default::default()
    });
    d.roots.push(n);
    d
}

/// Adds a root node holding `cloud` (world space) stored with POSITION/SCALE types `pos`,
/// `scale` (dequantization node matrix when needed) and ROTATION/OPACITY `rot`, `op`.
pub(crate) fn add_quantized(
    d: &mut SceneDoc,
    cloud: &SplatCloud,
    pos: Comp,
    rot: Comp,
    scale: Comp,
    op: Comp,
) {
    let dq = dequantize_node(cloud, pos, scale);
    let options = GltfWriteOptions {
        position: pos,
        rotation: rot,
        scale,
        opacity: op,
        ..Default::default()
    };
    let m = d.add_mesh(vec![SplatPrimitive {
        cloud: dq.cloud,
        options,
    }]);
    let n = d.add_node(SceneNode {
        name: Some(format!(
            "{}/{}/{}/{}",
            pos.name(),
            rot.name(),
            scale.name(),
            op.name()
        )),
        mesh: Some(m),
        transform: dq
            .matrix
            .map_or(NodeTransform::Identity, NodeTransform::Matrix),
        ..Default::default()
    });
    d.roots.push(n);
}

const PALETTE: [[f64; 3]; 9] = [
    [0.9, 0.2, 0.15],
    [0.2, 0.8, 0.25],
    [0.2, 0.35, 0.9],
    [0.9, 0.85, 0.2],
    [0.8, 0.25, 0.8],
    [0.2, 0.8, 0.8],
    [0.95, 0.55, 0.2],
    [0.55, 0.3, 0.95],
    [0.85, 0.85, 0.85],
];

/// Colour `k` of the suite's palette (cycled).
pub(crate) fn palette(k: usize) -> [f64; 3] {
    PALETTE[k % PALETTE.len()]
}

/// Every asset of the suite, in manifest order.
pub fn all() -> Vec<AssetSpec> {
    use super::assets_scene::*;
    let mut v = vec![
        attr_positions(),
        attr_rotations(),
        attr_scales(),
        attr_opacities(),
        accessor_layout(),
        cube_corners(),
        long_axes(),
        oblique_view(),
        node_hierarchy(),
        instanced_mesh(),
        interleaved_primitives(),
        distance_vs_depth(),
        color_space(false),
        color_space(true),
    ];
    v.extend(super::assets_light::all());
    v.extend(super::assets_pixel::all());
    v
}
