//! Embedding `SplatRenderer` in a legacy desktop GL application (compatibility profile):
//! the host draws a textured ground quad in immediate mode, splatgl draws the splats with the
//! host's fixed-function matrices and `restore_state = true`, then the host draws a cube from
//! client arrays in the vertex buffer it expects still bound — frame after frame. The host
//! logic is in `examples/host/legacy.rs` (rendered and checked by `tests/it/gl_embedding.rs`).
//!
//! `cargo run --release --example embed_legacy -- [SCENE] [OUT_PREFIX]` writes
//! OUT_PREFIX-N.png.

#[path = "host/mod.rs"]
mod host;

use splatgl::headless::{GlApi, HeadlessContext};
use splatgl::image::PngDepth;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let cloud = match args.next() {
        Some(p) => splatgl::load::load_path(&p, &Default::default())?.cloud,
        None => splatgl::synthetic::default_scene(),
    };
    let prefix = args.next().unwrap_or_else(|| "embed_legacy".into());
    let ctx = HeadlessContext::with_api(GlApi::DesktopCompat)?;
    eprintln!("context: {}", ctx.describe());
    let (_, frames) = host::legacy::run(&ctx, &cloud, 3, 320, 240)?;
    for (k, image) in frames.iter().enumerate() {
        let out = format!("{prefix}-{k}.png");
        image.write_png(&out, PngDepth::Eight, false)?;
        eprintln!("frame {k} -> {out}");
    }
    Ok(())
}
