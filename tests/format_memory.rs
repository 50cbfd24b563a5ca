//! Hostile packed files cannot make the loaders allocate more than the decompression budget
//! (16 MiB + 64 × input, docs/formats.md): gzip bombs, SPZ headers claiming 10⁸ and 4·10⁹
//! points, a zip member claiming 4 GiB, and a tiny WebP claiming a 32 MiB image. Peak heap
//! use is measured by a counting allocator; this binary holds one test so nothing else
//! allocates at the same time.

use common::{packed, random_cloud};
use splatgl::load::codec::budget_for;
use splatgl::load::{LoadOptions, load_bytes};
use splatgl_testkit as common;
use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering::SeqCst};

struct Counting;
static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is passed on to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let now = CURRENT.fetch_add(l.size(), SeqCst) + l.size();
        PEAK.fetch_max(now, SeqCst);
        // SAFETY: the caller's contract, passed on to the system allocator.
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        CURRENT.fetch_sub(l.size(), SeqCst);
        // SAFETY: the caller's contract, passed on to the system allocator.
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static A: Counting = Counting;

/// Loads `bytes` (expecting an error containing `needle`) and returns the peak extra heap.
fn peak_of(bytes: &[u8], name: &str, needle: &str) -> usize {
    let base = CURRENT.load(SeqCst);
    PEAK.store(base, SeqCst);
    let e = load_bytes(bytes, Some(Path::new(name)), &LoadOptions::default())
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains(needle), "{name}: {e}");
    PEAK.load(SeqCst) - base
}

#[test]
fn hostile_packed_files_stay_within_the_budget() {
    let mut cases: Vec<(&str, Vec<u8>, &str)> = Vec::new();
    // gzip bombs: an SPZ header claiming 10⁴ points (well within the budget) with the
    // extension flag or not, followed by 256 MiB of zeros (~250 KB compressed).
    for flags in [0u8, 2] {
        let mut raw = b"NGSP\x02\0\0\0\x10\x27\0\0\0\x0c\0\0".to_vec();
        raw[14] = flags;
        raw.resize(256 << 20, 0);
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        e.write_all(&raw).unwrap();
        drop(raw);
        let needle = if flags == 0 {
            "budget"
        } else {
            "extension records"
        };
        cases.push(("bomb.spz", e.finish().unwrap(), needle));
    }
    // A header claiming 10⁸ points in a small gzip member.
    let mut raw = b"NGSP\x03\0\0\0\0\xe1\xf5\x05\x03\x0c\0\0".to_vec();
    raw.resize(4096, 0);
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    e.write_all(&raw).unwrap();
    cases.push(("lying.spz", e.finish().unwrap(), "100000000 points"));
    // SPZ v4 claiming u32::MAX points.
    let mut v4 =
        splatgl::write::to_spz(&random_cloud(10, 0, 5.0, 1), splatgl::write::SpzVersion::V4)
            .unwrap();
    v4[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    cases.push(("count.spz", v4, "budget"));
    // A zip member claiming 4 GiB.
    let files = packed::sog_files(&random_cloud(10, 0, 5.0, 2));
    let m: Vec<(&str, &[u8])> = files
        .iter()
        .map(|(n, b)| (n.as_str(), b.as_slice()))
        .collect();
    let mut z = packed::zip_stored(&m);
    let cd = u32::from_le_bytes(z[z.len() - 6..z.len() - 2].try_into().unwrap()) as usize;
    z[cd + 24..cd + 28].copy_from_slice(&u32::MAX.to_le_bytes());
    cases.push(("member.sog", z, "budget"));
    // A few-KB lossless WebP of 4096 × 2048 texels (32 MiB decoded) as the scales texture.
    let mut files = packed::sog_files(&random_cloud(10, 0, 5.0, 2));
    files[3].1 = packed::webp(&vec![7u8; 4 * 4096 * 2048], 4096, 2048);
    let m: Vec<(&str, &[u8])> = files
        .iter()
        .map(|(n, b)| (n.as_str(), b.as_slice()))
        .collect();
    cases.push(("texture.sog", packed::zip_stored(&m), "budget"));

    for (name, bytes, needle) in &cases {
        let peak = peak_of(bytes, name, needle);
        let limit = budget_for(bytes.len(), &Default::default()) as usize;
        eprintln!(
            "{name}: {} input bytes, peak heap {peak} bytes, budget {limit}",
            bytes.len()
        );
        assert!(
            peak <= limit + (1 << 20),
            "{name}: peak {peak} > budget {limit}"
        );
    }
}
