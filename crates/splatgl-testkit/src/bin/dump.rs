//! Prints every splat of a file (debug aid): `cargo run -p splatgl-testkit --bin dump -- FILE`.
fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: dump FILE");
        std::process::exit(2);
    };
    match splatgl::load::load_path(&path, &Default::default()) {
        Ok(l) => {
            let c = &l.cloud;
            for i in 0..c.len() {
                println!(
                    "{i}: pos {:?} scale {:?} rot {:?} opacity {} dc {:?}",
                    c.positions[i],
                    c.scales[i],
                    c.rotations[i],
                    c.opacities[i],
                    c.sh_of(i)[0]
                );
            }
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    }
}
