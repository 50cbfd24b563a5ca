//! A tileset splatgl built, read by a renderer splatgl did not write: CesiumJS 1.145 (npm
//! `cesium`, headless Chromium, `scripts/conformance/cesium-tileset.mjs`, the conformance
//! adapter's page). The real biker scene is built twice with `--spz-compress` (CesiumJS draws
//! only SPZ splats): as a LOD tileset of 8,192-splat tiles, and as one tile holding every
//! splat. From splatgl's own automatic framing (`render --print-camera-json`):
//!
//! - at the same screen-space error CesiumJS draws exactly the tiles and splats splatgl
//!   selects (the leaves at 1 px, two merged tiles at its default 16 px): the geometric errors
//!   and bounding volumes mean the same to both;
//! - CesiumJS's image of the leaves equals, to float rounding, its image of the one-tile
//!   scene: every tile's content, frame and bounds read as splatgl wrote them; its image at
//!   16 px is far from that (the coarse, merged tiles are what it drew);
//! - splatgl's image is within CesiumJS's renderer deviations of CesiumJS's, for the leaves
//!   and for the coarse tiles (its 2.83σ square, near-zero dilation and view-depth order:
//!   docs/conformance-engines.md, "CesiumJS"), and much closer than to splatgl's image mirrored.
//!
//! Needs node, chromium, the npm tools and the real data; without them the test is skipped,
//! which fails under `SPLATGL_REQUIRE=all`.

use crate::common;
use common::cli::run;
use common::third_party::{missing_tools, tmp};
use splatgl::image::Image;
use std::path::Path;
use std::process::Command;

/// Builds `scene` into DIR/tileset.json with `--chunk-splats chunk --spz-compress`.
fn build(scene: &Path, dir: &Path, chunk: u32) -> String {
    let ts = dir.join("tileset.json").to_str().unwrap().to_owned();
    let chunk = chunk.to_string();
    let r = run(&[
        "convert",
        scene.to_str().unwrap(),
        &ts,
        "--chunk-splats",
        &chunk,
        "--spz-compress",
    ]);
    assert_eq!(r.code, 0, "{}", r.all());
    ts
}

/// "N selected, M splats" of `render -v`'s tiles line.
fn selected(stderr: &str) -> (u64, u64) {
    let line = stderr.lines().find(|l| l.starts_with("tiles: ")).unwrap();
    let n = |after: &str| -> u64 {
        let i = line.find(after).unwrap();
        let head = line[..i].trim_end();
        head[head.rfind(' ').unwrap() + 1..].parse().unwrap()
    };
    (n(" selected"), n(" splats"))
}

/// splatgl's render of `ts` at `sse` px (budget out of the way): the image and what it selected.
fn ours(ts: &str, cams: &Path, sse: &str, out: &Path) -> (Image, (u64, u64)) {
    let r = run(&[
        "render",
        ts,
        "--camera",
        cams.to_str().unwrap(),
        "--max-screen-error",
        sse,
        "--splat-budget",
        "10000000",
        "-v",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}", r.all());
    (Image::read(out).unwrap(), selected(&r.stderr))
}

/// CesiumJS's renders of `ts` from `cams` at each of `sses`: stderr (what it drew).
fn cesium(ts: &str, cams: &Path, sses: &str, out: &Path) -> String {
    let script = common::root().join("scripts/conformance/cesium-tileset.mjs");
    let o = Command::new("node")
        .arg(script)
        .args([ts, cams.to_str().unwrap(), out.to_str().unwrap()])
        .args(["--max-sse", sses, "--timeout", "300"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "cesium-tileset.mjs: {err}");
    err
}

/// What CesiumJS said it drew for `image`: (tiles, splats).
fn drawn(stderr: &str, image: &str) -> (u64, u64) {
    let at = format!("{image}: drawn ");
    let line = stderr.lines().find_map(|l| l.split_once(&at)).unwrap().1;
    let w: Vec<&str> = line.split_whitespace().collect();
    (w[3].parse().unwrap(), w[0].parse().unwrap())
}

fn psnr(a: &Image, b: &Image) -> f64 {
    common::lod::psnr(a, b)
}

/// `img` mirrored left to right.
fn mirrored(img: &Image) -> Image {
    let (w, h) = (img.width, img.height);
    let mut out = img.clone();
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            out.pixels[i] = img.pixels[(y * w + (w - 1 - x)) as usize];
        }
    }
    out
}

#[test]
fn cesium_draws_a_splatgl_tileset_as_splatgl_selects_and_places_it() {
    if let Some(why) = missing_tools("cesium/Build/Cesium/Cesium.js") {
        common::skip(&why);
        return;
    }
    let Some(scene) = common::real("playcanvas_biker.compressed.ply") else {
        common::skip("playcanvas_biker.compressed.ply");
        return;
    };
    let dir = tmp("tiles-cesium");
    let (lod, whole) = (
        build(&scene, &dir.join("lod"), 8192),
        build(&scene, &dir.join("whole"), 1 << 20),
    );
    // The camera: splatgl's automatic framing of the tileset, as a cameras.json.
    let cams = dir.join("cameras.json");
    let framed = run(&[
        "render",
        &lod,
        "--width",
        "320",
        "--height",
        "240",
        "--print-camera-json",
        "-o",
        dir.join("framing.png").to_str().unwrap(),
    ]);
    assert_eq!(framed.code, 0, "{}", framed.all());
    std::fs::write(&cams, framed.out()).unwrap();

    let (fine, fine_sel) = ours(&lod, &cams, "1", &dir.join("ours_1.png"));
    let (coarse, coarse_sel) = ours(&lod, &cams, "16", &dir.join("ours_16.png"));
    let theirs = dir.join("cesium");
    let err = cesium(&lod, &cams, "1,16", &theirs);
    cesium(&whole, &cams, "1", &dir.join("cesium_whole"));
    let img = |p: &Path| Image::read(p).unwrap();
    let (c_fine, c_coarse, c_whole) = (
        img(&theirs.join("view_0_sse_1.png")),
        img(&theirs.join("view_0_sse_16.png")),
        img(&dir.join("cesium_whole/view_0_sse_1.png")),
    );

    // The same selection: measured 32 tiles / 152,746 splats (every leaf) and 2 / 16,384.
    assert_eq!(drawn(&err, "view_0_sse_1"), fine_sel, "{err}");
    assert_eq!(drawn(&err, "view_0_sse_16"), coarse_sel, "{err}");
    assert!(
        fine_sel.0 > 8 && coarse_sel.0 < fine_sel.0,
        "{fine_sel:?} {coarse_sel:?}"
    );

    // Its leaves are its whole scene (measured 65.0 dB); the coarse tiles are not (32.9 dB).
    let leaves = psnr(&c_fine, &c_whole);
    let merged = psnr(&c_coarse, &c_whole);
    assert!(
        leaves >= 50.0,
        "CesiumJS leaves vs whole scene: {leaves:.1} dB"
    );
    assert!(
        merged < leaves - 15.0,
        "coarse {merged:.1} dB, leaves {leaves:.1} dB"
    );

    // splatgl vs CesiumJS: measured 28.4 dB (leaves) and 34.6 dB (coarse tiles); mirrored 20.9.
    let (p_fine, p_coarse) = (psnr(&fine, &c_fine), psnr(&coarse, &c_coarse));
    let p_mirrored = psnr(&mirrored(&fine), &c_fine);
    eprintln!(
        "splatgl vs CesiumJS: leaves {p_fine:.1} dB, coarse {p_coarse:.1} dB, mirrored {p_mirrored:.1} dB; \
         CesiumJS leaves vs its whole scene {leaves:.1} dB, coarse {merged:.1} dB"
    );
    assert!(p_fine >= 26.0, "leaves: {p_fine:.1} dB");
    assert!(p_coarse >= 30.0, "coarse tiles: {p_coarse:.1} dB");
    assert!(p_mirrored < p_fine - 5.0, "mirrored {p_mirrored:.1} dB");
    let _ = std::fs::remove_dir_all(&dir);
}
