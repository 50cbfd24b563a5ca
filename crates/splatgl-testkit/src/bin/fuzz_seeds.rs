//! Writes the fuzz targets' seed corpora (`scripts/fuzz.sh` runs it; nothing is committed):
//! `cargo run -p splatgl-testkit --bin fuzz_seeds -- fuzz/corpus [shared/data/real]`.
//!
//! Small synthetic files covering what the tests cover — every PLY variant (binary little and
//! big endian, ASCII, colours instead of SH, lists before `vertex`, PlayCanvas compressed with
//! SH), glTF/GLB with SH degrees 0–3, every component type the RC allows, stride, sparse
//! accessors, COLOR_0 and node matrices, SPZ-compressed GLB, cameras.json, SPZ v2–v4 with SH
//! 0–3, `.splat`, `.ksplat` of levels 0–2, SOG bundles and a bare meta.json — plus the real
//! files under 64 KiB.
use splatgl::SplatCloud;
use splatgl::synthetic::random_cloud;
use splatgl::write::{Comp, GltfWriteOptions, to_glb, to_gltf, to_inria_ply};
use splatgl::write::{SpzVersion, SpzWriteOptions, to_glb_spz, to_splat, to_spz_with};
use std::path::Path;

/// The tests' independent `.ksplat` and SOG encoders (splatgl writes neither).
use splatgl_testkit::packed;

fn put(dir: &Path, target: &str, name: &str, bytes: &[u8]) {
    let d = dir.join(target);
    std::fs::create_dir_all(&d).expect("corpus folder");
    std::fs::write(d.join(name), bytes).expect("seed");
}

/// The INRIA binary little-endian file as ASCII or big endian (same header, other body).
fn reencode(cloud: &SplatCloud, ascii: bool) -> Vec<u8> {
    let le = to_inria_ply(cloud);
    let end = le.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = String::from_utf8_lossy(&le[..end]).into_owned();
    let fmt = if ascii { "ascii" } else { "binary_big_endian" };
    let mut out = header.replace("binary_little_endian", fmt).into_bytes();
    let values: Vec<f32> = le[end..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let per_row = values.len() / cloud.len().max(1);
    for row in values.chunks(per_row.max(1)) {
        if ascii {
            let line: Vec<String> = row.iter().map(|v| v.to_string()).collect();
            out.extend_from_slice(line.join(" ").as_bytes());
            out.push(b'\n');
        } else {
            row.iter()
                .for_each(|v| out.extend_from_slice(&v.to_be_bytes()));
        }
    }
    out
}

fn ply_seeds(dir: &Path) {
    for degree in 0..=3 {
        let c = random_cloud(3, degree, 2.0, degree as u64);
        put(dir, "ply", &format!("le_sh{degree}.ply"), &to_inria_ply(&c));
    }
    let c = random_cloud(3, 1, 2.0, 9);
    put(dir, "ply", "ascii.ply", &reencode(&c, true));
    put(dir, "ply", "be.ply", &reencode(&c, false));
    let colours = "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n\
        element vertex 2\nproperty float x\nproperty float y\nproperty float z\n\
        property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float opacity\n\
        property float scale_0\nproperty float scale_1\nproperty float scale_2\n\
        property float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\n\
        end_header\n3 0 1 2\n0 0 0 255 0 128 1.5 -2 -2 -2 1 0 0 0\n1 2 3 10 20 30 -1 0 0 0 0.5 0.5 0.5 0.5\n";
    put(dir, "ply", "colours_and_lists.ply", colours.as_bytes());
    put(dir, "ply", "compressed.ply", &compressed_ply());
}

/// A PlayCanvas compressed PLY: one chunk with colour ranges, three splats, degree-1 SH bytes.
fn compressed_ply() -> Vec<u8> {
    let mut h = String::from("ply\nformat binary_little_endian 1.0\nelement chunk 1\n");
    for side in ["min", "max"] {
        for infix in ["", "scale_"] {
            for a in ["x", "y", "z"] {
                h += &format!("property float {side}_{infix}{a}\n");
            }
        }
    }
    for side in ["min", "max"] {
        for c in ["r", "g", "b"] {
            h += &format!("property float {side}_{c}\n");
        }
    }
    h += "element vertex 3\n";
    for p in ["position", "rotation", "scale", "color"] {
        h += &format!("property uint packed_{p}\n");
    }
    h += "element sh 3\n";
    for j in 0..9 {
        h += &format!("property uchar f_rest_{j}\n");
    }
    h += "end_header\n";
    let mut b = h.into_bytes();
    let chunk = [
        -1.0f32, -2.0, -3.0, -4.0, -4.0, -4.0, 1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        1.0, 1.0,
    ];
    chunk
        .iter()
        .for_each(|v| b.extend_from_slice(&v.to_le_bytes()));
    for s in [
        [u32::MAX, 0x1FF7_FDFF, u32::MAX, 0xFF00_FFFF],
        [0, 0x5FF7_FDFF, 0, 0x8080_8080],
        [0x1234_5678, 0xDEAD_BEEF, 0x0F0F_0F0F, 0x7F7F_7F7F],
    ] {
        s.iter().for_each(|v| b.extend_from_slice(&v.to_le_bytes()));
    }
    b.extend((0..27).map(|i| (i * 37 % 256) as u8));
    b
}

fn gltf_seeds(dir: &Path) {
    let variants = [
        GltfWriteOptions::default(),
        GltfWriteOptions {
            rotation: Comp::I8N,
            scale: Comp::U8N,
            opacity: Comp::U8N,
            position: Comp::I16N,
            ..Default::default()
        },
        GltfWriteOptions {
            rotation: Comp::I16N,
            scale: Comp::U16,
            opacity: Comp::U16N,
            padding: 4,
            sparse_opacity: true,
            ..Default::default()
        },
        GltfWriteOptions {
            color0: true,
            node_matrix: Some([
                0.0, 2.0, 0.0, 0.0, -2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 1.0, 2.0, 3.0, 1.0,
            ]),
            ..Default::default()
        },
    ];
    for degree in 0..=3u8 {
        for (v, o) in variants.iter().enumerate() {
            // Normalized positions must lie in [0, 1] / [−1, 1]: a small extent.
            let c = random_cloud(3, degree, 0.9, 10 * degree as u64 + v as u64);
            put(
                dir,
                "gltf_json",
                &format!("sh{degree}_v{v}.gltf"),
                &to_gltf(&c, o),
            );
            put(dir, "glb", &format!("sh{degree}_v{v}.glb"), &to_glb(&c, o));
        }
    }
}

fn packed_seeds(dir: &Path) {
    for degree in 0..=3u8 {
        let c = random_cloud(4, degree, 2.0, 40 + degree as u64);
        for version in [SpzVersion::V2, SpzVersion::V3, SpzVersion::V4] {
            let o = SpzWriteOptions {
                version,
                ..Default::default()
            };
            let name = format!("v{}_sh{degree}.spz", version.number());
            put(dir, "spz", &name, &to_spz_with(&c, &o).expect("spz"));
        }
        put(
            dir,
            "glb",
            &format!("spz_sh{degree}.glb"),
            &to_glb_spz(&c).expect("glb"),
        );
        for level in 0..=2u16 {
            let k = packed::ksplat(&c, level, 3, 5.0);
            put(dir, "ksplat", &format!("l{level}_sh{degree}.ksplat"), &k);
        }
        put(
            dir,
            "sog",
            &format!("sh{degree}.sog"),
            &packed::sog_bundle(&c),
        );
    }
    put(
        dir,
        "splat",
        "four.splat",
        &to_splat(&random_cloud(4, 0, 2.0, 50)),
    );
    let files = packed::sog_files(&random_cloud(4, 1, 2.0, 51));
    put(dir, "sog", "meta.json", &files.last().expect("meta").1);
    put(dir, "sog", "v1.sog", &{
        let f = packed::sog_files_v1(&random_cloud(4, 1, 2.0, 52));
        let m: Vec<(&str, &[u8])> = f.iter().map(|(n, b)| (n.as_str(), b.as_slice())).collect();
        packed::zip_stored(&m)
    });
}

fn cameras_seeds(dir: &Path) {
    let one = r#"{"id": 0, "img_name": "a", "width": 64, "height": 48, "position": [0.5, -1, 3],
        "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "fx": 50.5, "fy": 51}"#;
    let two = r#"{"id": 1, "img_name": "b", "width": 640, "height": 480, "position": [1e3, 0, -2],
        "rotation": [[0, -1, 0], [1, 0, 0], [0, 0, 1]], "fx": 500, "fy": 500, "cx": 320.5, "cy": 240}"#;
    put(
        dir,
        "cameras_json",
        "one.json",
        format!("[{one}]").as_bytes(),
    );
    put(
        dir,
        "cameras_json",
        "two.json",
        format!("[{one}, {two}]").as_bytes(),
    );
    put(dir, "cameras_json", "empty.json", b"[]");
}

/// Tilesets over the fuzz target's `c.ply` (fuzz/src/lib.rs), and URIs that try to leave.
fn tileset_seeds(dir: &Path) {
    let tile = |uri: &str| {
        format!(
            r#"{{"asset": {{"version": "1.1"}}, "geometricError": 10, "root": {{"boundingVolume":
            {{"box": [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]}}, "geometricError": 1, "refine": "ADD",
            "content": {{"uri": "{uri}"}}, "children": [{{"boundingVolume": {{"box": [0, 0, 0, 1, 0,
            0, 0, 1, 0, 0, 0, 1]}}, "geometricError": 0, "content": {{"uri": "./c.ply"}}}}]}}}}"#
        )
    };
    for (i, uri) in [
        "c.ply",
        "%2e%2e/secret.ply",
        "..%2fsecret.ply",
        "sub/../../secret.ply",
    ]
    .iter()
    .enumerate()
    {
        put(
            dir,
            "tileset",
            &format!("tileset{i}.json"),
            tile(uri).as_bytes(),
        );
        put(dir, "tileset", &format!("uri{i}"), uri.as_bytes());
    }
    let lod = r#"{"lodLevels": 1, "filenames": ["c.ply"], "tree": {"bound": {"min": [0, 0, 0],
        "max": [1, 1, 1]}, "lods": {"0": {"file": 0, "offset": 0, "count": 4}}}}"#;
    put(dir, "tileset", "lod-meta.json", lod.as_bytes());
}

/// Real files small enough to be fast seeds, by the target their format belongs to.
fn real_seeds(dir: &Path, real: &Path) {
    let Ok(entries) = std::fs::read_dir(real) else {
        eprintln!("no real files at {} (skipped)", real.display());
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        let small = e
            .metadata()
            .is_ok_and(|m| m.is_file() && m.len() <= 64 << 10);
        let target = match p.extension().and_then(|x| x.to_str()) {
            Some("ply") => "ply",
            Some("gltf") => "gltf_json",
            Some("glb") => "glb",
            Some(ext @ ("spz" | "splat" | "ksplat" | "sog")) => ext,
            _ => continue,
        };
        if small && let Ok(bytes) = std::fs::read(&p) {
            put(
                dir,
                target,
                &format!("real_{}", e.file_name().to_string_lossy()),
                &bytes,
            );
        }
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(out) = args.next() else {
        eprintln!("usage: fuzz_seeds CORPUS_DIR [REAL_DATA_DIR]");
        std::process::exit(2);
    };
    let dir = Path::new(&out);
    ply_seeds(dir);
    gltf_seeds(dir);
    cameras_seeds(dir);
    tileset_seeds(dir);
    packed_seeds(dir);
    // The structure-aware target decodes any bytes; a few fixed ones start it off.
    for (i, seed) in [&[0u8; 16][..], &[7; 64], &(0..=255).collect::<Vec<u8>>()]
        .iter()
        .enumerate()
    {
        put(dir, "gltf_struct", &format!("seed{i}"), seed);
    }
    if let Some(real) = args.next() {
        real_seeds(dir, Path::new(&real));
    }
}
