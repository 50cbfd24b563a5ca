//! Embedding `SplatRenderer` in a modern host (GLES 3 / core profile) that owns its context,
//! framebuffer, depth buffer and camera: the host draws an opaque cube with its own shader,
//! splatgl draws the splats into the same framebuffer with the host's view and projection
//! (`draw_with_matrices`), occluded by the cube through the host's depth buffer, with
//! `restore_state = true` — so the host's next frame is bit-identical to one drawn before
//! splatgl existed. The host logic is in `examples/host/modern.rs` (rendered and checked by
//! `tests/it/gl_embedding.rs`).
//!
//! `cargo run --release --example embed -- [SCENE] [OUT_PREFIX]` writes OUT_PREFIX-N.png.

#[path = "host/mod.rs"]
mod host;

use splatgl::headless::HeadlessContext;
use splatgl::image::PngDepth;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let cloud = match args.next() {
        Some(p) => splatgl::load::load_path(&p, &Default::default())?.cloud,
        None => splatgl::synthetic::default_scene(),
    };
    let prefix = args.next().unwrap_or_else(|| "embed".into());
    let ctx = HeadlessContext::new()?;
    let frames = host::modern::run(&ctx, &cloud, 2, 320, 240)?;
    for (k, image) in frames.with_splats.iter().enumerate() {
        let out = format!("{prefix}-{k}.png");
        image.write_png(&out, PngDepth::Eight, false)?;
        eprintln!("frame {k} -> {out}");
    }
    let same = frames.host_only_after == frames.host_only_before;
    eprintln!("host frame after splatgl identical to one before: {same}");
    Ok(())
}
