//! `render --antialiased` and `--crop` from the command line: `auto` follows the file's SPZ
//! flag (a flagged SPZ we write, and the real SPZ files, none flagged), `on` changes the image,
//! `info` says what `auto` picks; `--crop` draws exactly what a cropped file draws, and bad
//! boxes are errors that say why.

use crate::common;

use common::cli::run;
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cli-kernel-{name}"));
    std::fs::create_dir_all(&d).unwrap();
    d
}

const CAM: [&str; 8] = [
    "--look-at",
    "0,0,4,0,0,0",
    "--width",
    "64",
    "--height",
    "48",
    "--backend",
    "reference",
];

/// Renders `file` to a .pfm with `extra`, returns the bytes.
fn render(file: &Path, out: &Path, extra: &[&str]) -> Vec<u8> {
    let mut args = vec![
        "render",
        file.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-f",
        "-v",
    ];
    args.extend(CAM);
    args.extend(extra);
    let r = run(&args);
    assert_eq!(r.code, 0, "{}", r.all());
    std::fs::read(out).unwrap()
}

fn info_auto(file: &Path) -> bool {
    let r = run(&["info", file.to_str().unwrap(), "--json"]);
    assert_eq!(r.code, 0, "{}", r.all());
    let v: serde_json::Value = serde_json::from_str(&r.out()).unwrap();
    v["antialiased_auto"].as_bool().expect("antialiased_auto")
}

#[test]
fn antialiased_auto_follows_the_spz_flag_and_on_changes_the_image() {
    let d = dir("aa");
    let cloud = splatgl::synthetic::random_cloud(400, 1, 0.6, 12);
    let mut o = splatgl::write::SpzWriteOptions {
        antialiased: true,
        ..Default::default()
    };
    let flagged = d.join("flagged.spz");
    std::fs::write(&flagged, splatgl::write::to_spz_with(&cloud, &o).unwrap()).unwrap();
    o.antialiased = false;
    let plain = d.join("plain.spz");
    std::fs::write(&plain, splatgl::write::to_spz_with(&cloud, &o).unwrap()).unwrap();
    assert!(info_auto(&flagged));
    assert!(!info_auto(&plain));
    let out = d.join("out.pfm");
    let auto = render(&flagged, &out, &[]);
    let on = render(&flagged, &out, &["--antialiased", "on"]);
    let off = render(&flagged, &out, &["--antialiased", "off"]);
    assert_eq!(auto, on, "auto on a flagged file is on");
    assert_ne!(on, off, "the antialiased kernel changes the image");
    assert_eq!(
        render(&plain, &out, &[]),
        render(&plain, &out, &["--antialiased", "off"])
    );
    let text = run(&["info", flagged.to_str().unwrap()]).out();
    assert!(text.contains("--antialiased auto: on"), "{text}");
}

#[test]
fn the_real_spz_files_are_not_flagged_so_auto_draws_them_plain() {
    let Some(files) = common::real_files() else {
        return;
    };
    let spz: Vec<_> = files
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "spz"))
        .collect();
    assert!(spz.len() >= 4, "{spz:?}");
    for f in spz {
        let r = run(&["info", f.to_str().unwrap(), "--json"]);
        let v: serde_json::Value = serde_json::from_str(&r.out()).unwrap();
        assert_eq!(
            v["antialiased"],
            serde_json::json!(false),
            "{}",
            f.display()
        );
        assert_eq!(
            v["antialiased_auto"],
            serde_json::json!(false),
            "{}",
            f.display()
        );
    }
}

#[test]
fn crop_draws_what_a_cropped_file_draws() {
    let d = dir("crop");
    let cloud = splatgl::synthetic::random_cloud(600, 1, 0.5, 13);
    let input = d.join("in.ply");
    std::fs::write(&input, splatgl::write::to_inria_ply(&cloud)).unwrap();
    let cropped = d.join("cropped.ply");
    let box_ = "-0.6,-0.6,-0.6,0.5,0.7,0.4";
    let r = run(&[
        "convert",
        input.to_str().unwrap(),
        cropped.to_str().unwrap(),
        "-f",
        "--crop",
        box_,
    ]);
    assert_eq!(r.code, 0, "{}", r.all());
    assert!(r.stderr.contains("--crop: kept "), "{}", r.stderr);
    let out = d.join("out.pfm");
    let by_flag = render(&input, &out, &["--crop", box_]);
    let by_file = render(&cropped, &out, &[]);
    let whole = render(&input, &out, &[]);
    assert_eq!(by_flag, by_file, "--crop = rendering the cropped file");
    assert_ne!(by_flag, whole, "the box removes splats that show");
    for (bad, why) in [
        ("0,0,0,1,1", "5 values"),
        ("1,0,0,0,1,1", "min x 1 > max x 0"),
        ("0,0,0,1,1,nan", "not a finite number"),
        ("9,9,9,10,10,10", "none of the 600 splats"),
    ] {
        let r = run(&[
            "render",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-f",
            "--crop",
            bad,
        ]);
        assert_ne!(r.code, 0, "{bad}");
        assert!(r.stderr.contains(why), "{bad}: {}", r.stderr);
    }
}
