//! 3D Tiles tilesets (`splatgl::tiles`): `info` counts tiles and splats per level, `validate`
//! names each structural rule a tileset breaks by its JSON path, and hostile tilesets are
//! errors, never crashes. Tilesets are written here, with glTF content from the writer.
#![cfg(feature = "cli")]

mod common;
use common::cli::run;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// A fresh folder for one test.
fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-tiles-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
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
