//! Hostile inputs for the renderer side, found in review: each ends in an error or a sane
//! image, never a panic, an abort or an image painted by one broken splat.

use glam::Vec3;
use splatgl::SplatCloud;
use splatgl::camera::Camera;
use splatgl::image::Image;
use splatgl::reference::{RenderOptions, render};

fn crc32(data: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

#[test]
fn png_header_claiming_a_huge_image_is_rejected_before_allocation() {
    let mut png = Image::filled(1, 1, [0.5; 4])
        .encode_png(splatgl::image::PngDepth::Eight, false)
        .unwrap();
    // IHDR data starts at byte 16 (8 signature + 4 length + 4 type): width, height.
    png[16..20].copy_from_slice(&(1u32 << 30).to_be_bytes());
    png[20..24].copy_from_slice(&(1u32 << 30).to_be_bytes());
    let crc = crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    assert!(Image::decode_png(&png).is_err());
}

#[test]
fn pfm_with_crlf_and_bad_scale() {
    let mut ok = b"PF\r\n1 1\r\n-1.0\r\n".to_vec();
    for v in [0.25f32, 0.5, 0.75] {
        ok.extend_from_slice(&v.to_le_bytes());
    }
    let img = Image::decode_pfm(&ok).unwrap();
    assert_eq!(img.pixels[0][..3], [0.25, 0.5, 0.75]);
    let mut nan = b"PF\n1 1\nnan\n".to_vec();
    nan.extend_from_slice(&[0; 12]);
    assert!(Image::decode_pfm(&nan).is_err());
}

fn one_splat(scale: [f32; 3], rot: [f32; 4]) -> SplatCloud {
    let mut c = SplatCloud::new(0);
    c.push([0.0; 3], scale, rot, 0.9, &[[1.0, 0.0, 0.0]]);
    c
}

#[test]
fn end_on_needle_does_not_paint_the_frame() {
    // Long axis (z, 1e9) along the view ray: rounding can make Σ' negative definite.
    let cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 0.8, 48, 32);
    for k in 0..50 {
        let t = k as f32 * 0.001;
        let q = glam::Quat::from_euler(glam::EulerRot::XYZ, t, -t, 0.0).to_array();
        let img = render(
            &one_splat([0.01, 0.01, 1e9], q),
            &cam,
            &RenderOptions::default(),
        );
        let covered = img.pixels.iter().filter(|p| p[3] > 0.5).count();
        assert!(
            covered < img.pixels.len(),
            "rotation {k}: the whole frame is painted"
        );
    }
}

#[test]
fn degenerate_cameras_do_not_panic() {
    let cloud = one_splat([0.1; 3], [0.0, 0.0, 0.0, 1.0]);
    let mut cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 0.8, 16, 16);
    for (w, h, fx, fy) in [
        (0, 0, 10.0, 10.0),
        (16, 16, 0.0, 0.0),
        (16, 16, f32::NAN, 1.0),
        (16, 16, -5.0, 5.0),
    ] {
        cam.width = w;
        cam.height = h;
        cam.fx = fx;
        cam.fy = fy;
        let img = render(&cloud, &cam, &RenderOptions::default());
        assert_eq!(img.pixels.len(), (w * h) as usize);
    }
}

#[test]
fn quantized_sort_places_infinities() {
    use splatgl::sort::{Precision, Sorter};
    let mut s = Sorter::new().with_precision(Precision::Quantized { bits: 16 });
    assert_eq!(s.sort_keys(&[1.0, f32::INFINITY]), &[1, 0]);
    assert_eq!(s.sort_keys(&[f32::NEG_INFINITY, 1.0]), &[1, 0]);
}

#[test]
fn comparing_an_image_with_itself_is_identical_even_with_inf() {
    let mut a = Image::filled(2, 2, [0.5; 4]);
    a.pixels[1] = [f32::INFINITY, f32::NAN, 0.0, 1.0];
    let c = splatgl::compare::compare(&a, &a, 1.0 / 255.0).unwrap();
    assert_eq!(c.max_abs, 0.0);
}
