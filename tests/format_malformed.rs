//! Malformed SPZ, `.splat`, `.ksplat` and SOG inputs: each gives its specific error (naming
//! the block, member, section or texture, with expected vs found), never a panic; files whose
//! extension lies load by content with a warning naming both formats.

mod common;
use common::{packed, random_cloud};
use splatgl::load::{Format, LoadOptions, load_bytes};
use splatgl::write::{SpzWriteOptions, to_splat, to_spz};
use std::io::{Read, Write};
use std::path::Path;

#[track_caller]
fn err_of(bytes: &[u8], name: &str) -> String {
    match load_bytes(bytes, Some(Path::new(name)), &LoadOptions::default()) {
        Ok(l) => panic!("{name}: expected an error, loaded {} splats", l.cloud.len()),
        Err(e) => e.to_string(),
    }
}

#[track_caller]
fn expect(bytes: &[u8], name: &str, needles: &[&str]) {
    let e = err_of(bytes, name);
    for n in needles {
        assert!(e.contains(n), "error for {name} lacks {n:?}: {e}");
    }
}

fn gunzip(b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    flate2::read::GzDecoder::new(b)
        .read_to_end(&mut out)
        .unwrap();
    out
}

fn gzip(b: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(b).unwrap();
    e.finish().unwrap()
}

fn spz_of(c: &splatgl::SplatCloud, version: u32) -> Vec<u8> {
    let o = SpzWriteOptions {
        version,
        ..Default::default()
    };
    to_spz(c, &o).unwrap()
}

fn spz(version: u32, degree: u8) -> Vec<u8> {
    spz_of(&random_cloud(2, 40, degree), version)
}

#[test]
fn spz_corpus() {
    let v2 = spz(2, 1);
    let inner = gunzip(&v2);
    let with = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = inner.clone();
        f(&mut b);
        gzip(&b)
    };
    expect(&v2[..v2.len() - 20], "a.spz", &["SPZ: gzip:"]);
    expect(
        b"hello world, not a splat",
        "a.spz",
        &["not SPZ", "found 68656c6c"],
    );
    expect(&with(&|b| b[4] = 7), "a.spz", &["version 7", "gzip member"]);
    expect(&with(&|b| b[4] = 0), "a.spz", &["version 0"]);
    expect(&with(&|b| b[12] = 5), "a.spz", &["SH degree 5"]);
    expect(
        &with(&|b| b[8..12].copy_from_slice(&1000u32.to_le_bytes())),
        "a.spz",
        &[
            "claims 1000 points",
            "positions needs 28016 bytes, only 1136 present",
        ],
    );
    expect(
        &with(&|b| b[8..12].copy_from_slice(&1_000_000u32.to_le_bytes())),
        "a.spz",
        &["claims 1000000 points", "over the budget"],
    );
    expect(
        &with(&|b| b.truncate(b.len() - 5)),
        "a.spz",
        &["claims 40 points", "sh needs"],
    );
    // A gzip bomb: 64 MiB of zeros after a valid header, far over 16 MiB + 64 × ~65 KB.
    let mut bomb = inner[..16].to_vec();
    bomb.resize(64 << 20, 0);
    let bomb = gzip(&bomb);
    expect(&bomb, "a.spz", &["gzip", "budget"]);

    let v4 = spz(4, 1);
    let toc = u32::from_le_bytes(v4[16..20].try_into().unwrap()) as usize;
    let mut b = v4.clone();
    b[4] = 9;
    expect(&b, "a.spz", &["version 9"]);
    let mut b = v4.clone();
    b[15] = 3;
    expect(&b, "a.spz", &["3 streams, expected 6"]);
    let mut b = v4.clone();
    b[toc + 8] ^= 1; // stream 0 uncompressed size
    expect(&b, "a.spz", &["stream 0 (positions) holds", "expected 360"]);
    let mut b = v4.clone();
    b[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    expect(&b, "a.spz", &["4294967295 points", "budget"]);
    let mut b = v4.clone();
    b.truncate(b.len() - 3);
    expect(&b, "a.spz", &["sh needs"]);
    let mut b = v4.clone();
    b[toc + 6 * 16] ^= 0xff; // the first stream's zstd magic
    expect(&b, "a.spz", &["stream 0 (positions): zstd frame header"]);
    let mut b = v4.clone();
    b.extend_from_slice(b"junk");
    expect(&b, "a.spz", &["streams end at byte", "the file at"]);
}

#[test]
fn splat_and_ksplat_corpus() {
    let s = to_splat(&random_cloud(1, 5, 0));
    expect(
        &s[..s.len() - 7],
        "a.splat",
        &["length 153", "record 4 is truncated (25 of 32"],
    );
    // A NaN position is dropped and counted, not loaded and not an error.
    let mut b = s.clone();
    b[32..36].copy_from_slice(&f32::NAN.to_le_bytes());
    let l = load_bytes(&b, Some(Path::new("a.splat")), &LoadOptions::default()).unwrap();
    assert_eq!(l.cloud.len(), 4);
    assert!(
        l.report
            .warnings
            .iter()
            .any(|w| w.to_string().contains("1 splats dropped"))
    );

    let k = packed::ksplat(&random_cloud(3, 300, 1), 1, 128, 25.0);
    expect(
        &k[..5000],
        "a.ksplat",
        &["section headers needs", "the file has 5000"],
    );
    expect(&k[..k.len() - 1], "a.ksplat", &["section 0 data needs"]);
    let poke = |at: usize, v: &[u8]| {
        let mut b = k.clone();
        b[at..at + v.len()].copy_from_slice(v);
        b
    };
    expect(&poke(0, &[1]), "a.ksplat", &["version 1.1"]);
    expect(&poke(20, &[3, 0]), "a.ksplat", &["compression level 3"]);
    expect(
        &poke(4096, &301u32.to_le_bytes()),
        "a.ksplat",
        &["301 splats but room for 300"],
    );
    expect(&poke(4096 + 40, &[4, 0]), "a.ksplat", &["SH degree 4"]);
    expect(
        &poke(4096 + 32, &[1, 0, 0, 0]),
        "a.ksplat",
        &["buckets hold", "the section 300"],
    );
    let l = load_bytes(
        &poke(16, &[7, 0, 0, 0]),
        Some(Path::new("a.ksplat")),
        &LoadOptions::default(),
    )
    .unwrap();
    assert!(
        l.report
            .warnings
            .iter()
            .any(|w| w.to_string().contains("states 7 splats"))
    );
}

/// The files of a SOG bundle: (name, bytes).
type Files = Vec<(String, Vec<u8>)>;

fn sog_members(edit: &dyn Fn(&mut Files)) -> Vec<u8> {
    let mut files = packed::sog_files(&random_cloud(4, 50, 1));
    edit(&mut files);
    let m: Vec<(&str, &[u8])> = files
        .iter()
        .map(|(n, b)| (n.as_str(), b.as_slice()))
        .collect();
    packed::zip_stored(&m)
}

#[test]
fn sog_corpus() {
    let good = sog_members(&|_| {});
    expect(
        &sog_members(&|f| f.retain(|(n, _)| n != "quats.webp")),
        "a.sog",
        &["SOG: 'quats.webp' is missing"],
    );
    expect(
        &sog_members(&|f| f.retain(|(n, _)| n != "meta.json")),
        "a.sog",
        &["'meta.json' is missing"],
    );
    expect(
        &sog_members(&|f| f[3].1 = packed::webp(&[0; 4 * 12], 4, 3)),
        "a.sog",
        &[
            "texture 'scales.webp' (scales)",
            "4×3 = 12 texels, fewer than the 50 splats",
        ],
    );
    expect(
        &sog_members(&|f| f[0].1 = b"RIFF....WEBPnope".to_vec()),
        "a.sog",
        &["'means_l.webp' (means_l)", "not a WebP image"],
    );
    let meta = |f: &mut Files, from: &str, to: &str| {
        let m = f.last_mut().unwrap();
        m.1 = String::from_utf8(m.1.clone())
            .unwrap()
            .replace(from, to)
            .into_bytes();
    };
    expect(
        &sog_members(&|f| meta(f, "\"version\":2", "\"version\":3")),
        "a.sog",
        &["meta.json: version: 3"],
    );
    expect(
        &sog_members(&|f| meta(f, "\"bands\":1", "\"bands\":7")),
        "a.sog",
        &["shN.bands: 7, expected 1-3"],
    );
    expect(
        &sog_members(&|f| meta(f, "\"count\":50", "\"count\":5000")),
        "a.sog",
        &["fewer than the 5000 splats"],
    );
    // Zip-level damage: truncated, a corrupt member, a member claiming a huge size.
    expect(
        &good[..good.len() - 30],
        "a.sog",
        &["zip: no end-of-central-directory record"],
    );
    let mut b = good.clone();
    b[50] ^= 0xff; // inside means_l.webp's data (after the 30-byte header and its name)
    expect(&b, "a.sog", &["'means_l.webp'", "CRC-32"]);
    let cd = u32::from_le_bytes(good[good.len() - 6..good.len() - 2].try_into().unwrap()) as usize;
    let mut b = good.clone();
    b[cd + 24..cd + 28].copy_from_slice(&u32::MAX.to_le_bytes()); // first member's size
    expect(&b, "a.sog", &["'means_l.webp'", "over the", "budget"]);
    expect(
        b"PK\x03\x04 not really a zip at all",
        "a.sog",
        &["SOG: zip:"],
    );
}

#[test]
fn unbundled_sog_rejects_paths_outside_its_folder() {
    let dir = std::env::temp_dir().join(format!("splatgl-sogbad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let files = packed::sog_files(&random_cloud(4, 20, 0));
    for (n, b) in &files {
        std::fs::write(dir.join(n), b).unwrap();
    }
    let meta = String::from_utf8(files.last().unwrap().1.clone()).unwrap();
    let bad = meta.replace("\"quats.webp\"", "\"../quats.webp\"");
    let p = dir.join("meta.json");
    expect(
        bad.as_bytes(),
        p.to_str().unwrap(),
        &["'../quats.webp': not a plain relative file name"],
    );
    let gone = meta.replace("\"quats.webp\"", "\"nothere.webp\"");
    expect(
        gone.as_bytes(),
        p.to_str().unwrap(),
        &["'nothere.webp' is missing"],
    );
    let e = load_bytes(meta.as_bytes(), None, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("needs its path"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn content_decides_the_format_and_a_wrong_extension_warns() {
    let cloud = random_cloud(8, 30, 1);
    let cases: Vec<(Vec<u8>, &str, Format, &str)> = vec![
        (
            spz_of(&cloud, 2),
            "scene.ply",
            Format::Spz,
            "the extension '.ply' says ply, the content is spz",
        ),
        (
            spz_of(&cloud, 4),
            "scene.splat",
            Format::Spz,
            "says splat, the content is spz",
        ),
        (
            packed::sog_bundle(&cloud),
            "scene.splat",
            Format::Sog,
            "says splat, the content is sog",
        ),
        (
            packed::ksplat(&cloud, 2, 8, 25.0),
            "scene.spz",
            Format::Ksplat,
            "says spz, the content is ksplat",
        ),
        (
            to_splat(&cloud),
            "scene.bin",
            Format::Splat,
            "'.bin' names no splat format; the content is splat",
        ),
        (
            splatgl::write::to_inria_ply(&cloud),
            "scene.spz",
            Format::Ply,
            "says spz, the content is ply",
        ),
    ];
    for (bytes, name, format, warning) in cases {
        let l = load_bytes(&bytes, Some(Path::new(name)), &LoadOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(l.report.format, format, "{name}");
        assert_eq!(l.cloud.len(), 30, "{name}");
        let w: Vec<String> = l.report.warnings.iter().map(|w| w.to_string()).collect();
        assert!(w.iter().any(|m| m.contains(warning)), "{name}: {w:?}");
    }
    // The right extension: no warning about it.
    let l = load_bytes(
        &spz(3, 1),
        Some(Path::new("a.spz")),
        &LoadOptions::default(),
    )
    .unwrap();
    assert!(l.report.warnings.is_empty(), "{:?}", l.report.warnings);
}
