//! Paged GPU storage (`SplatRenderer::allocate_pages` / `write_page`, `tiles::pages`), what
//! the viewer streams tilesets into: tiles written page by page, in any order, into pages an
//! evicted tile held before, draw exactly what the same tiles uploaded whole draw; a new
//! selection writes only its new tiles; bad writes are errors.

use crate::common;

use common::gl::*;
use splatgl::gl::{ColorFormat, GlError, PAGE_SPLATS, ReadbackTarget, SplatRenderer};
use splatgl::sort::Sorter;
use splatgl::tiles::pages::PageTable;

const W: u32 = 96;
const H: u32 = 72;
const VIEWPORT: [i32; 4] = [0, 0, W as i32, H as i32];

/// Five "tiles" of one random cloud, sizes crossing page boundaries.
fn tiles() -> Vec<(String, SplatCloud)> {
    let cloud = synthetic::random_cloud(33_292, 2, 0.6, 8);
    let sizes = [9000, 100, 8192, 7000, 9000];
    let mut start = 0u32;
    sizes
        .iter()
        .enumerate()
        .map(|(k, &n)| {
            let idx: Vec<u32> = (start..start + n).collect();
            start += n;
            (format!("t{k}"), cloud.select(&idx))
        })
        .collect()
}

fn camera() -> Camera {
    look_at_fov_deg(Vec3::new(0.3, -0.2, 1.8), Vec3::ZERO, 50.0, W, H)
}

/// `order` drawn into a fresh RGBA8 target.
fn image(gl: &glow::Context, r: &mut SplatRenderer, order: &[u32]) -> Image {
    let mut target = ReadbackTarget::new(gl, W, H, ColorFormat::Rgba8, None).unwrap();
    target.bind(gl).unwrap();
    // SAFETY: clears the target just bound.
    unsafe {
        use glow::HasContext;
        gl.clear_color(0.0, 0.0, 0.0, 0.0);
        gl.clear(glow::COLOR_BUFFER_BIT);
    }
    let cam = camera();
    r.draw_with_matrices(gl, cam.gl_view(), cam.gl_projection(), VIEWPORT, order)
        .unwrap();
    let img = target.read_image(gl).unwrap();
    target.destroy(gl);
    img
}

/// The selection's tiles merged, and its back-to-front order.
fn merged(sel: &[&(String, SplatCloud)]) -> (SplatCloud, Vec<u32>) {
    let mut all = SplatCloud::new(0);
    for (_, c) in sel {
        all.append(c.clone());
    }
    let order = Sorter::new()
        .sort_by_distance(&all.positions, camera().eye().to_array())
        .to_vec();
    (all, order)
}

/// Places `sel` in `table`, writes its new pages (last first), returns the order as slots.
fn place(
    gl: &glow::Context,
    r: &mut SplatRenderer,
    table: &mut PageTable,
    sel: &[&(String, SplatCloud)],
    order: &[u32],
) -> (Vec<u32>, usize) {
    let ids: Vec<(&str, usize)> = sel.iter().map(|(p, c)| (p.as_str(), c.len())).collect();
    let pl = table.place(&ids).expect("the selection fits");
    for w in pl.writes.iter().rev() {
        r.write_page(gl, w.page as usize, &sel[w.tile].1, w.first)
            .unwrap();
    }
    let slots = order.iter().map(|&i| pl.slots[i as usize]).collect();
    (slots, pl.writes.len())
}

#[test]
fn paged_tiles_draw_exactly_what_the_same_tiles_uploaded_whole_draw() {
    let Some(ctx) = current_context() else { return };
    let gl = ctx.gl();
    let t = tiles();
    let mut whole = SplatRenderer::new(gl).unwrap();
    whole.settings_mut().depth_test = false;
    let mut paged = SplatRenderer::new(gl).unwrap();
    paged.settings_mut().depth_test = false;
    paged
        .allocate_pages(gl, 6, 2, ColorSpace::default())
        .unwrap();
    assert_eq!(paged.pages(), 6);
    let mut table = PageTable::new(6);

    // Tiles 0..3 (5 of the 6 pages), then 3, 1, 4: tile 4 (2 pages) takes the free page and
    // one of tile 0's (evicted, least recently used); 1 and 3 stay where they were.
    for (sel, new_pages) in [
        (vec![&t[0], &t[1], &t[2], &t[3]], 5),
        (vec![&t[3], &t[1], &t[4]], 2),
    ] {
        let (all, order) = merged(&sel);
        whole.upload(gl, &all).unwrap();
        let want = image(gl, &mut whole, &order);
        let (slots, written) = place(gl, &mut paged, &mut table, &sel, &order);
        assert_eq!(written, new_pages, "pages written for {:?}", sel.len());
        let got = image(gl, &mut paged, &slots);
        assert_eq!(got.pixels, want.pixels, "paged vs whole upload");
        let lit = got.pixels.iter().filter(|p| p[3] > 0.05).count();
        assert!(lit > (W * H / 4) as usize, "only {lit} pixels drawn");
    }
    whole.destroy(gl);
    paged.destroy(gl);
}

#[test]
fn page_writes_outside_the_pages_or_above_their_degree_are_errors() {
    let Some(ctx) = current_context() else { return };
    let gl = ctx.gl();
    let cloud = synthetic::random_cloud(100, 3, 0.5, 1);
    let mut r = SplatRenderer::new(gl).unwrap();
    assert!(matches!(
        r.write_page(gl, 0, &cloud, 0),
        Err(GlError::NotUploaded)
    ));
    r.allocate_pages(gl, 2, 1, ColorSpace::default()).unwrap();
    let e = r.write_page(gl, 0, &cloud, 0).unwrap_err().to_string();
    assert!(e.contains("SH degree 3") && e.contains("degree 1"), "{e}");
    let low = synthetic::random_cloud(100, 1, 0.5, 1);
    let e = r.write_page(gl, 2, &low, 0).unwrap_err().to_string();
    assert!(e.contains("outside the 2 pages"), "{e}");
    r.write_page(gl, 1, &low, 0).unwrap();
    // An order over slots beyond the pages is refused like any too-long order.
    let too_long = vec![0u32; 2 * PAGE_SPLATS + 1];
    assert!(matches!(
        r.set_order(gl, &too_long),
        Err(GlError::OrderTooLong { .. })
    ));
    // A plain upload replaces the pages.
    r.upload(gl, &low).unwrap();
    assert_eq!(r.pages(), 0);
    r.destroy(gl);
}
