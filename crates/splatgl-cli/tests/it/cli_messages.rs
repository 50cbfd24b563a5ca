//! What the command line says: `validate` tells *invalid* from *valid but not decodable by
//! splatgl* (`unsupported`) and collapses repeats; `info` and `validate` count non-finite
//! values; trainer artefacts are notes, not warnings; `-q` and `-v`.

use crate::common;

use std::path::PathBuf;

fn splatgl(args: &[&str]) -> (i32, String, String) {
    let r = common::cli::run(args);
    (r.code, r.out(), r.stderr)
}

fn real(name: &str) -> String {
    let p = common::root().join("../shared/data/real").join(name);
    assert!(p.exists(), "{} (see SOURCES.md)", p.display());
    p.to_str().unwrap().to_owned()
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-cli-msg-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn validate_calls_an_extension_splatgl_lacks_unsupported_not_invalid() {
    let d = dir("unsupported");
    let f = d.join("req.gltf");
    std::fs::write(
        &f,
        r#"{"asset":{"version":"2.0"},"extensionsUsed":["EXT_fancy"],"extensionsRequired":["EXT_fancy"]}"#,
    )
    .unwrap();
    let f = f.to_str().unwrap();
    let (code, out, _) = splatgl(&["validate", f]);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.contains("unsupported at extensionsRequired[0]"),
        "{out}"
    );
    assert!(
        out.contains("valid (0 errors, 0 warnings, 1 unsupported)"),
        "{out}"
    );
    assert!(out.contains("cannot decode"), "{out}");
    let (code, out, _) = splatgl(&["validate", "--json", f]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        (v["valid"].clone(), v["unsupported"].clone()),
        (true.into(), 1.into())
    );
    assert_eq!(v["findings"][0]["severity"], "unsupported");
    // It still cannot be loaded.
    let (code, _, err) = splatgl(&["info", f]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("EXT_fancy"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn validate_collapses_repeated_findings_like_info() {
    let f = real("bevy_khr_conformance_matrix.glb");
    let (code, out, _) = splatgl(&["validate", &f]);
    assert_eq!(code, 1, "{out}");
    let (_, json, _) = splatgl(&["validate", "--json", &f]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let findings = v["findings"].as_array().unwrap().len();
    let lines = out.lines().count();
    assert!(findings > 40, "{findings} findings");
    assert!(
        lines < findings / 2,
        "{lines} lines for {findings} findings:\n{out}"
    );
    assert!(out.contains("more like it"), "{out}");
    let (_, quiet, _) = splatgl(&["validate", "-q", &f]);
    assert_eq!(quiet.lines().count(), 1, "{quiet}");
}

#[test]
fn infinite_opacities_are_counted_by_info_and_validate() {
    let f = real("mujoco_warp_fox_sh0.ply");
    let (code, out, err) = splatgl(&["info", "--json", &f]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let n = v["non_finite_opacities"].as_u64().unwrap();
    assert!(n > 0, "{v}");
    let (_, text, _) = splatgl(&["info", &f]);
    assert!(text.contains(&format!("{n} opacity logits ±inf")), "{text}");
    let (code, out, _) = splatgl(&["validate", &f]);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.contains("warning at vertex.opacity")
            && out.contains(&format!("{n} opacity logits are ±inf")),
        "{out}"
    );
    // A file without them says nothing.
    let (_, out, _) = splatgl(&["info", "--json", &real("splatapult_test_16splats_sh3.ply")]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["non_finite_opacities"], 0);
}

#[test]
fn trainer_quaternions_are_notes_not_warnings() {
    let f = real("supersplat_fruit_drops_minimal_sh3.ply");
    let (code, out, _) = splatgl(&["info", &f]);
    assert_eq!(code, 0);
    let line = out
        .lines()
        .find(|l| l.contains("not unit length"))
        .expect("the note");
    assert!(line.starts_with("note: "), "{out}");
    let (_, json, _) = splatgl(&["validate", "--json", &f]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["warnings"], 0, "{v}");
    assert_eq!(v["notes"], 1, "{v}");
    let (_, quiet, _) = splatgl(&["info", "-q", &f]);
    assert!(!quiet.contains("not unit length"), "{quiet}");
    // info --json keeps them apart from the warnings too.
    let (_, json, _) = splatgl(&["info", "--json", &f]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let has = |key: &str| {
        v[key]
            .as_array()
            .unwrap()
            .iter()
            .any(|l| l.as_str().unwrap().contains("not unit length"))
    };
    assert!(has("notes") && !has("warnings"), "{v}");
    // render keeps it to -v.
    let d = dir("notes");
    let o = d.join("o.png");
    let args = [
        "render",
        &f,
        "--width",
        "8",
        "--height",
        "8",
        "--backend",
        "reference",
    ];
    let (_, _, err) = splatgl(&[&args[..], &["-o", o.to_str().unwrap()]].concat());
    assert!(!err.contains("not unit length"), "{err}");
    let (_, _, err) = splatgl(&[&args[..], &["-v", "-f", "-o", o.to_str().unwrap()]].concat());
    assert!(err.contains("note: vertex.rot_0..3"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn render_quiet_prints_nothing_and_verbose_says_the_backend_and_why() {
    let d = dir("quiet");
    let o = d.join("o.png");
    let o = o.to_str().unwrap();
    let args = ["render", "--width", "8", "--height", "8", "-f", "-o", o];
    let (code, out, err) = splatgl(&[&args[..], &["-q"]].concat());
    assert_eq!((code, out.as_str(), err.as_str()), (0, "", ""));
    let (code, _, err) = splatgl(&[&args[..], &["-v"]].concat());
    assert_eq!(code, 0, "{err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("backend: "))
        .expect("backend line");
    assert!(line.contains("auto:") && line.contains('('), "{line}");
    let (code, _, err) = splatgl(&[&args[..], &["-v", "--backend", "reference"]].concat());
    assert_eq!(code, 0);
    assert!(
        err.contains("backend: reference (--backend reference)"),
        "{err}"
    );
    std::fs::remove_dir_all(&d).ok();
}

/// One broken file, one message: `info`, `validate` and `render` say the same thing, each
/// naming the file and the element (PLY) or JSON path (glTF).
#[test]
fn info_validate_and_render_word_an_error_alike() {
    let d = dir("alike");
    let ply = d.join("broken.ply");
    std::fs::write(
        &ply,
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nend_header\n",
    )
    .unwrap();
    let gltf = d.join("broken.gltf");
    std::fs::write(
        &gltf,
        r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":5},"extensions":{"KHR_gaussian_splatting":{}}}]}]}"#,
    )
    .unwrap();
    let o = d.join("o.png");
    for (file, message) in [
        (&ply, "element 'vertex': missing property 'f_dc_0'"),
        (
            &gltf,
            r#"meshes[0].primitives[0].attributes["POSITION"]: accessor index 5 out of range"#,
        ),
    ] {
        let f = file.to_str().unwrap();
        let (code, _, info) = splatgl(&["info", f]);
        assert_eq!(code, 2);
        let (code, validate, _) = splatgl(&["validate", f]);
        assert_eq!(code, 1);
        let (code, _, render) = splatgl(&["render", f, "-o", o.to_str().unwrap()]);
        assert_eq!(code, 2);
        for (what, text) in [
            ("info", &info),
            ("validate", &validate),
            ("render", &render),
        ] {
            let line = text
                .lines()
                .find(|l| l.contains(message))
                .unwrap_or_else(|| panic!("{what}: no {message:?} in {text}"));
            assert!(line.contains(f), "{what} does not name the file: {line}");
        }
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn file_content_in_messages_reaches_the_terminal_with_its_control_characters_escaped() {
    let d = dir("controls");
    // A PLY element name and a glTF buffer URI carrying terminal escape sequences.
    let ply = d.join("esc.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty \x1b]0;owned\x07float x\nend_header\n1\n",
    )
    .unwrap();
    let gltf = d.join("esc.gltf");
    std::fs::write(
        &gltf,
        r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"\u001b[2J\u001b[31mx.bin","byteLength":4}]}"#,
    )
    .unwrap();
    for f in [&ply, &gltf] {
        for cmd in ["info", "validate"] {
            let (code, out, err) = splatgl(&[cmd, f.to_str().unwrap()]);
            assert_ne!(code, 0, "{cmd} {}: {out}{err}", f.display());
            let all = out + &err;
            assert!(
                !all.contains(['\x1b', '\x07']),
                "{cmd} {}: {all:?}",
                f.display()
            );
            assert!(all.contains("\\u{1b}"), "{cmd} {}: {all}", f.display());
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}
