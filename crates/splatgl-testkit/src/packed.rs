//! Test-side encoders for the formats splatgl reads but does not write: a stored zip, a SOG
//! (version 2) bundle and a `.ksplat` of any compression level. Written from the format
//! descriptions in docs/formats.md, so the readers are checked against an independent encoder.

use splatgl::SplatCloud;

/// The header of a binary little-endian INRIA PLY of `n` splats at SH degree 0 (14 floats a
/// row: position, `f_dc`, opacity logit, log scales, quaternion w x y z), for generators that
/// write the rows themselves.
pub fn ply_header_sh0(n: u64) -> String {
    let mut h = format!("ply\nformat binary_little_endian 1.0\nelement vertex {n}\n");
    for p in [
        "x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2",
        "rot_0", "rot_1", "rot_2", "rot_3",
    ] {
        h += &format!("property float {p}\n");
    }
    h + "end_header\n"
}
/// A zip with stored (method 0) members.
pub fn zip_stored(members: &[(&str, &[u8])]) -> Vec<u8> {
    let (mut out, mut central) = (Vec::new(), Vec::new());
    for (name, data) in members {
        let crc = crc32fast::hash(data);
        let off = out.len() as u32;
        let common = |v: &mut Vec<u8>| {
            v.extend_from_slice(&[20, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
            v.extend_from_slice(&crc.to_le_bytes());
            v.extend_from_slice(&(data.len() as u32).to_le_bytes());
            v.extend_from_slice(&(data.len() as u32).to_le_bytes());
            v.extend_from_slice(&(name.len() as u16).to_le_bytes());
            v.extend_from_slice(&0u16.to_le_bytes());
        };
        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        common(&mut out);
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(data);
        central.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        central.extend_from_slice(&20u16.to_le_bytes());
        common(&mut central);
        central.extend_from_slice(&[0; 6]); // comment length, disk, internal attributes
        central.extend_from_slice(&0u32.to_le_bytes()); // external attributes
        central.extend_from_slice(&off.to_le_bytes());
        central.extend_from_slice(name.as_bytes());
    }
    let cd_off = out.len() as u32;
    out.extend_from_slice(&central);
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    out.extend_from_slice(&[0; 4]);
    let n = (members.len() as u16).to_le_bytes();
    out.extend_from_slice(&[n[0], n[1], n[0], n[1]]);
    out.extend_from_slice(&(central.len() as u32).to_le_bytes());
    out.extend_from_slice(&cd_off.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    out
}

/// Lossless WebP of an RGBA image.
pub fn webp(rgba: &[u8], w: u32, h: u32) -> Vec<u8> {
    let mut out = Vec::new();
    image_webp::WebPEncoder::new(&mut out)
        .encode(rgba, w, h, image_webp::ColorType::Rgba8)
        .unwrap();
    out
}

fn log_t(x: f32) -> f64 {
    (x as f64).signum() * (x.abs() as f64).ln_1p()
}

/// A 256-entry linear codebook over [lo, hi] and the nearest index of `v`.
fn book(lo: f32, hi: f32) -> Vec<f32> {
    (0..256)
        .map(|k| lo + (hi - lo) * k as f32 / 255.0)
        .collect()
}
fn nearest(book: &[f32], v: f32) -> u8 {
    let step = (book[255] - book[0]).max(1e-12) / 255.0;
    ((v - book[0]) / step).round().clamp(0.0, 255.0) as u8
}

/// The SOG v2 files of `c` (name, bytes), meta.json last. One palette entry per splat (so
/// SH is only quantised by its codebook), codebooks linear over each attribute's range.
pub fn sog_files(c: &SplatCloud) -> Vec<(String, Vec<u8>)> {
    sog_version(c, false)
}

/// Logit range of the legacy (v1) SOG opacity byte written here.
pub const SOG_V1_LOGIT: f32 = 6.0;

/// The same splats as a legacy version-1 SOG: no `version`, `means.shape`, linear ranges
/// (`mins`/`maxs`) instead of codebooks, the opacity as a logit in [−6, 6], the palette size
/// implied by the centroid texture.
pub fn sog_files_v1(c: &SplatCloud) -> Vec<(String, Vec<u8>)> {
    sog_version(c, true)
}

fn sog_version(c: &SplatCloud, v1: bool) -> Vec<(String, Vec<u8>)> {
    let n = c.len();
    let w = ((n as f64).sqrt().ceil() as u32).max(1);
    let h = (n as u32).div_ceil(w).max(1);
    let texels = (w * h) as usize;
    let mut tex = vec![vec![0u8; 4 * texels]; 5];
    let (mut mins, mut maxs) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in &c.positions {
        for a in 0..3 {
            mins[a] = mins[a].min(log_t(p[a]));
            maxs[a] = maxs[a].max(log_t(p[a]));
        }
    }
    let (slo, shi) = value_range(n, &|i| c.scales[i].map(f32::ln).to_vec());
    let (clo, chi) = value_range(n, &|i| c.sh_of(i)[0].to_vec());
    let (sbook, cbook) = (book(slo, shi), book(clo, chi));
    for i in 0..n {
        let o = 4 * i;
        for a in 0..3 {
            let v = ((log_t(c.positions[i][a]) - mins[a]) / (maxs[a] - mins[a]).max(1e-12)
                * 65535.0)
                .round() as u32;
            tex[0][o + a] = v as u8;
            tex[1][o + a] = (v >> 8) as u8;
            tex[3][o + a] = nearest(&sbook, c.scales[i][a].ln());
            tex[4][o + a] = nearest(&cbook, c.sh_of(i)[0][a]);
        }
        tex[2][o..o + 4].copy_from_slice(&quat_bytes(c.rotations[i]));
        tex[0][o + 3] = 255;
        tex[1][o + 3] = 255;
        tex[3][o + 3] = 255;
        tex[4][o + 3] = if v1 {
            let logit = (c.opacities[i] / (1.0 - c.opacities[i])).ln();
            ((logit + SOG_V1_LOGIT) / (2.0 * SOG_V1_LOGIT) * 255.0)
                .round()
                .clamp(0.0, 255.0) as u8
        } else {
            (c.opacities[i] * 255.0).round() as u8
        };
    }
    let names = [
        "means_l.webp",
        "means_u.webp",
        "quats.webp",
        "scales.webp",
        "sh0.webp",
    ];
    let mut files: Vec<(String, Vec<u8>)> = names
        .iter()
        .zip(&tex)
        .map(|(name, t)| (name.to_string(), webp(t, w, h)))
        .collect();
    let mut meta = serde_json::json!({
        "version": 2, "count": n,
        "means": {"mins": mins, "maxs": maxs, "files": ["means_l.webp", "means_u.webp"]},
        "scales": {"codebook": sbook, "files": ["scales.webp"]},
        "quats": {"files": ["quats.webp"]},
        "sh0": {"codebook": cbook, "files": ["sh0.webp"]},
    });
    if c.sh_degree > 0 {
        meta["shN"] = sh_rest(c, (w, h), v1, &mut files);
    }
    if v1 {
        let m = meta.as_object_mut().unwrap();
        m.remove("version");
        m.remove("count");
        m["means"]["shape"] = serde_json::json!([n, 3]);
        m["scales"] = serde_json::json!({"mins": [slo, slo, slo], "maxs": [shi, shi, shi], "files": ["scales.webp"]});
        let l = SOG_V1_LOGIT;
        m["sh0"] = serde_json::json!({"mins": [clo, clo, clo, -l], "maxs": [chi, chi, chi, l], "files": ["sh0.webp"]});
    }
    files.push(("meta.json".into(), meta.to_string().into_bytes()));
    files
}

/// The smallest and largest of the values `f(i)` gives for `i < n` (the largest at least
/// 10⁻⁶ above the smallest).
fn value_range(n: usize, f: &dyn Fn(usize) -> Vec<f32>) -> (f32, f32) {
    let all: Vec<f32> = (0..n).flat_map(f).collect();
    let lo = all.iter().copied().fold(f32::MAX, f32::min);
    (
        lo,
        all.iter().copied().fold(f32::MIN, f32::max).max(lo + 1e-6),
    )
}

/// A SOG quats texel: the three smallest of (w, x, y, z), signed by the largest, and the
/// largest's index in alpha (252 + index).
fn quat_bytes([x, y, z, qw]: [f32; 4]) -> [u8; 4] {
    let q = [qw, x, y, z];
    let big = (0..4)
        .max_by(|&a, &b| q[a].abs().total_cmp(&q[b].abs()))
        .unwrap();
    let s = if q[big] < 0.0 { -1.0 } else { 1.0 };
    let mut out = [0u8; 4];
    let others = q.iter().enumerate().filter(|(j, _)| *j != big);
    for (k, (_, v)) in others.enumerate() {
        out[k] = ((v * s * std::f32::consts::SQRT_2 * 0.5 + 0.5) * 255.0).round() as u8;
    }
    out[3] = 252 + big as u8;
    out
}

/// The higher SH bands as a palette of one entry per splat (centroids and labels textures,
/// added to `files`); returns `meta.shN` (v1's form with `v1`).
fn sh_rest(
    c: &SplatCloud,
    (w, h): (u32, u32),
    v1: bool,
    files: &mut Vec<(String, Vec<u8>)>,
) -> serde_json::Value {
    let n = c.len();
    let k = c.coeffs_per_splat() - 1;
    let (lo, hi) = value_range(n, &|i| c.sh_of(i)[1..].iter().flatten().copied().collect());
    let shbook = book(lo, hi);
    let rows = n.div_ceil(64).max(1);
    let mut cent = vec![255u8; 4 * 64 * k * rows];
    let mut labels = vec![255u8; 4 * (w * h) as usize];
    for i in 0..n {
        for j in 0..k {
            let t = 4 * ((i / 64) * 64 * k + (i % 64) * k + j);
            for ch in 0..3 {
                cent[t + ch] = nearest(&shbook, c.sh_of(i)[1 + j][ch]);
            }
        }
        labels[4 * i] = i as u8;
        labels[4 * i + 1] = (i >> 8) as u8;
        labels[4 * i + 2] = 0;
    }
    files.push((
        "shN_centroids.webp".into(),
        webp(&cent, 64 * k as u32, rows as u32),
    ));
    files.push(("shN_labels.webp".into(), webp(&labels, w, h)));
    if v1 {
        return serde_json::json!({"mins": lo, "maxs": hi,
            "files": ["shN_centroids.webp", "shN_labels.webp"]});
    }
    serde_json::json!({"count": n, "bands": c.sh_degree, "codebook": shbook,
        "files": ["shN_centroids.webp", "shN_labels.webp"]})
}

/// A bundled `.sog` of `c`.
pub fn sog_bundle(c: &SplatCloud) -> Vec<u8> {
    let files = sog_files(c);
    let members: Vec<(&str, &[u8])> = files
        .iter()
        .map(|(n, b)| (n.as_str(), b.as_slice()))
        .collect();
    zip_stored(&members)
}

fn f16(v: f32) -> [u8; 2] {
    splatgl::load::codec::f32_to_f16(v).to_le_bytes()
}

/// A one-section `.ksplat` of `c` at compression `level` (SH degree ≤ 2 kept), buckets of
/// `bucket` splats along the input order with centres at their first splat, block size
/// `block`, the last bucket partial.
pub fn ksplat(c: &SplatCloud, level: u16, bucket: usize, block: f32) -> Vec<u8> {
    let n = c.len();
    let degree = c.sh_degree.min(2);
    let (full, partial) = (n / bucket, usize::from(!n.is_multiple_of(bucket)));
    let buckets = if level == 0 { 0 } else { full + partial };
    let mut out = vec![0u8; 4096 + 1024];
    out[1] = 1;
    out[4..8].copy_from_slice(&1u32.to_le_bytes());
    out[8..12].copy_from_slice(&1u32.to_le_bytes());
    out[12..16].copy_from_slice(&(n as u32).to_le_bytes());
    out[16..20].copy_from_slice(&(n as u32).to_le_bytes());
    out[20..22].copy_from_slice(&level.to_le_bytes());
    out[36..40].copy_from_slice(&(-2.0f32).to_le_bytes());
    out[40..44].copy_from_slice(&2.0f32.to_le_bytes());
    let s = 4096;
    let put32 = |o: &mut Vec<u8>, at: usize, v: u32| {
        o[s + at..s + at + 4].copy_from_slice(&v.to_le_bytes())
    };
    put32(&mut out, 0, n as u32);
    put32(&mut out, 4, n as u32);
    put32(&mut out, 8, bucket as u32);
    put32(&mut out, 12, buckets as u32);
    out[s + 16..s + 20].copy_from_slice(&block.to_le_bytes());
    out[s + 20..s + 22].copy_from_slice(&(if level == 0 { 0u16 } else { 12 }).to_le_bytes());
    put32(&mut out, 24, 32767);
    put32(&mut out, 32, if level == 0 { 0 } else { full as u32 });
    put32(&mut out, 36, if level == 0 { 0 } else { partial as u32 });
    out[s + 40..s + 42].copy_from_slice(&(degree as u16).to_le_bytes());
    if level > 0 {
        if partial == 1 {
            out.extend_from_slice(&((n % bucket) as u32).to_le_bytes());
        }
        for b in 0..buckets {
            for v in c.positions[b * bucket] {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    for i in 0..n {
        ksplat_row(&mut out, c, i, (level, bucket, block), degree);
    }
    out
}

/// Splat `i` of a `.ksplat` section at compression `level` (buckets of `bucket` splats,
/// block size `block`), SH up to `degree`, appended to `out`.
fn ksplat_row(
    out: &mut Vec<u8>,
    c: &SplatCloud,
    i: usize,
    (level, bucket, block): (u16, usize, f32),
    degree: u8,
) {
    let sh_vals = ((degree as usize + 1).pow(2) - 1) * 3;
    let [x, y, z, w] = c.rotations[i];
    if level == 0 {
        for v in c.positions[i]
            .iter()
            .chain(&c.scales[i])
            .chain(&[w, x, y, z])
        {
            out.extend_from_slice(&v.to_le_bytes());
        }
    } else {
        let centre = c.positions[(i / bucket) * bucket];
        let f = 32767.0 / (0.5 * block);
        for (p, c) in c.positions[i].iter().zip(centre) {
            let v = ((p - c) * f).round() + 32767.0;
            out.extend_from_slice(&(v.clamp(0.0, 65535.0) as u16).to_le_bytes());
        }
        for v in c.scales[i].iter().chain(&[w, x, y, z]) {
            out.extend_from_slice(&f16(*v));
        }
    }
    for ch in 0..3 {
        out.push(
            (splatgl::sh::color_from_dc(c.sh_of(i)[0][ch]) as f32 * 255.0)
                .clamp(0.0, 255.0)
                .floor() as u8,
        );
    }
    out.push((c.opacities[i] * 255.0).floor() as u8);
    let mut vals = Vec::with_capacity(sh_vals);
    for l in 1..=degree as usize {
        for ch in 0..3 {
            for j in 0..2 * l + 1 {
                vals.push(c.sh_of(i)[l * l + j][ch]);
            }
        }
    }
    for v in vals {
        match level {
            0 => out.extend_from_slice(&v.to_le_bytes()),
            1 => out.extend_from_slice(&f16(v)),
            _ => out.push((((v + 2.0) / 4.0 * 255.0).floor()).clamp(0.0, 255.0) as u8),
        }
    }
}

/// An SPZ file read from memory with its numbers taken to be in `axes`.
pub fn read_spz(bytes: &[u8], axes: splatgl::load::spz::SpzAxes) -> SplatCloud {
    let opts = splatgl::load::LoadOptions {
        spz_axes: axes,
        ..Default::default()
    };
    splatgl::load::load_bytes(bytes, None, &opts)
        .unwrap_or_else(|e| panic!("{e}"))
        .cloud
}

/// `c` with its SH cut to degree `degree` (what a writer that keeps fewer bands stores).
pub fn truncate_sh(c: &SplatCloud, degree: u8) -> SplatCloud {
    let mut out = SplatCloud::with_capacity(degree, c.len());
    let k = splatgl::cloud::sh_coeff_count(degree);
    for i in 0..c.len() {
        let (p, s, q, o) = (c.positions[i], c.scales[i], c.rotations[i], c.opacities[i]);
        out.push(p, s, q, o, &c.sh_of(i)[..k]);
    }
    out.meta = c.meta.clone();
    out
}

/// The JSON and BIN chunks of a GLB (test input, well formed).
pub fn glb_chunks(glb: &[u8]) -> (serde_json::Value, Vec<u8>) {
    let u32_at = |o: usize| u32::from_le_bytes(glb[o..o + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let doc = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    let bin = glb[bin_at + 8..bin_at + 8 + u32_at(bin_at)].to_vec();
    (doc, bin)
}

/// A GLB from its chunks (BIN padded to 4 bytes).
pub fn glb_of(doc: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    splatgl::write::glb_bytes(doc, bin)
}
