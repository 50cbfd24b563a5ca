//! What the compiler cannot check of the layering (ARCHITECTURE.md). The crates are the outer
//! layers: the applications (`crates/splatgl-*`) depend on the library, never the other way,
//! and cargo refuses a cycle. Inside the library, each module of `src/` may use modules of its
//! own layer or below, never above, and no two modules of one layer use each other both ways.
//! And the library's dependency tree: with its default features (`gl`) it compiles no window,
//! UI, command-line or network crate; without them, no GL.

use crate::common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The layers, lowest first. A module not listed fails the test (add it where it belongs).
const LAYERS: &[&[&str]] = &[
    // Data and numbers every stage shares; bounded file access.
    &["cloud", "covariance", "sh", "profile", "files"],
    // The camera model (framing, cameras.json, glTF cameras).
    &["camera"],
    // Reading and writing files; images; the synthetic scenes.
    &["load", "write", "image", "compare", "synthetic"],
    // Per-frame CPU stages; the converter; tilesets (read through the loaders).
    &["cull", "sort", "convert", "tiles"],
    // The two renderers.
    &["reference", "gl"],
    // Driving a renderer: headless EGL; either renderer for offline images.
    &["headless", "engine"],
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The code of a file without comments and without its `#[cfg(test)] mod tests { … }` tail.
fn code_lines(text: &str) -> Vec<(usize, String)> {
    let end = text.find("#[cfg(test)]\nmod tests").unwrap_or(text.len());
    text[..end]
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim_start().starts_with("//"))
        .map(|(i, l)| (i + 1, l.split(" // ").next().unwrap_or(l).to_owned()))
        .collect()
}

/// The top-level modules a line names through `crate::` (also `crate::{a, b::c}`) or through
/// enough `super::`s to reach the crate root from a file `depth` modules deep.
fn named_modules(line: &str, depth: usize) -> Vec<String> {
    let mut out = Vec::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut rest = line;
    while let Some(i) = rest.find("crate::") {
        let after = &rest[i + 7..];
        if let Some(group) = after.strip_prefix('{') {
            let inner = &group[..group.find('}').unwrap_or(group.len())];
            out.extend(inner.split(',').map(|p| ident(p.trim())));
        } else {
            out.push(ident(after));
        }
        rest = after;
    }
    let supers = "super::".repeat(depth);
    if depth > 0 {
        let mut rest = line;
        while let Some(i) = rest.find(&supers) {
            let after = &rest[i + supers.len()..];
            if !after.starts_with("super::") {
                out.push(ident(after));
            }
            rest = after;
        }
    }
    out.retain(|m| !m.is_empty() && m != "self");
    out
}

#[test]
fn no_module_uses_a_module_of_a_higher_layer_or_one_that_uses_it_back() {
    let src = common::root().join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut uses: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    let mut problems = Vec::new();
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap();
        let parts: Vec<String> = rel
            .iter()
            .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_owned())
            .collect();
        let top = parts[0].clone();
        if top == "lib" || parts.last().unwrap() == "tests" {
            continue; // the crate root and test-only modules
        }
        // Modules deep: src/a.rs and src/a/mod.rs are 1, src/a/b.rs is 2.
        let depth = parts.len() - usize::from(parts.last().unwrap() == "mod");
        let text = std::fs::read_to_string(f).unwrap();
        for (line_no, line) in code_lines(&text) {
            for m in named_modules(&line, depth) {
                if m == top
                    || layer_of(&m).is_none()
                        && !src.join(format!("{m}.rs")).exists()
                        && !src.join(&m).is_dir()
                {
                    continue; // itself, or not a module (a macro, a type at the root)
                }
                let at = format!("src/{}:{line_no}", rel.display());
                uses.entry(top.clone())
                    .or_default()
                    .entry(m.clone())
                    .or_insert(at.clone());
                match (layer_of(&top), layer_of(&m)) {
                    (Some(a), Some(b)) if b > a => problems.push(format!(
                        "{at}: `{top}` (layer {a}) uses `{m}` (layer {b}), a higher layer"
                    )),
                    (None, _) => problems.push(format!(
                        "{at}: module `{top}` is in no layer of tests/it/layering.rs"
                    )),
                    (_, None) => problems.push(format!(
                        "{at}: module `{m}` is in no layer of tests/it/layering.rs"
                    )),
                    _ => {}
                }
            }
        }
    }
    for (a, used) in &uses {
        for (b, at) in used {
            if let Some(back) = uses.get(b).and_then(|u| u.get(a))
                && a < b
            {
                problems.push(format!("`{a}` and `{b}` use each other ({at}, {back})"));
            }
        }
    }
    let problems: BTreeSet<String> = problems.into_iter().collect();
    assert!(
        problems.is_empty(),
        "layering broken:\n{}",
        problems.into_iter().collect::<Vec<_>>().join("\n")
    );
    // The check sees what it should: the loaders use the cloud, headless the GL backend.
    assert!(
        uses["load"].contains_key("cloud") && uses["headless"].contains_key("gl"),
        "{uses:?}"
    );
}

#[test]
fn the_check_finds_crate_paths_groups_and_supers() {
    assert_eq!(named_modules("use crate::load::Format;", 1), ["load"]);
    assert_eq!(
        named_modules("use crate::{cloud::X, sh::Y};", 1),
        ["cloud", "sh"]
    );
    assert_eq!(named_modules("let x = super::super::gl::f();", 2), ["gl"]);
    assert!(named_modules("use super::frame::UpAxis;", 2).is_empty());
    assert_eq!(named_modules("use super::cloud::SplatCloud;", 1), ["cloud"]);
}

/// The crates `cargo tree` lists for the library with `features` (normal edges only).
fn library_tree(features: &[&str]) -> Vec<String> {
    let out = Command::new(env!("CARGO"))
        .current_dir(common::root())
        .args(["tree", "--offline", "--locked", "-p", "splatgl"])
        .args(["-e", "normal", "--prefix", "none", "--format", "{p}"])
        .args(features)
        .output()
        .expect("cargo tree");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let mut names: Vec<String> = text
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_owned)
        .collect();
    names.sort();
    names.dedup();
    names
}

#[test]
fn the_default_library_compiles_no_window_ui_cli_or_network_crate() {
    let names = library_tree(&[]);
    assert!(names.iter().any(|n| n == "glow"), "{names:?}");
    for app in [
        "winit",
        "glutin",
        "egui",
        "clap",
        "ureq",
        "rustls",
        "ring",
        "splatgl-cli",
        "splatgl-viewer",
        "splatgl-conformance",
        "splatgl-capi",
    ] {
        assert!(
            !names.iter().any(|n| n == app),
            "`splatgl` with default features compiles {app}: {names:?}"
        );
    }
}

#[test]
fn the_library_without_features_compiles_no_gl() {
    let names = library_tree(&["--no-default-features"]);
    assert!(names.iter().any(|n| n == "gltf"), "{names:?}");
    for gl in ["glow", "khronos-egl"] {
        assert!(
            !names.iter().any(|n| n == gl),
            "`splatgl --no-default-features` compiles {gl}: {names:?}"
        );
    }
}
