//! The desktop viewer from library code: what `splatgl view` runs, with default options.
//!
//! `cargo run --release -p splatgl-viewer --example viewer -- [SCENE]` (H or F1 in the window prints the
//! controls). An application that wants its own window and loop embeds `splatgl::gl`
//! instead (see `examples/embed.rs`).

fn main() {
    let opts = splatgl_viewer::ViewerOptions {
        file: std::env::args_os().nth(1).map(Into::into),
        ..Default::default()
    };
    if let Err(e) = splatgl_viewer::run(opts) {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}
