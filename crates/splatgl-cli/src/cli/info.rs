//! `splatgl info FILE [--json]`.
use splatgl::cloud::{ColorSpace, Kernel, Projection, SortingMethod};
use std::process::ExitCode;

/// Help of `info --json`.
pub const JSON_HELP: &str = "Print JSON (keys: format, splat_count, sh_degree, color_space, \
    kernel, projection, sorting_method, bounds_min, bounds_max, up, up_rule, scale_space, \
    non_unit_quaternions, non_finite_opacities, memory_bytes, warnings, notes; for quantized containers also container, \
    container_version, compression, gltf_extension, quantization[{attribute, bits, encoding}], \
    lossy, antialiased — null otherwise; with -v also limits)";

/// Runs `info`. Exit status 0, or 2 when the file cannot be loaded.
pub fn run(a: super::FileArgs) -> ExitCode {
    let opts = a.load.options();
    if super::tileset::is_tileset_file(&a.file, &opts) {
        return super::tileset::info(&a, &opts);
    }
    let loaded = match splatgl::load::load_path(&a.file, &opts) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("error: {}", splatgl::load::printable(&e.to_string()));
            return ExitCode::from(2);
        }
    };
    let c = &loaded.cloud;
    let r = &loaded.report;
    let file = a.file.display().to_string();
    if let Err(e) = a.load.common.check_applies(&file, Some(r.format)) {
        eprintln!("error: {}", splatgl::load::printable(&e.to_string()));
        return ExitCode::from(2);
    }
    let b = c.bounds();
    let (up, up_rule) = splatgl::camera::UpAxis::for_cloud_explained(Some(r.format), c);
    let mut info = serde_json::json!({
        "file": a.file.display().to_string(),
        "format": r.format.name(),
        "splat_count": c.len(),
        "sh_degree": c.sh_degree,
        "color_space": c.meta.color_space.to_string_with(ColorSpace::as_str),
        "kernel": c.meta.kernel.to_string_with(Kernel::as_str),
        "projection": c.meta.projection.to_string_with(Projection::as_str),
        "sorting_method": c.meta.sorting_method.to_string_with(SortingMethod::as_str),
        "bounds_min": b.map(|b| b.min),
        "bounds_max": b.map(|b| b.max),
        "up": up.name(),
        "up_rule": up_rule,
        "scale_space": r.scale_space.map(|s| s.name()),
        "non_unit_quaternions": r.non_unit_quaternions,
        "non_finite_opacities": r.non_finite_opacities,
        "antialiased_auto": splatgl::load::AntialiasMode::Auto.resolve(r.trained_antialiased()),
        "memory_bytes": c.memory_bytes(),
        "warnings": r.warning_lines(),
        "notes": r.note_lines(),
    });
    let details = r.details.as_ref();
    if let Some(obj) = info.as_object_mut() {
        obj.extend(splatgl::load::Details::json_keys(details));
    }
    if a.verbose {
        info["limits"] = super::limits_json(&opts.limits);
    }
    if a.json {
        println!("{info:#}");
        return ExitCode::SUCCESS;
    }
    print_text(&a, &loaded, &info, &opts.limits);
    ExitCode::SUCCESS
}

/// The text output of `info` (`info` holds the JSON values it shares).
fn print_text(
    a: &super::FileArgs,
    loaded: &splatgl::load::Scene,
    info: &serde_json::Value,
    limits: &splatgl::load::Limits,
) {
    let (c, r) = (&loaded.cloud, &loaded.report);
    let b = c.bounds();
    let (up, up_rule) = splatgl::camera::UpAxis::for_cloud_explained(Some(r.format), c);
    println!("file:           {}", a.file.display());
    println!("format:         {}", r.format.name());
    println!("splats:         {}", c.len());
    println!("SH degree:      {}", c.sh_degree);
    println!(
        "colour space:   {}",
        info["color_space"].as_str().unwrap_or("?")
    );
    println!("kernel:         {}", info["kernel"].as_str().unwrap_or("?"));
    println!(
        "--antialiased auto: {}",
        if r.trained_antialiased() {
            "on (the file says it was trained with antialiasing)"
        } else {
            "off (no antialiasing flag in the file)"
        }
    );
    match b {
        Some(b) => println!("bounds:         {:?} .. {:?}", b.min, b.max),
        None => println!("bounds:         (empty)"),
    }
    println!("up:             {} ({up_rule})", up.name());
    println!(
        "scale space:    {}",
        r.scale_space.map_or("-", |s| s.name())
    );
    println!(
        "memory:         {:.1} MiB",
        c.memory_bytes() as f64 / 1048576.0
    );
    if let Some(d) = &r.details {
        print_details(d);
    }
    if a.verbose {
        super::print_limits(limits);
    }
    if r.non_finite_opacities > 0 {
        println!(
            "non-finite:     {} opacity logits ±inf (read as opacity 1 or 0)",
            r.non_finite_opacities
        );
    }
    if !a.quiet {
        for w in r.summarized_warnings() {
            println!("warning: {w}");
        }
        for n in r.summarized_notes() {
            println!("note: {n}");
        }
    }
}

/// The container lines of the text output.
fn print_details(d: &splatgl::load::Details) {
    println!("container:      {}", d.summary());
    println!(
        "antialiased:    {}",
        if d.antialiased { "yes" } else { "no" }
    );
    println!("quantization:");
    for q in &d.quantization {
        println!("  {:<9} {:>2} bits  {}", q.attribute, q.bits, q.encoding);
    }
    println!("lossy:");
    for l in &d.lossy {
        println!("  - {l}");
    }
}
