//! The docs name what exists: every relative link of the README, `ARCHITECTURE.md` and
//! `docs/*.md` resolves to a file or folder of the repository; every repository path quoted
//! in their code (`src/…`, `crates/…`, `scripts/…`, `docs/…`, …) exists; and every `cargo`
//! command they show names a package, test, bench, example and feature that exist.

use crate::common;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The folders of the repository a quoted path may start with.
const ROOTS: &[&str] = &[
    "src/",
    "crates/",
    "scripts/",
    "docs/",
    "python/",
    "tests/",
    "examples/",
    "benches/",
    "glsl/",
    "fuzz/",
    "web/",
    "include/",
    ".ci/",
];

/// File types of this repository: a quoted path with another extension names a file of some
/// other project (a peer's `src/…` source, a tool's), not ours.
const OURS: &[&str] = &[
    "rs", "sh", "py", "pyi", "md", "glsl", "mjs", "js", "ts", "toml", "json", "h", "c", "cpp",
    "html", "txt", "yml", "css",
];

/// Built or generated outputs a doc may name (they exist after a build or a fuzz run, not in
/// a clone: the folders `.gitignore` and `fuzz/.gitignore` name).
const BUILT: &[&str] = &[
    "web/dist",
    "target/",
    "fuzz/target",
    "fuzz/corpus",
    "fuzz/artifacts",
    "fuzz/coverage",
    "fuzz/seeds",
];

fn docs(root: &Path) -> Vec<PathBuf> {
    let mut out = vec![root.join("README.md"), root.join("ARCHITECTURE.md")];
    let mut more: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    more.sort();
    out.extend(more);
    out
}

/// The targets of `[text](target)` links.
fn links(text: &str) -> Vec<&str> {
    text.match_indices("](")
        .filter_map(|(i, _)| {
            let rest = &text[i + 2..];
            let end = rest.find(')')?;
            Some(&rest[..end])
        })
        .filter(|t| !t.contains(' ') && !t.is_empty())
        .collect()
}

/// The text of every inline code span and fenced block.
fn code(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut in_block = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_block = !in_block;
            continue;
        }
        if in_block {
            out.push(line);
            continue;
        }
        out.extend(line.split('`').skip(1).step_by(2));
    }
    out
}

/// Repository paths quoted in `code`: tokens that start with one of [`ROOTS`].
fn quoted_paths(code: &str) -> Vec<&str> {
    code.split(|c: char| c.is_whitespace() || "()[],;'\"=|".contains(c))
        .map(|t| t.trim_end_matches(['.', ':']))
        .filter(|t| ROOTS.iter().any(|r| t.starts_with(r)))
        .filter(|t| !t.contains(['*', '…', '<', '>', '{', '}', '$']))
        .filter(|t| !BUILT.iter().any(|b| t.starts_with(b)))
        .filter(|t| {
            let file = t.rsplit('/').next().unwrap_or("");
            match file.rsplit_once('.') {
                Some((_, ext)) => OURS.contains(&ext),
                None => true,
            }
        })
        .collect()
}

#[test]
fn every_link_and_quoted_path_in_the_docs_exists() {
    let root = common::root();
    let mut missing = Vec::new();
    for doc in docs(&root) {
        let text = std::fs::read_to_string(&doc).unwrap();
        let name = doc.strip_prefix(&root).unwrap().display().to_string();
        for t in links(&text) {
            if t.starts_with('#') || t.contains("://") || t.starts_with("mailto:") {
                continue;
            }
            let file = t.split('#').next().unwrap();
            if !doc.parent().unwrap().join(file).exists() {
                missing.push(format!("{name}: link {t}"));
            }
        }
        for c in code(&text) {
            for p in quoted_paths(c) {
                if !root.join(p).exists() {
                    missing.push(format!("{name}: path {p}"));
                }
            }
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

/// What `cargo` commands may name: packages, their targets and features.
struct Workspace {
    packages: BTreeSet<String>,
    targets: BTreeSet<String>,
    features: BTreeSet<String>,
}

impl Workspace {
    fn read(root: &Path) -> Self {
        let mut w = Workspace {
            packages: BTreeSet::new(),
            targets: BTreeSet::new(),
            features: BTreeSet::new(),
        };
        let mut dirs = vec![root.to_path_buf()];
        for e in std::fs::read_dir(root.join("crates")).unwrap() {
            dirs.push(e.unwrap().path());
        }
        for d in dirs {
            w.add_package(&d);
        }
        w
    }

    fn add_package(&mut self, dir: &Path) {
        let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap();
        let mut section = String::new();
        for line in manifest.lines() {
            let line = line.trim();
            if line.starts_with('[') {
                section = line.to_string();
                continue;
            }
            let Some((key, value)) = line.split_once(" = ") else {
                continue;
            };
            match (section.as_str(), key) {
                ("[package]", "name") => {
                    self.packages.insert(value.trim_matches('"').to_string());
                }
                ("[features]", f) => {
                    self.features.insert(f.to_string());
                }
                ("[[bench]]" | "[[test]]" | "[[example]]" | "[[bin]]", "name") => {
                    self.targets.insert(value.trim_matches('"').to_string());
                }
                _ => {}
            }
        }
        for sub in ["benches", "tests", "examples", "src/bin"] {
            let Ok(entries) = std::fs::read_dir(dir.join(sub)) else {
                continue;
            };
            for e in entries {
                let p = e.unwrap().path();
                if let Some(stem) = p.file_stem() {
                    self.targets.insert(stem.to_string_lossy().into_owned());
                }
            }
        }
    }

    /// What in `args` (a cargo command's words after `cargo`) names nothing.
    fn unknown(&self, args: &[&str]) -> Vec<String> {
        let mut out = Vec::new();
        for pair in args.windows(2) {
            let (flag, value) = (pair[0], pair[1]);
            let known = match flag {
                "-p" | "--package" => self.packages.contains(value),
                "--bench" | "--test" | "--example" | "--bin" => self.targets.contains(value),
                "--features" | "-F" => value
                    .split(',')
                    .all(|f| self.features.contains(f.rsplit('/').next().unwrap_or(f))),
                _ => true,
            };
            if !known && !value.starts_with('-') {
                out.push(format!("{flag} {value}"));
            }
        }
        out
    }
}

#[test]
fn every_cargo_command_in_the_docs_names_what_exists() {
    let root = common::root();
    let w = Workspace::read(&root);
    let mut missing = Vec::new();
    for doc in docs(&root) {
        let text = std::fs::read_to_string(&doc).unwrap();
        let name = doc.strip_prefix(&root).unwrap().display().to_string();
        for c in code(&text) {
            for cmd in c.split("cargo ").skip(1) {
                // One command: up to a shell separator, a comment or the end of the span.
                let cmd = cmd.split(['#', ';', '|', '&', ')']).next().unwrap_or("");
                let args: Vec<&str> = cmd
                    .split_whitespace()
                    .map(|a| a.trim_matches('"'))
                    .collect();
                if args.first() == Some(&"install") {
                    continue; // tools from crates.io
                }
                for u in w.unknown(&args) {
                    missing.push(format!("{name}: `cargo {}`: {u}", cmd.trim()));
                }
            }
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}
