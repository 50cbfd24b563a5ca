//! `render --backend auto`: the reference where GL is a software rasterizer (llvmpipe,
//! softpipe, SwiftShader) or unavailable, GL on a hardware driver; `-v` says which and why.

use std::process::Command;

const SOFTWARE: [&str; 3] = ["llvmpipe", "softpipe", "swiftshader"];

#[test]
fn auto_takes_the_reference_on_a_software_rasterizer_and_says_why() {
    let d = std::env::temp_dir().join(format!("splatgl-cli-backend-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let o = d.join("o.png");
    let out = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args([
            "render", "--width", "16", "--height", "12", "-v", "-f", "-o",
        ])
        .arg(&o)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let line = err
        .lines()
        .find_map(|l| l.strip_prefix("backend: "))
        .expect("backend line");
    let (name, why) = line.split_once(' ').unwrap();
    let software = SOFTWARE
        .iter()
        .any(|s| why.to_ascii_lowercase().contains(s));
    if why.contains("GL unavailable") {
        assert_eq!(name, "reference", "{line}");
    } else if software {
        // Mesa llvmpipe on CI machines.
        assert_eq!(name, "reference", "{line}");
        assert!(why.contains("software rasterizer"), "{line}");
    } else {
        assert_eq!(name, "gl", "{line}");
        assert!(why.contains("hardware GL driver"), "{line}");
    }
    // The summary names the same backend.
    assert!(err.contains(&format!("backend {name}:")), "{err}");
    // --backend gl is honoured where GL works at all, whatever the driver.
    let out = Command::new(env!("CARGO_BIN_EXE_splatgl"))
        .args([
            "render",
            "--width",
            "16",
            "--height",
            "12",
            "-v",
            "-f",
            "--backend",
            "gl",
            "-o",
        ])
        .arg(&o)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    if out.status.success() {
        assert!(err.contains("backend: gl (--backend gl"), "{err}");
    } else {
        assert!(err.contains("--backend gl:"), "{err}");
    }
    std::fs::remove_dir_all(&d).ok();
}
