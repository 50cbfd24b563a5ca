//! Writers never lose data: every file goes through a temporary file renamed into place, so a
//! failure midway leaves the previous file byte-identical, and no command writes over its own
//! input.

mod common;
use common::random_cloud;
use splatgl::write::{save, write_atomic};
use std::path::{Path, PathBuf};
use std::process::Command;

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("splatgl-writers-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn entries(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn interrupted_write_leaves_the_previous_file_byte_identical() {
    let d = dir("interrupt");
    let out = d.join("image.png");
    let previous: Vec<u8> = (0..=255u8).cycle().take(10_000).collect();
    std::fs::write(&out, &previous).unwrap();
    // The writer fails after half of a new, longer content.
    let e = write_atomic(&out, &[], |w| {
        w.write_all(&[1u8; 8_000])?;
        Err(std::io::Error::other("disk pulled out"))
    })
    .unwrap_err();
    assert!(e.to_string().contains("disk pulled out"));
    assert_eq!(std::fs::read(&out).unwrap(), previous);
    assert_eq!(entries(&d), ["image.png"], "no temporary file left behind");
    // A panicking writer too.
    let o = out.clone();
    let r = std::panic::catch_unwind(move || {
        write_atomic(&o, &[], |w| {
            w.write_all(b"partial")?;
            panic!("writer bug")
        })
    });
    assert!(r.is_err());
    assert_eq!(std::fs::read(&out).unwrap(), previous);
    assert_eq!(entries(&d), ["image.png"]);
    // And a complete write replaces it.
    write_atomic(&out, &[], |w| w.write_all(b"new")).unwrap();
    assert_eq!(std::fs::read(&out).unwrap(), b"new");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn writing_over_an_input_is_refused_through_any_name() {
    let d = dir("inputs");
    let scene = d.join("scene.ply");
    let cloud = random_cloud(4, 1, 5.0, 1);
    save(&cloud, &scene, &[]).unwrap();
    let before = std::fs::read(&scene).unwrap();
    std::fs::hard_link(&scene, d.join("alias.ply")).unwrap();
    for out in [
        scene.clone(),
        d.join("alias.ply"),
        d.join(".").join("scene.ply"),
    ] {
        let e = save(&random_cloud(9, 0, 5.0, 2), &out, &[&scene]).unwrap_err();
        assert!(
            e.to_string()
                .contains("refusing to write over the input file"),
            "{e}"
        );
    }
    assert_eq!(std::fs::read(&scene).unwrap(), before);
    // Other names are fine, and every format round-trips through `save`.
    for name in ["copy.ply", "copy.glb", "copy.gltf"] {
        save(&cloud, &d.join(name), &[&scene]).unwrap();
        let l = splatgl::load::load_path(d.join(name), &Default::default()).unwrap();
        assert_eq!(l.cloud.len(), 4, "{name}");
    }
    assert!(save(&cloud, &d.join("x.txt"), &[]).is_err());
    std::fs::remove_dir_all(&d).ok();
}

fn splatgl(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args(args)
        .output()
        .expect("runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn render_and_compare_refuse_to_overwrite_their_inputs() {
    let d = dir("cli");
    // A PLY named .png (formats are found by magic bytes), rendered onto itself.
    let scene = d.join("scene.png");
    save(&random_cloud(4, 0, 5.0, 3), &d.join("scene.ply"), &[]).unwrap();
    std::fs::rename(d.join("scene.ply"), &scene).unwrap();
    let before = std::fs::read(&scene).unwrap();
    let s = scene.to_str().unwrap();
    let (code, err) = splatgl(&["render", s, "--backend", "reference", "-o", s]);
    assert_eq!(code, 2);
    assert!(
        err.contains("refusing to write over the input file"),
        "{err}"
    );
    assert_eq!(std::fs::read(&scene).unwrap(), before);
    // compare --diff onto one of the compared images.
    let img = splatgl::image::Image::filled(2, 2, [0.5, 0.5, 0.5, 1.0]);
    let a = d.join("a.png");
    img.write_png(&a, splatgl::image::PngDepth::Eight, false)
        .unwrap();
    let a_bytes = std::fs::read(&a).unwrap();
    let p = a.to_str().unwrap();
    let (code, err) = splatgl(&["compare", p, p, "--diff", p]);
    assert_eq!(code, 2);
    assert!(
        err.contains("refusing to write over the input file"),
        "{err}"
    );
    assert_eq!(std::fs::read(&a).unwrap(), a_bytes);
    std::fs::remove_dir_all(&d).ok();
}
