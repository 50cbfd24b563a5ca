//! PLY variants: big-endian, ASCII, other property types, u8 colours, extra properties and
//! elements before `vertex` all decode to the same splats as the little-endian float file.

use crate::common;
use common::random_cloud;
use splatgl::SplatCloud;
use splatgl::load::{LoadOptions, load_bytes};
use std::path::Path;

fn load(bytes: &[u8]) -> SplatCloud {
    load_bytes(bytes, Some(Path::new("t.ply")), &LoadOptions::default())
        .expect("loads")
        .cloud
}

/// Splits an INRIA LE file into (property names, rows of f32).
fn parse_le(bytes: &[u8]) -> (Vec<String>, Vec<Vec<f32>>) {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    let props: Vec<String> = header
        .lines()
        .filter_map(|l| l.strip_prefix("property float "))
        .map(str::to_owned)
        .collect();
    let floats: Vec<f32> = bytes[end..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let rows = floats.chunks(props.len()).map(<[f32]>::to_vec).collect();
    (props, rows)
}

fn header(format: &str, n: usize, props: &[(&str, &str)]) -> String {
    let mut h = format!("ply\nformat {format} 1.0\ncomment made by a test\nelement vertex {n}\n");
    for (t, p) in props {
        h += &format!("property {t} {p}\n");
    }
    h + "end_header\n"
}

#[test]
fn big_endian_and_ascii_match_little_endian() {
    let c = random_cloud(40, 2, 5.0, 5);
    let le = splatgl::write::to_inria_ply(&c);
    let want = load(&le);
    let (props, rows) = parse_le(&le);
    let typed: Vec<(&str, &str)> = props.iter().map(|p| ("float", p.as_str())).collect();

    let mut be = header("binary_big_endian", rows.len(), &typed).into_bytes();
    for r in &rows {
        for v in r {
            be.extend_from_slice(&v.to_be_bytes());
        }
    }
    assert!(load(&be) == want, "big endian differs");

    let mut ascii = header("ascii", rows.len(), &typed);
    for r in &rows {
        let line: Vec<String> = r.iter().map(|v| format!("{v:?}")).collect();
        ascii += &line.join(" ");
        ascii += "\n";
    }
    assert!(load(ascii.as_bytes()) == want, "ASCII differs");
    // Written on Windows: CRLF line ends in the header and the body.
    let crlf = ascii.replace('\n', "\r\n");
    assert!(
        load(crlf.as_bytes()) == want,
        "ASCII with CRLF line ends differs"
    );
}

#[test]
fn doubles_extra_properties_and_preceding_elements() {
    let c = random_cloud(10, 0, 5.0, 6);
    let want = load(&splatgl::write::to_inria_ply(&c));
    let (props, rows) = parse_le(&splatgl::write::to_inria_ply(&c));
    // A leading element with a list, every value as double, plus normals and a uchar extra.
    let mut h = String::from("ply\nformat binary_little_endian 1.0\nelement camera 2\n");
    h += "property list uchar int ids\nproperty float fov\n";
    h += &format!("element vertex {}\n", rows.len());
    for p in &props {
        h += &format!("property double {p}\n");
    }
    h += "property float nx\nproperty uchar flag\nend_header\n";
    let mut b = h.into_bytes();
    for k in 0..2u8 {
        b.push(k); // list of k ints
        for j in 0..k as i32 {
            b.extend_from_slice(&j.to_le_bytes());
        }
        b.extend_from_slice(&1.5f32.to_le_bytes());
    }
    for r in &rows {
        for v in r {
            b.extend_from_slice(&(*v as f64).to_le_bytes());
        }
        b.extend_from_slice(&0.0f32.to_le_bytes());
        b.push(7);
    }
    let got = load(&b);
    assert_eq!(got.len(), want.len());
    for i in 0..got.len() {
        assert_eq!(got.positions[i], want.positions[i]);
        assert_eq!(got.sh_of(i), want.sh_of(i));
        for k in 0..3 {
            assert!((got.scales[i][k] - want.scales[i][k]).abs() <= 1e-6 * want.scales[i][k]);
        }
    }
}

#[test]
fn u8_colours_instead_of_f_dc() {
    let props = [
        ("float", "x"),
        ("float", "y"),
        ("float", "z"),
        ("uchar", "red"),
        ("uchar", "green"),
        ("uchar", "blue"),
        ("float", "opacity"),
        ("float", "scale_0"),
        ("float", "scale_1"),
        ("float", "scale_2"),
        ("float", "rot_0"),
        ("float", "rot_1"),
        ("float", "rot_2"),
        ("float", "rot_3"),
    ];
    let mut b = header("binary_little_endian", 1, &props).into_bytes();
    for v in [1.0f32, 2.0, 3.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&[255, 0, 128]);
    for v in [0.0f32, -1.0, -1.0, -1.0, 2.0, 0.0, 0.0, 0.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    let c = load(&b);
    let colour = splatgl::sh::eval_color(c.sh_of(0), 0, [0.0, 0.0, 1.0]);
    assert!((colour[0] - 1.0).abs() < 1e-6 && colour[1].abs() < 1e-6);
    assert!((colour[2] - 128.0 / 255.0).abs() < 1e-6);
    assert_eq!(c.opacities[0], 0.5, "logit 0");
    assert_eq!(
        c.rotations[0],
        [0.0, 0.0, 0.0, 1.0],
        "w-first (2,0,0,0) normalised"
    );
}

/// A hand-packed PlayCanvas compressed PLY: one chunk, two splats, every field decoded to the
/// value the packing defines.
#[test]
fn compressed_ply_fields() {
    let chunk_props = [
        "min_x",
        "min_y",
        "min_z",
        "max_x",
        "max_y",
        "max_z",
        "min_scale_x",
        "min_scale_y",
        "min_scale_z",
        "max_scale_x",
        "max_scale_y",
        "max_scale_z",
        "min_r",
        "min_g",
        "min_b",
        "max_r",
        "max_g",
        "max_b",
    ];
    let mut h = String::from("ply\nformat binary_little_endian 1.0\nelement chunk 1\n");
    for p in chunk_props {
        h += &format!("property float {p}\n");
    }
    h += "element vertex 2\n";
    for p in [
        "packed_position",
        "packed_rotation",
        "packed_scale",
        "packed_color",
    ] {
        h += &format!("property uint {p}\n");
    }
    h += "end_header\n";
    let mut b = h.into_bytes();
    let chunk = [
        -1.0f32, -2.0, -3.0, 1.0, 2.0, 3.0, // box
        -4.0, -4.0, -4.0, 0.0, 0.0, 0.0, // log scale range
        0.0, 0.0, 0.0, 1.0, 1.0, 1.0, // colour range
    ];
    for v in chunk {
        b.extend_from_slice(&v.to_le_bytes());
    }
    // Splat 0: position at the max corner, identity (w = rot_0 largest, others ≈ 0), scale at the
    // range top (exp 0 = 1), colour (255, 0, 255) with opacity 255.
    let half10 = 511u32; // (511/1023 − 0.5)·√2 ≈ −0.0007
    let identity = (half10 << 20) | (half10 << 10) | half10; // index 0 = rot_0 = w
    let s0 = [u32::MAX, identity, u32::MAX, 0xFF00_FFFF];
    // Splat 1: min corner, x largest (a 180° turn about x), scale range bottom (exp −4), grey.
    let x_turn = (1 << 30) | (half10 << 20) | (half10 << 10) | half10;
    let s1 = [0u32, x_turn, 0, 0x8080_8080];
    for v in s0.iter().chain(&s1) {
        b.extend_from_slice(&v.to_le_bytes());
    }
    let c = load(&b);
    assert_eq!(c.len(), 2);
    assert_eq!(c.positions[0], [1.0, 2.0, 3.0]);
    assert_eq!(c.positions[1], [-1.0, -2.0, -3.0]);
    assert!(c.scales[0].iter().all(|s| (s - 1.0).abs() < 1e-6));
    assert!(
        c.scales[1]
            .iter()
            .all(|s| (s - (-4.0f32).exp()).abs() < 1e-6)
    );
    let q0 = c.rotations[0];
    assert!((q0[3].abs() - 1.0).abs() < 1e-5, "identity: {q0:?}"); // xyzw, w ≈ ±1
    let q1 = c.rotations[1];
    assert!((q1[0].abs() - 1.0).abs() < 1e-5, "x turn: {q1:?}");
    assert_eq!(c.opacities[0], 1.0);
    assert!((c.opacities[1] - 128.0 / 255.0).abs() < 1e-6);
    let colour = splatgl::sh::eval_color(c.sh_of(0), 0, [0.0, 0.0, 1.0]);
    assert!(
        (colour[0] - 1.0).abs() < 1e-5 && colour[1].abs() < 1e-5 && (colour[2] - 1.0).abs() < 1e-5
    );
}

#[test]
fn trainer_normals_are_skipped_like_any_extra_property() {
    let cloud = random_cloud(500, 3, 5.0, 12);
    let plain = splatgl::write::to_inria_ply(&cloud);
    let with = splatgl::write::to_inria_ply_with_normals(&cloud);
    assert_eq!(
        with.len() - plain.len(),
        500 * 12 + 3 * "property float nx\n".len()
    );
    assert_eq!(load(&with), load(&plain));
}
