//! Writers never lose data: every file goes through a temporary file renamed into place, so a
//! failure midway leaves the previous file byte-identical, and no command writes over its own
//! input.

use crate::common;
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
    let r = common::cli::run(args);
    (r.code, r.stderr)
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

#[test]
fn convert_refuses_to_write_over_its_input_even_with_force() {
    let d = dir("convert-input");
    let scene = d.join("scene.ply");
    save(&random_cloud(6, 1, 5.0, 4), &scene, &[]).unwrap();
    let before = std::fs::read(&scene).unwrap();
    std::fs::hard_link(&scene, d.join("alias.ply")).unwrap();
    let s = scene.to_str().unwrap();
    for out in [
        s.to_owned(),
        d.join("alias.ply").to_string_lossy().into_owned(),
    ] {
        for force in [false, true] {
            let mut args = vec!["convert", s, &out];
            if force {
                args.push("-f");
            }
            let (code, err) = splatgl(&args);
            assert_eq!(code, 2, "{args:?}");
            assert!(
                err.contains("refusing to write over the input file"),
                "{args:?}: {err}"
            );
        }
    }
    assert_eq!(std::fs::read(&scene).unwrap(), before);
    // Another existing file is replaced with -f only.
    let other = d.join("other.ply");
    std::fs::write(&other, b"previous").unwrap();
    let o = other.to_str().unwrap();
    assert_eq!(splatgl(&["convert", s, o]).0, 2);
    assert_eq!(std::fs::read(&other).unwrap(), b"previous");
    assert_eq!(splatgl(&["convert", s, o, "-f"]).0, 0);
    assert_eq!(std::fs::read(&other).unwrap(), before, "PLY → PLY is exact");
    std::fs::remove_dir_all(&d).ok();
}

/// Runs splatgl with its file writes capped at `limit` bytes (RLIMIT_FSIZE): a write past the
/// cap kills the process with SIGXFSZ midway (`killed`: an interrupted write), or fails with
/// EFBIG when SIGXFSZ is ignored (a failed write).
fn splatgl_capped(args: &[&str], limit: u64, killed: bool) -> std::process::Output {
    use std::os::unix::process::CommandExt;
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_splatgl"));
    cmd.args(args);
    // SAFETY: setrlimit and signal are async-signal-safe; nothing else runs in the child.
    unsafe {
        cmd.pre_exec(move || {
            let cap = libc::rlimit {
                rlim_cur: limit,
                rlim_max: limit,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &cap) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            let action = if killed { libc::SIG_DFL } else { libc::SIG_IGN };
            libc::signal(libc::SIGXFSZ, action);
            Ok(())
        });
    }
    cmd.output().expect("runs")
}

#[test]
fn interrupted_or_failed_convert_leaves_the_previous_output_byte_identical() {
    use std::os::unix::process::ExitStatusExt;
    let d = dir("convert-cut");
    let scene = d.join("big.ply");
    save(&random_cloud(3000, 0, 5.0, 5), &scene, &[]).unwrap();
    let out = d.join("out.glb");
    let previous: Vec<u8> = (0..=255u8).cycle().take(1000).collect();
    let (s, o) = (scene.to_str().unwrap(), out.to_str().unwrap());
    for killed in [true, false] {
        std::fs::write(&out, &previous).unwrap();
        let r = splatgl_capped(&["convert", s, o, "-f"], 32 << 10, killed);
        let err = String::from_utf8_lossy(&r.stderr);
        if killed {
            assert_eq!(r.status.signal(), Some(libc::SIGXFSZ), "{err}");
        } else {
            assert_eq!(r.status.code(), Some(2), "{err}");
            assert!(err.contains("File too large"), "{err}");
        }
        assert_eq!(std::fs::read(&out).unwrap(), previous, "killed: {killed}");
        // A killed process leaves its partial temporary file beside the output (never in its
        // place); a failed write removes it.
        let tmp: Vec<String> = entries(&d)
            .into_iter()
            .filter(|n| n.contains("splatgl-tmp"))
            .collect();
        assert_eq!(tmp.len(), usize::from(killed), "{tmp:?}");
        for t in tmp {
            std::fs::remove_file(d.join(t)).unwrap();
        }
    }
    // Uncapped, the same command replaces the file.
    assert_eq!(splatgl(&["convert", s, o, "-f"]).0, 0);
    assert_eq!(
        splatgl::load::load_path(&out, &Default::default())
            .unwrap()
            .cloud
            .len(),
        3000
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn failed_conformance_writes_leave_the_previous_suite_and_report_byte_identical() {
    let d = dir("conformance-cut");
    // A previous suite's asset files: generation fails at its first write (over the cap).
    let mut previous = Vec::new();
    for spec in splatgl_conformance::assets::all() {
        let ext = if spec.json { "gltf" } else { "glb" };
        let p = d.join("suite/assets").join(format!("{}.{ext}", spec.name));
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(&p, format!("previous {}", spec.name)).unwrap();
        previous.push(p);
    }
    let suite = d.join("suite");
    let r = splatgl_capped(
        &["conformance", "generate", suite.to_str().unwrap()],
        1024,
        false,
    );
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("File too large"), "{err}");
    for p in &previous {
        let name = p.file_stem().unwrap().to_string_lossy();
        assert_eq!(
            std::fs::read_to_string(p).unwrap(),
            format!("previous {name}")
        );
    }
    assert!(
        !entries(&suite.join("assets"))
            .iter()
            .any(|n| n.contains("splatgl-tmp"))
    );
    // `conformance run` on an (empty) suite: the report files stay as they were.
    let empty = d.join("empty");
    std::fs::create_dir_all(empty.join("report")).unwrap();
    std::fs::write(
        empty.join("manifest.json"),
        format!(
            r#"{{"generator": "test", "rules_version": {}, "background": [0, 0, 0], "assets": []}}"#,
            splatgl_conformance::manifest::RULES_VERSION
        ),
    )
    .unwrap();
    for f in ["report.json", "report.html"] {
        std::fs::write(empty.join("report").join(f), "previous").unwrap();
    }
    let e = empty.to_str().unwrap();
    let r = splatgl_capped(&["conformance", "run", e, "--images", e], 64, false);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("File too large"), "{err}");
    for f in ["report.json", "report.html"] {
        assert_eq!(
            std::fs::read_to_string(empty.join("report").join(f)).unwrap(),
            "previous"
        );
    }
    // Uncapped, both are replaced.
    assert_eq!(splatgl(&["conformance", "run", e, "--images", e]).0, 0);
    let json = std::fs::read_to_string(empty.join("report/report.json")).unwrap();
    assert!(json.starts_with('{'), "{json}");
    std::fs::remove_dir_all(&d).ok();
}

#[cfg(unix)]
#[test]
fn writes_follow_symlinks_keep_permissions_and_refuse_special_files() {
    use splatgl::write::write_bytes_atomic;
    use std::os::unix::fs::PermissionsExt;
    let d = dir("special-dest");
    // A symlinked output: the target is replaced, the link stays a link.
    let target = d.join("target.png");
    std::fs::write(&target, b"old").unwrap();
    let link = d.join("link.png");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    write_bytes_atomic(&link, &[], b"new").unwrap();
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(std::fs::read(&target).unwrap(), b"new");
    // An existing file keeps its permissions.
    let kept = d.join("kept.png");
    std::fs::write(&kept, b"old").unwrap();
    std::fs::set_permissions(&kept, std::fs::Permissions::from_mode(0o640)).unwrap();
    write_bytes_atomic(&kept, &[], b"new").unwrap();
    let mode = std::fs::metadata(&kept).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o640);
    // A FIFO (or a device) is not replaced by a regular file.
    let fifo = d.join("fifo.png");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo with a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    let e = write_bytes_atomic(&fifo, &[], b"x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a regular file"), "{e}");
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo()
    );
    assert_eq!(
        entries(&d),
        ["fifo.png", "kept.png", "link.png", "target.png"]
    );
    std::fs::remove_dir_all(&d).ok();
}
