//! The C and C++ host examples, compiled with the system compiler (`-Wall -Wextra -Werror`)
//! against the committed header and the C library built with the `splatgl-capi` crate, run headless
//! through EGL, and held to their own pixel and state checks (`examples/c/legacy_host.c`,
//! `examples/cpp/core_host.cpp`).
//!
//! The library is the crate's own `cdylib` / `staticlib`, which cargo builds before these
//! tests; it is copied under the name C hosts link (`-lsplatgl`).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn root() -> PathBuf {
    common::root()
}

/// A folder holding this crate's C libraries under the names C hosts link (`libsplatgl.so`,
/// `libsplatgl.a`, as cargo-c installs them), or why not. The test command builds them first
/// (`cargo build -p splatgl-capi`: `libsplatgl_capi.*` in `target/<profile>/`); cargo test
/// itself builds only the `rlib`, so where they are missing this builds them into a target
/// folder of its own (`target/capi`: the main one is locked by the running cargo).
fn library() -> &'static Result<PathBuf, String> {
    static LIB: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    LIB.get_or_init(|| {
        let exe = std::env::current_exe().map_err(|e| e.to_string())?;
        let profile_dir = exe
            .ancestors()
            .nth(2)
            .ok_or("the test binary is not in target/<profile>/deps")?;
        let built = if profile_dir.join("libsplatgl_capi.so").is_file() {
            profile_dir.to_path_buf()
        } else {
            build_apart(profile_dir)?
        };
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("capi-lib");
        std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
        for (from, to) in [
            ("libsplatgl_capi.so", "libsplatgl.so"),
            ("libsplatgl_capi.a", "libsplatgl.a"),
        ] {
            std::fs::copy(built.join(from), dir.join(to))
                .map_err(|e| format!("{}: {e}", built.join(from).display()))?;
        }
        Ok(dir)
    })
}

/// Builds the C libraries into `target/capi` (beside `profile_dir`'s target folder); returns
/// the folder holding them.
fn build_apart(profile_dir: &Path) -> Result<PathBuf, String> {
    let target = profile_dir.parent().ok_or("no target folder")?.join("capi");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(root())
        .args([
            "build",
            "-p",
            "splatgl-capi",
            "--lib",
            "--locked",
            "--target-dir",
        ])
        .arg(&target)
        .output()
        .map_err(|e| format!("cargo: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "cargo build -p splatgl-capi failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(target.join("debug"))
}

/// Compiles `source` with `compiler` into the temporary folder, or `None` (skipped) when the
/// compiler is missing.
fn compile(compiler: &str, std: &str, source: &str, name: &str, libs: &[&str]) -> Option<PathBuf> {
    if Command::new(compiler).arg("--version").output().is_err() {
        common::skip(&format!("no `{compiler}` (Debian: build-essential)"));
        return None;
    }
    let lib = library().as_ref().expect("the C library builds");
    let exe = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let out = Command::new(compiler)
        .current_dir(root())
        .args([
            std,
            "-Wall",
            "-Wextra",
            "-Werror",
            "-Icrates/splatgl-capi/include",
            "-Iexamples/c",
            source,
        ])
        .arg("-L")
        .arg(lib)
        .arg("-lsplatgl")
        .args(libs)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .arg("-o")
        .arg(&exe)
        .output()
        .expect("the compiler runs");
    assert!(
        out.status.success(),
        "{compiler} {source} failed:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    Some(exe)
}

/// Runs a host example; its exit status is its verdict (it prints each failed check).
fn run(exe: &Path, args: &[&Path]) -> String {
    // Our copy, whatever cargo's LD_LIBRARY_PATH names.
    let lib = library().as_ref().expect("the C library builds");
    let out = Command::new(exe)
        .args(args)
        .env("LD_LIBRARY_PATH", lib)
        .output()
        .expect("the host runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    if text.contains("EGL: cannot open") {
        common::skip("EGL cannot be opened here");
        return text;
    }
    assert!(out.status.success(), "{} failed:\n{text}", exe.display());
    text
}

/// The splat wall `legacy_host.c` expects (`write_legacy_host_wall`).
fn wall_ply() -> PathBuf {
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("capi-wall.ply");
    common::write_legacy_host_wall(&path);
    path
}

#[test]
fn legacy_c_host_keeps_its_pixels_and_state_with_splats_drawn_in_between() {
    let libs = ["-lEGL", "-lGL", "-lm"];
    let Some(exe) = compile(
        "cc",
        "-std=c99",
        "examples/c/legacy_host.c",
        "legacy_host",
        &libs,
    ) else {
        return;
    };
    let out = run(&exe, &[&wall_ply()]);
    assert!(out.contains("state pieces checked"), "{out}");
    eprintln!("{out}");
}

#[test]
fn core_cpp_host_with_reversed_z_occludes_splats_with_its_mesh() {
    let libs = ["-lEGL", "-lm"];
    let Some(exe) = compile(
        "c++",
        "-std=c++17",
        "examples/cpp/core_host.cpp",
        "core_host",
        &libs,
    ) else {
        return;
    };
    let out = run(&exe, &[]);
    assert!(out.contains("pixels show splats"), "{out}");
    eprintln!("{out}");
}
