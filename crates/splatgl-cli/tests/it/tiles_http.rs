//! Tilesets over HTTP (`splatgl::files::http`): a tileset served by a local server started
//! here reads, validates and renders as it does from its folder; content that is missing,
//! truncated or outside the tileset's folder on the server is a finding or a skipped tile,
//! never a fetch outside what the user pointed at.

use crate::common;
use common::cli::run;
use common::http::serve;
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    common::fresh_dir("http", name)
}

/// Builds a tileset of `n` random splats into `d/ts/`.
fn built(d: &Path, n: usize) -> PathBuf {
    let input = d.join("in.glb");
    let cloud = common::random_cloud(n, 1, 1.0, 21);
    std::fs::write(&input, splatgl::write::to_glb(&cloud, &Default::default())).unwrap();
    let ts = d.join("ts").join("tileset.json");
    let r = run(&[
        "convert",
        input.to_str().unwrap(),
        ts.to_str().unwrap(),
        "--chunk-splats",
        "100",
    ]);
    assert_eq!(r.code, 0, "{}", r.all());
    ts
}

fn render(scene: &str, out: &Path) -> common::cli::Run {
    common::cli::render_small(scene, "0,-3,1,0,0,0,0,0,1", out, &[])
}

#[test]
fn a_served_tileset_reads_and_renders_as_its_folder_does() {
    let d = dir("served");
    let ts = built(&d, 800);
    let (base, log) = serve(&d);
    let url = format!("{base}/ts/tileset.json");
    let info = |scene: &str| {
        let r = run(&["info", scene, "--json"]);
        assert_eq!(r.code, 0, "{}", r.all());
        let mut v: serde_json::Value = serde_json::from_str(&r.out()).unwrap();
        v["file"] = serde_json::Value::Null;
        v
    };
    assert_eq!(info(&url), info(ts.to_str().unwrap()));
    let v = run(&["validate", &url]);
    assert!(
        v.out().contains("valid (0 errors, 0 warnings)"),
        "{}",
        v.all()
    );
    let (web, local) = (d.join("web.png"), d.join("local.png"));
    let r = render(&url, &web);
    assert_eq!(r.code, 0, "{}", r.all());
    let r = render(ts.to_str().unwrap(), &local);
    assert_eq!(r.code, 0, "{}", r.all());
    assert_eq!(std::fs::read(&web).unwrap(), std::fs::read(&local).unwrap());
    // Only the tileset's own files were asked for.
    let seen = log.lock().unwrap().clone();
    assert!(seen.iter().all(|p| p.starts_with("/ts/")), "{seen:?}");
    assert!(seen.iter().any(|p| p.starts_with("/ts/tiles/")), "{seen:?}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn missing_truncated_or_escaping_content_on_a_server_is_named_and_the_rest_draws() {
    let d = dir("hostile");
    let ts = built(&d, 800);
    let mut doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&ts).unwrap()).unwrap();
    let tiles = ts.parent().unwrap().join("tiles");
    // The root's children: one truncated, one moved outside the tileset's folder; a grandchild
    // points at a file that is not there.
    let glb = std::fs::read(tiles.join("r0.glb")).unwrap();
    std::fs::write(tiles.join("r0.glb"), &glb[..glb.len() / 2]).unwrap();
    std::fs::rename(tiles.join("r1.glb"), d.join("r1.glb")).unwrap();
    doc["root"]["children"][1]["content"]["uri"] = "../r1.glb".into();
    doc["root"]["children"][1]["children"][0]["content"]["uri"] = "tiles/gone.glb".into();
    std::fs::write(&ts, serde_json::to_vec(&doc).unwrap()).unwrap();
    let (base, log) = serve(&d);
    let url = format!("{base}/ts/tileset.json");
    let r = run(&["validate", &url, "--json"]);
    assert_eq!(r.code, 1, "{}", r.all());
    let v: serde_json::Value = serde_json::from_str(&r.out()).unwrap();
    let at = |path: &str| -> String {
        v["findings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["path"] == path)
            .map(|f| f["message"].as_str().unwrap().to_owned())
            .unwrap_or_else(|| panic!("nothing at {path}: {v:#}"))
    };
    assert!(at("root.children[0].content").contains("does not load"));
    assert!(at("root.children[1].content").contains("outside the asset's folder"));
    assert!(at("root.children[1].children[0].content").contains("404"));
    // The escaping URI was never requested.
    let seen = log.lock().unwrap().clone();
    assert!(!seen.iter().any(|p| p.contains("r1.glb")), "{seen:?}");
    // Close up the broken tiles are skipped with a warning and the root and the rest draw.
    let r = render(&url, &d.join("x.png"));
    assert_eq!(r.code, 0, "{}", r.all());
    assert!(r.stderr.contains("skipped"), "{}", r.all());
    assert!(!r.stderr.contains("panicked"), "{}", r.all());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn percent_encoded_dots_in_served_uris_request_nothing_outside_the_folder() {
    let d = dir("encoded");
    let ts = built(&d, 400);
    let tiles = ts.parent().unwrap().join("tiles");
    // A loadable file outside the tileset's folder, which a decoding server would serve.
    std::fs::copy(tiles.join("r1.glb"), d.join("secret.glb")).unwrap();
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&ts).unwrap()).unwrap();
    let (base, log) = serve(&d);
    let url = format!("{base}/ts/tileset.json");
    for uri in [
        "%2e%2e/secret.glb",
        "%2E%2E/secret.glb",
        "..%2fsecret.glb",
        "%2e%2e%2fsecret.glb",
        "tiles/%2e%2e/%2e%2e/secret.glb",
    ] {
        let mut doc = doc.clone();
        doc["root"]["children"][1]["content"]["uri"] = uri.into();
        std::fs::write(&ts, serde_json::to_vec(&doc).unwrap()).unwrap();
        let r = run(&["validate", &url, "--json"]);
        assert_eq!(r.code, 1, "{uri}: {}", r.all());
        let v: serde_json::Value = serde_json::from_str(&r.out()).unwrap();
        let found = v["findings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["path"] == "root.children[1].content")
            .unwrap_or_else(|| panic!("{uri}: {v:#}"));
        let m = found["message"].as_str().unwrap();
        assert!(
            m.contains("outside") || m.contains("separator"),
            "{uri}: {m}"
        );
    }
    let seen = log.lock().unwrap().clone();
    assert!(seen.iter().all(|p| p.starts_with("/ts/")), "{seen:?}");
    let _ = std::fs::remove_dir_all(&d);
}
