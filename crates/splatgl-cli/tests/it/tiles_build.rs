//! Level-of-detail tilesets built by `splatgl convert IN out/tileset.json`
//! (`splatgl::tiles::build`): they pass `validate`, their leaves are the input exactly, a far
//! view of a real scene drawn from the coarse tiles stays close to the whole scene and closer
//! than the same number of splats picked uniformly, and a close view selects the finest tiles
//! around the eye.

use crate::common;
use common::cli::run;
use glam::Vec3;
use splatgl::SplatCloud;
use splatgl::camera::Camera;
use splatgl::tiles::{SelectOptions, TileCache, Tileset};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    common::fresh_dir("lod", name)
}

/// `convert input d/tileset.json` with `extra`; the tileset read back.
fn build(input: &Path, d: &Path, extra: &[&str]) -> Tileset {
    build_as(input, d, "tileset.json", extra)
}

/// `convert input d/NAME` (`tileset.json`: 3D Tiles; `lod-meta.json`: streamed SOG) with
/// `extra`; the tree read back.
fn build_as(input: &Path, d: &Path, name: &str, extra: &[&str]) -> Tileset {
    let out = d.join(name);
    let mut args = vec!["convert", input.to_str().unwrap(), out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let r = run(&args);
    assert_eq!(r.code, 0, "{}", r.all());
    assert!(
        r.stderr.contains("tiles in") || r.stderr.contains("streamed SOG: "),
        "{}",
        r.all()
    );
    let v = run(&["validate", out.to_str().unwrap()]);
    assert!(
        v.out().contains("valid (0 errors, 0 warnings)"),
        "{}",
        v.all()
    );
    splatgl::tiles::read(&out, &Default::default()).unwrap()
}

/// Every leaf of the tileset (its finest level: the input's splats) as one cloud.
fn leaves(ts: &Tileset, cache: &mut TileCache) -> SplatCloud {
    let leaves: Vec<_> = ts
        .root
        .walk()
        .into_iter()
        .filter(|t| t.children.is_empty())
        .collect();
    cache.merged(&leaves)
}

#[test]
fn a_built_tileset_validates_and_its_leaves_are_the_input() {
    let d = dir("leaves");
    let input = d.join("in.glb");
    let cloud = common::random_cloud(3000, 2, 1.0, 11);
    std::fs::write(&input, splatgl::write::to_glb(&cloud, &Default::default())).unwrap();
    let ts = build(&input, &d, &["--chunk-splats", "256"]);
    let mut cache = TileCache::new(&ts, &Default::default());
    let all = leaves(&ts, &mut cache);
    assert_eq!(all.len(), cloud.len());
    assert!(cache.warnings.is_empty(), "{:?}", cache.warnings);
    // Every tile within the chunk size; geometric errors shrink towards the leaves.
    for t in ts.root.walk() {
        assert!(cache.splats(t) <= 256, "{}", t.path);
        for c in &t.children {
            assert!(c.geometric_error < t.geometric_error, "{}", c.path);
        }
    }
    // The leaves hold the input's splats (turned z-up, as 3D Tiles turns glTF content): the
    // same multiset of opacities and of SH degree-0 colours.
    assert_eq!(splat_keys(&all), splat_keys(&cloud));
    let _ = std::fs::remove_dir_all(&d);
}

/// Far views of the biker's LOD tree `ts` (leaves in the tileset's frame, `dir` and `up` the
/// same view in it): the coarse selection stays ≥ 30 dB from the whole scene and above uniform
/// decimation to the same count. Its per-distance report.
fn far_views_beat_uniform_decimation(ts: &Tileset, dir: Vec3, up: Vec3) -> Vec<String> {
    let mut cache = TileCache::new(ts, &Default::default());
    let full = leaves(ts, &mut cache);
    // At CesiumJS's 16 px, far views draw the coarse tiles (the default 1 px floor with a
    // budget above the whole scene would draw its leaves).
    let select = SelectOptions {
        max_screen_error: 16.0,
        ..Default::default()
    };
    let mut report = Vec::new();
    for distance in [6.0, 3.0, 2.0, 1.5, 1.2] {
        let cam = common::lod::camera_at(&full, dir, distance, up);
        let sel = splatgl::tiles::select(ts, &cam, &select, &mut |t| cache.splats(t)).unwrap();
        let lod = cache.merged(&sel.tiles);
        assert!(
            lod.len() < full.len() / 2,
            "{} of {}",
            lod.len(),
            full.len()
        );
        let (p_lod, p_uniform) = common::lod::lod_and_uniform_psnr(&full, &lod, &cam);
        report.push(format!(
            "{distance}× radius: {} tiles, {} of {} splats: LOD {p_lod:.1} dB, uniform {p_uniform:.1} dB",
            sel.tiles.len(),
            lod.len(),
            full.len()
        ));
        eprintln!("{}", report.last().unwrap());
        assert!(p_lod >= 30.0, "{report:?}");
        assert!(p_lod > p_uniform + 1.0, "{report:?}");
    }
    report
}

/// The biker as a streamed SOG (`convert … lod-meta.json`, SOG units in the PLY's own frame):
/// it validates, its finest level is the whole scene within SOG's quantization, and far
/// views of it beat uniform decimation as the 3D Tiles tileset's do (the same views: the
/// tileset's (0.3, −1, 0.4) with +Z up is (−0.3, −0.4, 1) with −Y up in the PLY's frame).
#[test]
fn a_built_streamed_sog_validates_and_its_far_views_beat_uniform_decimation() {
    let Some(biker) = common::real("playcanvas_biker.compressed.ply") else {
        return;
    };
    let d = dir("biker-sog");
    let ts = build_as(&biker, &d, "lod-meta.json", &["--chunk-splats", "8192"]);
    let mut cache = TileCache::new(&ts, &Default::default());
    let finest = leaves(&ts, &mut cache);
    let whole = splatgl::load::load_path(&biker, &Default::default())
        .unwrap()
        .cloud;
    assert_eq!(finest.len(), whole.len());
    let cam = common::lod::camera_at(&whole, Vec3::new(-0.3, -0.4, 1.0), 2.0, -Vec3::Y);
    let p = common::lod::psnr(
        &common::lod::render(&finest, &cam),
        &common::lod::render(&whole, &cam),
    );
    assert!(p >= 50.0, "finest level vs the PLY: {p:.1} dB");
    far_views_beat_uniform_decimation(&ts, Vec3::new(-0.3, -0.4, 1.0), -Vec3::Y);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_far_view_of_the_coarse_tiles_beats_uniform_decimation_and_a_close_view_is_finest() {
    let Some(biker) = common::real("playcanvas_biker.compressed.ply") else {
        return;
    };
    let d = dir("biker");
    let ts = build(&biker, &d, &["--chunk-splats", "8192"]);
    far_views_beat_uniform_decimation(&ts, Vec3::new(0.3, -1.0, 0.4), Vec3::Z);
    let mut cache = TileCache::new(&ts, &Default::default());
    let full = leaves(&ts, &mut cache);
    let select = SelectOptions::default();
    // Inside the scene every tile in view refines: the selection is leaves only.
    let b = full.bounds().unwrap();
    let inside = Camera::look_at(
        Vec3::from(b.center()),
        Vec3::from(b.center()) + Vec3::Y,
        Vec3::Z,
        50f32.to_radians(),
        320,
        240,
    );
    let sel = splatgl::tiles::select(&ts, &inside, &select, &mut |t| cache.splats(t)).unwrap();
    // Close up, the tiles around the eye are the finest; a coarser tile is drawn only where
    // its error on screen is within the bound (far parts of the scene).
    let around_eye = |t: &splatgl::tiles::Tile| {
        let (c, r) = t.bounds.unwrap().sphere();
        (c - inside.eye().as_dvec3()).length() <= r
    };
    assert!(sel.tiles.iter().any(|t| around_eye(t)));
    for t in &sel.tiles {
        let sse = splatgl::tiles::screen_space_error(t, &inside);
        assert!(
            t.children.is_empty() || (!around_eye(t) && sse <= select.max_screen_error),
            "{} (error {sse} px) is drawn instead of its children",
            t.path
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// The leaves' splats as sortable keys (opacity and DC colour bits).
fn splat_keys(c: &SplatCloud) -> Vec<(u32, u32)> {
    let mut v: Vec<(u32, u32)> = (0..c.len())
        .map(|i| (c.opacities[i].to_bits(), c.sh_of(i)[0][0].to_bits()))
        .collect();
    v.sort_unstable();
    v
}

#[test]
fn a_streamed_build_holds_the_same_splats_as_one_in_memory_and_leaves_no_scratch() {
    let d = dir("streamed");
    let input = d.join("in.ply");
    let cloud = common::random_cloud(5000, 1, 3.0, 12);
    std::fs::write(&input, splatgl::write::to_inria_ply(&cloud)).unwrap();
    let scratch = d.join("scratch");
    let (mem, streamed) = (d.join("mem"), d.join("streamed"));
    std::fs::create_dir_all(&mem).unwrap();
    std::fs::create_dir_all(&streamed).unwrap();
    let ts_mem = build(&input, &mem, &["--chunk-splats", "200"]);
    let s = scratch.to_str().unwrap();
    let ts = build(
        &input,
        &streamed,
        &[
            "--chunk-splats",
            "200",
            "--scratch-dir",
            s,
            "--bucket-splats",
            "600",
        ],
    );
    let v = run(&["validate", streamed.join("tileset.json").to_str().unwrap()]);
    assert!(
        v.out().contains("valid (0 errors, 0 warnings)"),
        "{}",
        v.all()
    );
    let mut cache = TileCache::new(&ts, &Default::default());
    let mut cache_mem = TileCache::new(&ts_mem, &Default::default());
    let (a, b) = (leaves(&ts, &mut cache), leaves(&ts_mem, &mut cache_mem));
    assert_eq!(splat_keys(&a), splat_keys(&b));
    assert_eq!(a.len(), 5000);
    for t in ts.root.walk() {
        assert!(cache.splats(t) <= 200, "{}", t.path);
    }
    // Eight or more buckets of about 600 splats: the tree's top levels came from the planes.
    assert!(ts.root.walk().iter().map(|t| t.level).max().unwrap() >= 5);
    let left: Vec<_> = std::fs::read_dir(&scratch).unwrap().collect();
    assert!(left.is_empty(), "scratch files left: {left:?}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_streamed_build_of_a_file_it_cannot_stream_says_why() {
    let d = dir("unstreamable");
    let out = d.join("tileset.json");
    let scratch = d.join("scratch");
    let truncated = d.join("short.ply");
    let whole = splatgl::write::to_inria_ply(&common::random_cloud(100, 0, 1.0, 1));
    std::fs::write(&truncated, &whole[..whole.len() - 10]).unwrap();
    let mut cases: Vec<(PathBuf, &str)> = vec![(truncated, "vertex")];
    if let Some(p) = common::real("playcanvas_biker.compressed.ply") {
        cases.push((p, "compressed PLY is not read in chunks"));
    }
    if let Some(p) = common::real("jsplat_unitCube-ascii.ply") {
        cases.push((p, "ASCII PLY is not read in chunks"));
    }
    for (input, why) in &cases {
        let r = run(&[
            "convert",
            input.to_str().unwrap(),
            out.to_str().unwrap(),
            "--scratch-dir",
            scratch.to_str().unwrap(),
        ]);
        assert_eq!(r.code, 2, "{}", r.all());
        assert!(r.stderr.contains(why), "{why}: {}", r.all());
        assert!(!out.exists());
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_small_cache_evicts_yet_every_frame_draws_the_same_splats_whatever_the_load_order() {
    let d = dir("cache");
    let input = d.join("in.glb");
    let cloud = common::random_cloud(4000, 1, 4.0, 13);
    std::fs::write(&input, splatgl::write::to_glb(&cloud, &Default::default())).unwrap();
    let ts = build(&input, &d, &["--chunk-splats", "128"]);
    let opts = SelectOptions {
        max_screen_error: 1.0,
        ..Default::default()
    };
    // A flight from one side of the scene to the other, close enough to refine.
    let cams: Vec<Camera> = (0..12)
        .map(|i| {
            let x = -4.0 + 8.0 * i as f32 / 11.0;
            Camera::look_at(
                Vec3::new(x, -2.0, 1.0),
                Vec3::new(x, 2.0, 0.0),
                Vec3::Z,
                0.9,
                160,
                120,
            )
        })
        .collect();
    let frames = |cache: &mut TileCache| -> Vec<SplatCloud> {
        cams.iter()
            .map(|cam| {
                cache.next_frame();
                let sel =
                    splatgl::tiles::select(&ts, cam, &opts, &mut |t| cache.splats(t)).unwrap();
                cache.merged(&sel.tiles)
            })
            .collect()
    };
    let mut unlimited = TileCache::new(&ts, &Default::default());
    let want = frames(&mut unlimited);
    assert_eq!(unlimited.evictions, 0);
    // Tiles loaded in another order first: every tile, finest first.
    let mut reversed = TileCache::new(&ts, &Default::default());
    for t in ts.root.walk().into_iter().rev() {
        reversed.splats(t);
    }
    assert!(
        frames(&mut reversed) == want,
        "another load order drew other splats"
    );
    // A cap of a quarter of what the flight touches: tiles are evicted and loaded again.
    let cap = unlimited.resident_bytes() / 4;
    let mut small = TileCache::with_max_bytes(&ts, &Default::default(), cap);
    for (cam, want) in cams.iter().zip(&want) {
        small.next_frame();
        // The tiles this frame touches (selection counts the children it weighs).
        let mut touched = std::collections::HashMap::new();
        let sel = splatgl::tiles::select(&ts, cam, &opts, &mut |t| {
            let n = small.splats(t);
            touched.insert(t.path.clone(), n);
            n
        })
        .unwrap();
        // 44 bytes a splat and SH degree 1's 4 RGB coefficients.
        let frame_bytes: u64 = touched.values().map(|n| n * (44 + 4 * 12)).sum();
        assert!(
            small.merged(&sel.tiles) == *want,
            "an evicting cache drew other splats"
        );
        // Over the cap only by what this frame itself needs.
        assert!(
            small.resident_bytes() <= cap + frame_bytes,
            "{} resident, cap {cap}, frame {frame_bytes}, {} tiles touched",
            small.resident_bytes(),
            touched.len()
        );
    }
    assert!(
        small.evictions > 0,
        "nothing was evicted under a {cap}-byte cap"
    );
    assert!(
        small.loads > unlimited.loads,
        "{} vs {}",
        small.loads,
        unlimited.loads
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A streamed SOG output is built in memory and holds SOG units: the options it cannot honour
/// are errors that say so, before anything is written.
#[test]
fn a_streamed_sog_output_refuses_what_it_cannot_write() {
    let d = dir("sog-refusals");
    let input = d.join("in.ply");
    std::fs::write(
        &input,
        splatgl::write::to_inria_ply(&common::random_cloud(100, 0, 1.0, 3)),
    )
    .unwrap();
    let out = d.join("lod-meta.json");
    let (i, o) = (input.to_str().unwrap(), out.to_str().unwrap());
    let scratch = d.join("scratch");
    for (extra, says) in [
        (
            vec!["--scratch-dir", scratch.to_str().unwrap()],
            "built in memory",
        ),
        (
            vec!["--spz-compress"],
            "--spz-compress applies to .glb outputs only",
        ),
        (vec!["--quantize", "scale=u8n"], "--quantize applies to"),
    ] {
        let mut args = vec!["convert", i, o];
        args.extend(extra);
        let r = run(&args);
        assert_eq!(r.code, 2, "{}", r.all());
        assert!(r.stderr.contains(says), "{}", r.all());
        assert!(!out.exists());
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// `render`'s views of a tileset upload a selection once while it stays the same: an orbit at
/// a far distance keeps the root tile, the later views say they draw what is on the GPU
/// already, and each of their images is the one a render of that view alone makes (GL; within
/// 1/255, the rounding of the camera through cameras.json).
#[test]
fn a_batch_whose_views_keep_their_selection_draws_it_without_uploading_again() {
    let Some(biker) = common::real("playcanvas_biker.compressed.ply") else {
        return;
    };
    if let Err(e) = splatgl::headless::HeadlessContext::new() {
        common::skip(&format!("the GL part: {e}"));
        return;
    }
    let d = dir("orbit-upload");
    build(&biker, &d, &["--chunk-splats", "8192"]);
    let ts = d.join("tileset.json");
    let ts = ts.to_str().unwrap();
    let pattern = d.join("o_{index}.png");
    // At 16 px the orbit's far views keep one selection (at the default 1 px each refines).
    let common_args = [
        "--backend",
        "gl",
        "--width",
        "96",
        "--height",
        "72",
        "--max-screen-error",
        "16",
    ];
    let mut args = vec![
        "render",
        ts,
        "--orbit",
        "3",
        "-v",
        "--print-camera-json",
        "-o",
    ];
    args.push(pattern.to_str().unwrap());
    args.extend(common_args);
    let r = run(&args);
    assert_eq!(r.code, 0, "{}", r.all());
    assert_eq!(
        r.stderr.matches("(not uploaded again)").count(),
        2,
        "{}",
        r.stderr
    );
    let cams = d.join("cameras.json");
    std::fs::write(&cams, r.out()).unwrap();
    let read = |p: &Path| splatgl::image::Image::read(p).unwrap();
    for i in 0..3 {
        let one = d.join(format!("one_{i}.png"));
        let view = i.to_string();
        let mut args = vec![
            "render",
            ts,
            "--camera",
            cams.to_str().unwrap(),
            "--view",
            &view,
        ];
        args.extend(["-o", one.to_str().unwrap()]);
        args.extend(common_args);
        let r = run(&args);
        assert_eq!(r.code, 0, "{}", r.all());
        // cameras.json's rounding of the orbit's camera moves a pixel by 1/255 at most.
        let c = splatgl::compare::compare(
            &read(&one),
            &read(&d.join(format!("o_{i}.png"))),
            1.0 / 255.0,
        )
        .unwrap();
        assert!(
            c.max_abs <= 1.5 / 255.0,
            "view {i}: max error {}",
            c.max_abs
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// The selection spends its budget and never passes it: for budgets from the root's size to
/// more than the whole tileset and cameras from far to inside it, with the default options,
/// the selection is never empty, holds at most the budget, and every tile left unrefined
/// is a leaf, out of view, at or under the error floor, or one whose refinement would pass
/// the budget (nothing is left unspent that a refinement could have used).
#[test]
fn the_selection_fills_its_budget_and_never_passes_it() {
    use splatgl::tiles::{Refine, screen_space_error, visible};
    let d = dir("budget");
    let input = d.join("in.glb");
    let cloud = common::random_cloud(6000, 0, 4.0, 5);
    std::fs::write(&input, splatgl::write::to_glb(&cloud, &Default::default())).unwrap();
    let ts = build(&input, &d, &["--chunk-splats", "200"]);
    let mut cache = TileCache::new(&ts, &Default::default());
    let root = cache.splats(&ts.root);
    let cams = [
        Vec3::new(0.0, -60.0, 20.0),
        Vec3::new(0.0, -9.0, 3.0),
        Vec3::new(0.5, 0.2, 0.1),
    ]
    .map(|eye| Camera::look_at(eye, Vec3::ZERO, Vec3::Z, 0.9, 320, 240));
    let mut filled = 0;
    for budget in [root, root + 150, 800, 2500, 7000, 100_000] {
        let o = SelectOptions {
            splat_budget: budget,
            ..Default::default()
        };
        for cam in &cams {
            let sel = splatgl::tiles::select(&ts, cam, &o, &mut |t| cache.splats(t)).unwrap();
            assert!(!sel.tiles.is_empty(), "budget {budget}: nothing selected");
            let drawn: u64 = sel.tiles.iter().map(|t| cache.splats(t)).sum();
            assert_eq!(drawn, sel.splats);
            assert!(drawn <= budget, "{drawn} splats over the budget {budget}");
            for t in &sel.tiles {
                let kids: Vec<_> = t.children.iter().filter(|c| visible(c, cam)).collect();
                let floor = screen_space_error(t, cam) <= o.max_screen_error;
                if kids.is_empty() || floor || !visible(t, cam) {
                    continue;
                }
                let cost: u64 = kids.iter().map(|c| cache.splats(c)).sum();
                let freed = if t.refine == Refine::Replace {
                    cache.splats(t)
                } else {
                    0
                };
                assert!(
                    drawn - freed + cost > budget,
                    "budget {budget}: {} left unrefined with {} splats to spare",
                    t.path,
                    budget - drawn
                );
            }
            filled += usize::from(sel.held_back > 0);
        }
    }
    // Small budgets are what end the refinement, not the error floor.
    assert!(
        filled >= 6,
        "only {filled} selections were held back by their budget"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `convert … tileset.json -v` prints the matrix from the input's coordinates to the
/// tileset's, and `info` names the tileset's frame and root transform: a camera carried over
/// by that matrix sees in the tileset (every leaf drawn: a budget above the scene) what the
/// same camera sees in the PLY.
#[test]
fn convert_prints_the_transform_that_carries_a_camera_into_the_tileset() {
    let d = dir("carry");
    let input = d.join("in.ply");
    let cloud = common::random_cloud(1500, 0, 1.0, 21);
    std::fs::write(&input, splatgl::write::to_inria_ply(&cloud)).unwrap();
    let out = d.join("tileset.json");
    let r = run(&[
        "convert",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "--chunk-splats",
        "256",
        "-v",
    ]);
    assert_eq!(r.code, 0, "{}", r.all());
    let line = r
        .stderr
        .lines()
        .find(|l| l.starts_with("transform: input → tileset (z-up) ["))
        .unwrap_or_else(|| panic!("no transform line: {}", r.all()));
    let rows: Vec<Vec<f64>> = line
        .split('[')
        .nth(1)
        .unwrap()
        .split(']')
        .next()
        .unwrap()
        .split(';')
        .map(|row| row.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    let m = |v: [f64; 3], w: f64| -> String {
        (0..3)
            .map(|i| {
                format!(
                    "{}",
                    (0..3).map(|k| rows[i][k] * v[k]).sum::<f64>() + rows[i][3] * w
                )
            })
            .collect::<Vec<_>>()
            .join(",")
    };
    let info = run(&["info", out.to_str().unwrap()]);
    assert!(
        info.out().contains("frame:          z-up"),
        "{}",
        info.all()
    );
    assert!(
        info.out().contains("root transform: identity"),
        "{}",
        info.all()
    );
    let (e, t, u) = ([0.3, -0.4, -3.0], [0.0, 0.0, 0.0], [0.0, -1.0, 0.0]);
    let text = |v: [f64; 3]| v.map(|x| x.to_string()).join(",");
    let look = format!("{},{},{}", text(e), text(t), text(u));
    let carried = format!("{},{},{}", m(e, 1.0), m(t, 1.0), m(u, 0.0));
    let (a, b) = (d.join("ply.png"), d.join("tiles.png"));
    let size = [
        "--width",
        "160",
        "--height",
        "120",
        "--backend",
        "reference",
    ];
    let mut args = vec!["render", input.to_str().unwrap(), "--look-at", &look, "-o"];
    args.push(a.to_str().unwrap());
    args.extend(size);
    assert_eq!(run(&args).code, 0);
    let mut args = vec!["render", out.to_str().unwrap(), "--look-at", &carried, "-o"];
    args.push(b.to_str().unwrap());
    args.extend(size);
    args.extend(["--splat-budget", "100000"]);
    let r = run(&args);
    assert_eq!(r.code, 0, "{}", r.all());
    let (ia, ib) = (
        splatgl::image::Image::read(&a).unwrap(),
        splatgl::image::Image::read(&b).unwrap(),
    );
    let lit = ia
        .pixels
        .iter()
        .filter(|p| p[0] + p[1] + p[2] > 0.1)
        .count();
    assert!(
        lit > ia.pixels.len() / 20,
        "the view misses the scene: {lit} pixels lit"
    );
    let p = common::lod::psnr(&ia, &ib);
    assert!(p >= 45.0, "the carried camera sees another view: {p:.1} dB");
    // The uncarried numbers in the tileset: another view.
    let mut args = vec!["render", out.to_str().unwrap(), "--look-at", &look, "-o"];
    args.push(b.to_str().unwrap());
    args.extend(size);
    args.extend(["--splat-budget", "100000", "-f"]);
    assert_eq!(run(&args).code, 0);
    let other = splatgl::image::Image::read(&b).unwrap();
    assert!(common::lod::psnr(&ia, &other) < 30.0);
    let _ = std::fs::remove_dir_all(&d);
}

/// Every file under `d`, by relative path, with its bytes.
fn tree_bytes(d: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![d.to_path_buf()];
    while let Some(p) = stack.pop() {
        for e in std::fs::read_dir(&p).unwrap() {
            let e = e.unwrap().path();
            if e.is_dir() {
                stack.push(e);
            } else {
                let rel = e.strip_prefix(d).unwrap().to_string_lossy().into_owned();
                out.insert(rel, std::fs::read(&e).unwrap());
            }
        }
    }
    out
}

#[test]
fn the_build_in_steps_writes_the_streamed_builds_tileset_byte_for_byte_even_run_twice() {
    use splatgl::tiles::{StreamOptions, steps};
    let d = dir("steps");
    let input = d.join("in.ply");
    let cloud = common::random_cloud(5000, 1, 3.0, 21);
    std::fs::write(&input, splatgl::write::to_inria_ply(&cloud)).unwrap();
    let (one, many) = (d.join("one"), d.join("many"));
    std::fs::create_dir_all(&one).unwrap();
    let scratch = d.join("scratch");
    let s = scratch.to_str().unwrap();
    let args = [
        "--chunk-splats",
        "200",
        "--scratch-dir",
        s,
        "--bucket-splats",
        "600",
    ];
    build(&input, &one, &args);
    let o = StreamOptions {
        chunk_splats: 200,
        bucket_splats: 600,
        scratch_dir: d.join("shared"),
    };
    let plan = steps::plan(&input, &many.join("tileset.json"), &o, 3, &|_, _, _| {}).unwrap();
    assert_eq!(
        steps::BuildPlan::read(&o.scratch_dir.join("plan.json")).unwrap(),
        plan
    );
    assert!(plan.buckets >= 8 && plan.ranges.len() == 3);
    // Out of order, and each step twice (a task retried after its worker died).
    for r in (0..3).rev().chain(0..3) {
        steps::route_range(&plan, r).unwrap();
    }
    let mut reports: Vec<_> = (0..plan.buckets)
        .rev()
        .map(|b| steps::build_bucket(&plan, b).unwrap())
        .collect();
    assert_eq!(
        steps::build_bucket(&plan, 0).unwrap(),
        reports[plan.buckets - 1]
    );
    reports.reverse();
    let joined = steps::join(&plan, &reports).unwrap();
    assert_eq!(joined.splats, 5000);
    assert_eq!(tree_bytes(&one), tree_bytes(&many));
    let left: Vec<_> = std::fs::read_dir(&o.scratch_dir).unwrap().collect();
    assert!(left.is_empty(), "scratch files left: {left:?}");
    assert!(steps::build_bucket(&plan, plan.buckets).is_err());
    let _ = std::fs::remove_dir_all(&d);
}
