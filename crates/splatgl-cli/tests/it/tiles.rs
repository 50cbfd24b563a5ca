//! 3D Tiles tilesets (`splatgl::tiles`): `info` counts tiles and splats per level, `validate`
//! names each structural rule a tileset breaks by its JSON path, and hostile tilesets are
//! errors, never crashes. Tilesets are written here, with glTF content from the writer.

use crate::common;
use common::cli::run;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    common::fresh_dir("tiles", name)
}

/// Writes `n` random splats within ±`extent` (glTF, y-up) as `dir/name`.
fn content(dir: &Path, name: &str, n: usize, extent: f32, seed: u64) {
    let cloud = splatgl::synthetic::random_cloud(n, 0, extent, seed);
    let glb = splatgl::write::to_glb(&cloud, &Default::default());
    std::fs::write(dir.join(name), glb).unwrap();
}

/// A `box` bounding volume: centre and three half axes along x, y, z.
fn bx(c: [f64; 3], h: [f64; 3]) -> Value {
    json!({ "box": [c[0], c[1], c[2], h[0], 0, 0, 0, h[1], 0, 0, 0, h[2]] })
}

/// Writes `tileset.json` with `root` into `dir`; returns its path.
fn tileset(dir: &Path, root: Value) -> PathBuf {
    let p = dir.join("tileset.json");
    let doc = json!({ "asset": { "version": "1.1" }, "geometricError": 100.0, "root": root });
    std::fs::write(&p, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
    p
}

/// A root with coarse content over two finer children that split it along x.
fn two_level(d: &Path) -> PathBuf {
    content(d, "root.glb", 50, 1.0, 1);
    content(d, "a.glb", 100, 0.4, 2);
    content(d, "b.glb", 200, 0.4, 3);
    tileset(
        d,
        json!({
            "geometricError": 10.0, "refine": "REPLACE",
            "boundingVolume": bx([0.0, 0.0, 0.0], [2.0, 2.0, 2.0]),
            "content": { "uri": "root.glb" },
            "children": [
                { "geometricError": 1.0, "boundingVolume": bx([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
                  "content": { "uri": "a.glb" } },
                { "geometricError": 1.0, "boundingVolume": { "sphere": [0.0, 0.0, 0.0, 1.5] },
                  "contents": [{ "uri": "b.glb" }] },
            ],
        }),
    )
}

fn json_of(args: &[&str]) -> (i32, Value) {
    let r = run(args);
    let v = serde_json::from_str(&r.out()).unwrap_or_else(|e| panic!("{e}: {}", r.all()));
    (r.code, v)
}

#[test]
fn info_counts_tiles_and_splats_per_level() {
    let d = dir("info");
    let ts = two_level(&d);
    let (code, v) = json_of(&["info", ts.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{v:#}");
    assert_eq!(v["format"], "3dtiles");
    assert_eq!(v["version"], "1.1");
    assert_eq!(v["tiles"], 3);
    assert_eq!(v["splat_count"], 350);
    assert_eq!(v["levels"][0]["splats"], 50);
    assert_eq!(v["levels"][1]["splats"], 300);
    assert_eq!(v["levels"][1]["contents"], 2);
    assert_eq!(v["levels"][0]["geometric_error"], 10.0);
    // The root box's corner sphere: √12.
    let r = v["bounds_radius"].as_f64().unwrap();
    assert!((r - 12f64.sqrt()).abs() < 1e-9, "{r}");
    assert_eq!(v["problems"].as_array().unwrap().len(), 0, "{v:#}");
    let text = run(&["info", ts.to_str().unwrap()]);
    assert!(
        text.out().contains("3D Tiles 1.1 tileset"),
        "{}",
        text.all()
    );
    let (code, v) = json_of(&["validate", ts.to_str().unwrap(), "--json"]);
    assert_eq!(
        (code, &v["status"], &v["format"]),
        (0, &json!("valid"), &json!("3dtiles"))
    );
    // Named bare in its own folder, it reads the same content (resolved against `.`).
    let name = ts.file_name().unwrap().to_str().unwrap();
    let r = common::cli::run_in(ts.parent().unwrap(), &["info", name, "--json"]);
    let v: Value = serde_json::from_str(&r.out()).unwrap_or_else(|e| panic!("{e}: {}", r.all()));
    assert_eq!((r.code, &v["splat_count"]), (0, &json!(350)), "{v:#}");
    let _ = std::fs::remove_dir_all(&d);
}

/// The finding at `path` (exactly), if any, as (severity, message).
fn finding(v: &Value, path: &str) -> Option<(String, String)> {
    v["findings"]
        .as_array()?
        .iter()
        .find(|f| f["path"] == path)
        .map(|f| {
            (
                f["severity"].as_str().unwrap().to_owned(),
                f["message"].as_str().unwrap().to_owned(),
            )
        })
}

#[test]
fn validate_names_each_structural_break_by_its_path() {
    let d = dir("rules");
    content(&d, "wide.glb", 40, 3.0, 4);
    content(&d, "ok.glb", 40, 0.2, 5);
    let outside = dir("rules-outside");
    content(&outside, "x.glb", 10, 0.2, 6);
    let escape = format!(
        "../{}/x.glb",
        outside.file_name().unwrap().to_str().unwrap()
    );
    let root = json!({
        "geometricError": 10.0, "refine": "ADD",
        "boundingVolume": bx([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
        "children": [
            // Coarser than its parent.
            { "geometricError": 20.0, "boundingVolume": bx([0.0, 0.0, 0.0], [0.5, 0.5, 0.5]),
              "content": { "uri": "ok.glb" } },
            // Reaches outside its parent's box.
            { "geometricError": 1.0, "boundingVolume": bx([0.9, 0.0, 0.0], [0.5, 0.5, 0.5]) },
            // Content outside the tileset's folder.
            { "geometricError": 1.0, "boundingVolume": bx([0.0, 0.0, 0.0], [0.5, 0.5, 0.5]),
              "content": { "uri": escape } },
            // Missing content.
            { "geometricError": 1.0, "boundingVolume": bx([0.0, 0.0, 0.0], [0.5, 0.5, 0.5]),
              "content": { "uri": "missing.glb" } },
            // A region splatgl does not read, and an unknown refine.
            { "geometricError": 1.0, "refine": "SIDEWAYS",
              "boundingVolume": { "region": [0.0, 0.0, 0.1, 0.1, 0.0, 10.0] } },
            // Splats beyond the tile's volume.
            { "geometricError": 1.0, "boundingVolume": bx([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
              "content": { "uri": "wide.glb" } },
        ],
    });
    let ts = tileset(&d, root);
    let (code, v) = json_of(&["validate", ts.to_str().unwrap(), "--json"]);
    assert_eq!(code, 1, "{v:#}");
    let at = |p: &str| finding(&v, p).unwrap_or_else(|| panic!("nothing at {p}: {v:#}"));
    let (s, m) = at("root.children[0].geometricError");
    assert!(
        s == "warning" && m.contains("larger than its parent"),
        "{m}"
    );
    let (s, m) = at("root.children[1].boundingVolume");
    assert!(s == "warning" && m.contains("outside its parent"), "{m}");
    let (s, m) = at("root.children[2].content");
    assert!(
        s == "error" && m.contains("outside the asset's folder"),
        "{m}"
    );
    let (s, m) = at("root.children[3].content");
    assert!(s == "error" && m.contains("missing.glb"), "{m}");
    let (s, m) = at("root.children[4].boundingVolume");
    assert!(s == "unsupported" && m.contains("region"), "{m}");
    let (s, m) = at("root.children[4].refine");
    assert!(s == "error" && m.contains("SIDEWAYS"), "{m}");
    let (s, m) = at("root.children[5].content");
    assert!(
        s == "warning" && m.contains("outside the tile's bounding volume"),
        "{m}"
    );
    // The tiles that break nothing have no finding.
    assert!(finding(&v, "root.children[0].content").is_none(), "{v:#}");
    assert!(finding(&v, "root").is_none(), "{v:#}");
    for p in [&d, &outside] {
        let _ = std::fs::remove_dir_all(p);
    }
}

#[test]
fn hostile_tilesets_are_errors_not_crashes() {
    let d = dir("hostile");
    // No root tile object, no version, and a tree nested past the JSON depth limit.
    let cases: Vec<(&str, String)> = vec![
        ("no_version.json", r#"{"asset": {}, "root": {}}"#.into()),
        (
            "root_not_object.json",
            r#"{"asset": {"version": "1.1"}, "root": 7}"#.into(),
        ),
        (
            "deep.json",
            format!(
                r#"{{"asset": {{"version": "1.1"}}, "root": {}0{}}}"#,
                r#"{"geometricError": 1, "children": ["#.repeat(100),
                "]}".repeat(100)
            ),
        ),
    ];
    for (name, text) in &cases {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        for cmd in ["info", "validate"] {
            let r = run(&[cmd, p.to_str().unwrap()]);
            assert_eq!(r.code, 2, "{cmd} {name}: {}", r.all());
            // Read as a tileset, and the error says what is wrong with it.
            let why = ["asset.version", "root: not a tile object", "max_json_depth"];
            assert!(
                why.iter().any(|w| r.all().contains(w)),
                "{cmd} {name}: {}",
                r.all()
            );
            assert!(!r.stderr.contains("panicked"), "{}", r.all());
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// Undoes 3D Tiles' y-up → z-up turn of glTF content, so the tileset's frame is the glTF
/// frame and a tileset renders like its content loaded directly.
const Z_UP_TO_Y_UP: [f64; 16] = [
    1.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
];

/// A REPLACE tileset: a coarse root of 10 splats over two children that split a 400-splat
/// cloud in half along x; also the whole cloud as `whole.glb`.
fn lod(d: &Path, child_b: &str) -> PathBuf {
    let whole = splatgl::synthetic::random_cloud(400, 1, 1.0, 7);
    let half = |left: bool| -> Vec<u32> {
        (0..whole.len() as u32)
            .filter(|&i| (whole.positions[i as usize][0] < 0.0) == left)
            .collect()
    };
    let write = |name: &str, c: &splatgl::SplatCloud| {
        std::fs::write(d.join(name), splatgl::write::to_glb(c, &Default::default())).unwrap()
    };
    write("whole.glb", &whole);
    write("a.glb", &whole.select(&half(true)));
    write("b.glb", &whole.select(&half(false)));
    content(d, "coarse.glb", 10, 1.0, 8);
    let h = [2.0, 2.0, 2.0];
    tileset(
        d,
        json!({
            "geometricError": 1.0, "refine": "REPLACE", "transform": Z_UP_TO_Y_UP,
            "boundingVolume": bx([0.0, 0.0, 0.0], h), "content": { "uri": "coarse.glb" },
            "children": [
                { "geometricError": 0.0, "boundingVolume": bx([0.0, 0.0, 0.0], h),
                  "content": { "uri": "a.glb" } },
                { "geometricError": 0.0, "boundingVolume": bx([0.0, 0.0, 0.0], h),
                  "content": { "uri": child_b } },
            ],
        }),
    )
}

/// `render SCENE` from `eye` towards the origin with the reference backend into `out`.
fn render(scene: &Path, eye: &str, out: &Path, extra: &[&str]) -> common::cli::Run {
    let look = format!("{eye},0,0,0");
    common::cli::render_small(scene.to_str().unwrap(), &look, out, extra)
}

#[test]
fn a_near_view_refines_to_the_children_and_matches_the_whole_cloud() {
    let d = dir("near");
    let ts = lod(&d, "b.glb");
    let r = render(&ts, "0,1,4", &d.join("tiles.png"), &[]);
    assert_eq!(r.code, 0, "{}", r.all());
    assert!(
        r.stderr.contains("tiles: 2 selected, 400 splats"),
        "{}",
        r.all()
    );
    let r = render(&d.join("whole.glb"), "0,1,4", &d.join("whole.png"), &[]);
    assert_eq!(r.code, 0, "{}", r.all());
    let read = |n: &str| splatgl::image::Image::read(d.join(n)).unwrap();
    let c = splatgl::compare::compare(&read("tiles.png"), &read("whole.png"), 1.0 / 255.0).unwrap();
    assert!(c.psnr >= 50.0, "{} dB", c.psnr);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn max_wait_draws_what_has_loaded_and_a_long_wait_the_whole_selection() {
    let d = dir("wait");
    let ts = lod(&d, "b.glb");
    let read = |n: &str| splatgl::image::Image::read(d.join(n)).unwrap();
    // No time to load the children: the coarse tile is drawn, and the warning says so.
    let r = render(&ts, "0,1,4", &d.join("w0.png"), &["--max-wait", "0"]);
    assert_eq!(r.code, 0, "{}", r.all());
    assert!(
        r.stderr.contains("tiles: 1 selected, 10 splats"),
        "{}",
        r.all()
    );
    assert!(
        r.stderr
            .contains("--max-wait 0: 2 tiles of this view's selection had not loaded"),
        "{}",
        r.all()
    );
    let r = render(
        &ts,
        "0,1,4",
        &d.join("coarse.png"),
        &["--max-screen-error", "1e9"],
    );
    assert_eq!(r.code, 0, "{}", r.all());
    assert_eq!(read("w0.png").pixels, read("coarse.png").pixels);
    // Time enough: the same image as waiting for everything, without a warning.
    let r = render(&ts, "0,1,4", &d.join("w60.png"), &["--max-wait", "60"]);
    assert_eq!(r.code, 0, "{}", r.all());
    assert!(!r.stderr.contains("--max-wait"), "{}", r.all());
    let r = render(&ts, "0,1,4", &d.join("all.png"), &[]);
    assert_eq!(r.code, 0, "{}", r.all());
    assert_eq!(read("w60.png").pixels, read("all.png").pixels);
    // Not a number of seconds: refused by the parser.
    let r = render(&ts, "0,1,4", &d.join("x.png"), &["--max-wait", "-1"]);
    assert_eq!(r.code, 2, "{}", r.all());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_far_view_under_the_floor_or_a_small_budget_keeps_the_coarse_tile() {
    let d = dir("far");
    let ts = lod(&d, "b.glb");
    let out = d.join("x.png");
    // Far, with CesiumJS's 16 px as the floor: the root is fine enough.
    let r = render(&ts, "0,5,40", &out, &["--max-screen-error", "16"]);
    assert_eq!(r.code, 0, "{}", r.all());
    assert!(
        r.stderr.contains("tiles: 1 selected, 10 splats"),
        "{}",
        r.all()
    );
    // Near, but the two children (400 splats) do not fit in 300.
    let r = render(&ts, "0,1,4", &out, &["--splat-budget", "300"]);
    assert_eq!(r.code, 0, "{}", r.all());
    assert!(
        r.stderr
            .contains("tiles: 1 selected, 10 splats (budget 300), 1 held back"),
        "{}",
        r.all()
    );
    // Not even the root fits: a clear error.
    let r = render(&ts, "0,1,4", &out, &["--splat-budget", "5"]);
    assert_eq!(r.code, 2, "{}", r.all());
    assert!(
        r.stderr.contains("root tile alone holds 10 splats"),
        "{}",
        r.all()
    );
    // The option means nothing for a single file.
    let r = render(
        &d.join("whole.glb"),
        "0,1,4",
        &out,
        &["--splat-budget", "5"],
    );
    assert_eq!(r.code, 2, "{}", r.all());
    assert!(
        r.stderr
            .contains("--splat-budget applies to 3D Tiles tilesets only"),
        "{}",
        r.all()
    );
    let r = render(&d.join("whole.glb"), "0,1,4", &out, &["--cache-mb", "5"]);
    assert_eq!(r.code, 2, "{}", r.all());
    assert!(
        r.stderr
            .contains("--cache-mb applies to 3D Tiles tilesets only"),
        "{}",
        r.all()
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_missing_tile_is_skipped_with_a_warning_while_the_rest_draws() {
    let d = dir("missing");
    let ts = lod(&d, "gone.glb");
    let r = render(&ts, "0,1,4", &d.join("x.png"), &[]);
    assert_eq!(r.code, 0, "{}", r.all());
    assert!(
        r.stderr.contains("root.children[1]: \"gone.glb\" skipped"),
        "{}",
        r.all()
    );
    let left = splatgl::load::load_path(d.join("a.glb"), &Default::default())
        .unwrap()
        .cloud
        .len();
    let line = format!("tiles: 2 selected, {left} splats");
    assert!(r.stderr.contains(&line), "{line}: {}", r.all());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn required_extensions_splatgl_cannot_honour_are_unsupported_at_their_path() {
    let d = dir("required");
    content(&d, "a.glb", 10, 0.5, 9);
    let p = d.join("tileset.json");
    let doc = json!({
        "asset": { "version": "1.1" }, "geometricError": 10.0,
        "extensionsUsed": ["3DTILES_content_gltf", "VENDOR_tiles_magic"],
        "extensionsRequired": ["3DTILES_content_gltf", "VENDOR_tiles_magic"],
        "extensions": { "3DTILES_content_gltf": {
            "extensionsUsed": ["KHR_gaussian_splatting", "EXT_meshopt_compression"],
            "extensionsRequired": ["KHR_gaussian_splatting", "EXT_meshopt_compression"],
        } },
        "root": { "geometricError": 0.0, "refine": "ADD",
                  "boundingVolume": bx([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
                  "content": { "uri": "a.glb" } },
    });
    std::fs::write(&p, serde_json::to_vec(&doc).unwrap()).unwrap();
    let (code, v) = json_of(&["validate", p.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "unsupported is not invalid: {v:#}");
    let (s, m) = finding(&v, "extensionsRequired[1]").unwrap_or_else(|| panic!("{v:#}"));
    assert!(
        s == "unsupported" && m.contains("VENDOR_tiles_magic"),
        "{m}"
    );
    let at = "extensions.3DTILES_content_gltf.extensionsRequired[1]";
    let (s, m) = finding(&v, at).unwrap_or_else(|| panic!("{v:#}"));
    assert!(
        s == "unsupported" && m.contains("EXT_meshopt_compression"),
        "{m}"
    );
    // The extensions splatgl reads are no finding.
    assert!(finding(&v, "extensionsRequired[0]").is_none(), "{v:#}");
    let at0 = "extensions.3DTILES_content_gltf.extensionsRequired[0]";
    assert!(finding(&v, at0).is_none(), "{v:#}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn automatic_framing_takes_the_tilesets_up_axis_from_its_root_transform() {
    use splatgl::camera::UpAxis;
    let d = dir("up");
    let opts = splatgl::load::LoadOptions::default();
    // 3D Tiles are z-up; a root transform that turns the tileset y-up makes it y-up.
    let up = |root: Value| {
        splatgl::tiles::read(&tileset(&d, root), &opts)
            .unwrap()
            .up()
    };
    content(&d, "c.glb", 10, 1.0, 3);
    let plain = json!({ "geometricError": 0.0, "boundingVolume": bx([0.0; 3], [2.0; 3]),
                        "content": { "uri": "c.glb" } });
    assert_eq!(up(plain.clone()), Some(UpAxis::Z));
    let mut turned = plain;
    turned["transform"] = json!(Z_UP_TO_Y_UP);
    assert_eq!(up(turned), Some(UpAxis::Y));
    let _ = std::fs::remove_dir_all(&d);
}
