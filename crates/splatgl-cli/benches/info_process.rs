//! `splatgl info` as a whole process on a 248 MB PLY (1M splats, SH degree 3, with the INRIA
//! trainer's `nx ny nz`): wall time, bytes/s and peak resident memory (the child's
//! `ru_maxrss`) against the cloud's own size, for
//! - `mmap`: the default path (memory-mapped file, pages released as rows are decoded),
//! - `read`: the same binary with `SPLATGL_NO_MMAP=1` (the file read into memory first: the
//!   path before memory mapping),
//! - `plyfile+numpy`: `benches/plyfile_load.py` doing the same work in Python (read every row,
//!   exp / sigmoid / normalise / SH reorder, bounds), when `python3 -c "import plyfile"` works;
//!   skipped with a note otherwise,
//! - `cat`: the file copied to `/dev/null` (the page-cache read bandwidth of this machine).
//!
//! Every variant runs `ROUNDS` times interleaved (one of each per round, so background load
//! hits them alike); the best and the median are printed. The file is generated once into
//! `target/bench-data/` (or `SPLATGL_BENCH_PLY=PATH`), and read once before timing so every
//! variant starts from a warm page cache.
//!
//! `cargo bench -p splatgl-cli --bench info_process`

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

const N: usize = 1_000_000;
const ROUNDS: usize = 7;

/// Builds a fresh command for one run of a variant.
type MakeCommand<'a> = Box<dyn Fn() -> Command + 'a>;

/// One child run: wall seconds and peak RSS in bytes.
fn run_child(cmd: &mut Command) -> Option<(f64, u64)> {
    let t0 = Instant::now();
    let child = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::inherit())
        .spawn()
        .ok()?;
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value; wait4 fills it for our own child.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: the pid is our child's and has not been waited for.
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    let secs = t0.elapsed().as_secs_f64();
    if pid <= 0 || !libc::WIFEXITED(status) || libc::WEXITSTATUS(status) != 0 {
        eprintln!("  (child failed: status {status})");
        return None;
    }
    Some((secs, usage.ru_maxrss as u64 * 1024))
}

fn bench_file() -> PathBuf {
    if let Some(p) = std::env::var_os("SPLATGL_BENCH_PLY") {
        return PathBuf::from(p);
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/bench-data");
    let p = dir.join("info_1m_sh3_normals.ply");
    if !p.exists() {
        std::fs::create_dir_all(&dir).expect("target/bench-data");
        eprintln!("generating {} …", p.display());
        // In a child: a child's peak RSS starts from its parent's (Linux carries the high
        // water mark across fork and exec), so this process must never hold a cloud.
        let ok = Command::new(std::env::current_exe().expect("bench exe"))
            .arg("--generate")
            .arg(&p)
            .status()
            .is_ok_and(|s| s.success());
        assert!(ok, "generating {} failed", p.display());
    }
    p
}

fn generate(p: &Path) {
    let cloud = splatgl::synthetic::random_cloud(N, 3, 10.0, 7);
    let bytes = splatgl::write::to_inria_ply_with_normals(&cloud);
    splatgl::write::write_bytes_atomic(p, &[], &bytes).expect("bench file");
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// What is timed: `splatgl info` with and without the memory map, `cat` of the file, and
/// plyfile + NumPy where Python has them.
fn variants<'a>(exe: &'a str, file: &'a Path) -> Vec<(&'static str, MakeCommand<'a>)> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/plyfile_load.py");
    let have_plyfile = Command::new("python3")
        .args(["-c", "import plyfile, numpy"])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    let mut variants: Vec<(&str, MakeCommand<'a>)> = vec![
        (
            "mmap",
            Box::new(move || {
                let mut c = Command::new(exe);
                c.arg("info").arg(file).env_remove("SPLATGL_NO_MMAP");
                c
            }),
        ),
        (
            "read",
            Box::new(move || {
                let mut c = Command::new(exe);
                c.arg("info").arg(file).env("SPLATGL_NO_MMAP", "1");
                c
            }),
        ),
        (
            "cat",
            Box::new(move || {
                let mut c = Command::new("cat");
                c.arg(file);
                c
            }),
        ),
    ];
    if have_plyfile {
        variants.push((
            "plyfile+numpy",
            Box::new(move || {
                let mut c = Command::new("python3");
                c.arg(&script).arg(file);
                c
            }),
        ));
    } else {
        println!("plyfile+numpy: skipped (python3 -c \"import plyfile, numpy\" fails)");
    }
    variants
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.iter().any(|a| a == "--list") {
        println!("info_process: bench");
        return;
    }
    if let Some(i) = args.iter().position(|a| a == "--generate") {
        generate(Path::new(&args[i + 1]));
        return;
    }
    let exe = env!("CARGO_BIN_EXE_splatgl");
    let file = bench_file();
    let size = std::fs::metadata(&file).expect("bench file").len();
    // Warm the page cache (in a child, see `bench_file`).
    let _ = Command::new("cat")
        .arg(&file)
        .stdout(Stdio::null())
        .status();
    let info = Command::new(exe)
        .args(["info", "--json"])
        .arg(&file)
        .output()
        .expect("splatgl info");
    let json: serde_json::Value = serde_json::from_slice(&info.stdout).expect("info --json");
    let cloud_bytes = json["memory_bytes"].as_u64().expect("memory_bytes");
    let variants = variants(exe, &file);
    let mut times = vec![Vec::new(); variants.len()];
    let mut peaks = vec![0u64; variants.len()];
    for _ in 0..ROUNDS {
        for (i, (_, make)) in variants.iter().enumerate() {
            if let Some((t, rss)) = run_child(&mut make()) {
                times[i].push(t);
                peaks[i] = peaks[i].max(rss);
            }
        }
    }
    println!(
        "file {} ({:.1} MB), cloud {:.1} MB, {ROUNDS} interleaved rounds",
        file.display(),
        size as f64 / 1e6,
        cloud_bytes as f64 / 1e6
    );
    let best_mmap = times[0].iter().copied().fold(f64::INFINITY, f64::min);
    for (i, (name, _)) in variants.iter().enumerate() {
        if times[i].is_empty() {
            println!("{name:>14}: failed");
            continue;
        }
        let best = times[i].iter().copied().fold(f64::INFINITY, f64::min);
        let med = median(&mut times[i]);
        println!(
            "{name:>14}: best {:7.1} ms ({:.2} GB/s), median {:7.1} ms, peak RSS {:6.1} MB = {:.3}× the cloud; {:.2}× the time of mmap",
            best * 1e3,
            size as f64 / best / 1e9,
            med * 1e3,
            peaks[i] as f64 / 1e6,
            peaks[i] as f64 / cloud_bytes as f64,
            best / best_mmap
        );
    }
}
