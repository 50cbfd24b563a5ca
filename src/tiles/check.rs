//! The structural rules of a tileset and its content, for `info` and `validate`: what
//! [`super::read`] found, geometric error that does not decrease, child volumes outside their
//! parent's, content that is missing, outside the tileset's folder, not loadable, not splats,
//! or with splats outside its tile's volume.

use super::ContentError;
use super::{Tile, Tileset, TilesetFormat};
use crate::load::validate::Report;
use crate::load::{Finding, Format, LoadOptions};
use glam::DVec3;
use std::path::Path;

/// Relative slack of the containment tests (f32 positions, rounding of written volumes).
const EPS: f64 = 1e-4;

/// One level of the tree.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LevelSummary {
    /// Depth (the root is 0).
    pub level: usize,
    /// Tiles at this depth.
    pub tiles: usize,
    /// Content files at this depth.
    pub contents: usize,
    /// Splats in the content that loaded.
    pub splats: u64,
    /// The largest `geometricError` at this depth.
    pub geometric_error: f64,
}

/// What [`check`] found.
#[derive(Debug, Clone)]
pub struct TilesetReport {
    /// The tileset, when `tileset.json` could be read.
    pub tileset: Option<Tileset>,
    /// Findings in tree order, as `validate` prints them.
    pub report: Report,
    /// Per depth.
    pub levels: Vec<LevelSummary>,
}

/// Reads `path` as a tileset and checks it; with `load_content`, every tile's content is
/// loaded (with `opts`: limits, containment) and its splats counted and checked against the
/// tile's volume.
pub fn check(path: &Path, opts: &LoadOptions, load_content: bool) -> TilesetReport {
    let ts = match super::read(path, opts) {
        Ok(ts) => ts,
        Err(e) => {
            return TilesetReport {
                tileset: None,
                report: Report {
                    format: None,
                    findings: vec![Finding::fatal("", e)],
                    readable: false,
                    splat_count: None,
                },
                levels: Vec::new(),
            };
        }
    };
    let mut findings: Vec<Finding> = ts
        .problems
        .iter()
        .map(|p| match p.unsupported {
            true => Finding::unsupported(&p.path, &p.message),
            false => Finding::error(&p.path, &p.message),
        })
        .collect();
    let mut levels: Vec<LevelSummary> = Vec::new();
    let mut total = 0u64;
    let mut stack = vec![(&ts.root, None::<&Tile>)];
    while let Some((t, parent)) = stack.pop() {
        if let Some(p) = parent {
            nesting(t, p, &mut findings);
        }
        if levels.len() <= t.level {
            levels.resize_with(t.level + 1, Default::default);
        }
        let l = &mut levels[t.level];
        l.level = t.level;
        l.tiles += 1;
        l.contents += t.content.len();
        l.geometric_error = l.geometric_error.max(t.geometric_error);
        if load_content {
            let n = contents(&ts, t, opts, &mut findings);
            levels[t.level].splats += n;
            total += n;
        }
        stack.extend(t.children.iter().rev().map(|c| (c, Some(t))));
    }
    let report = Report {
        format: None,
        findings,
        readable: true,
        splat_count: load_content.then_some(total as usize),
    };
    TilesetReport {
        tileset: Some(ts),
        report,
        levels,
    }
}

/// The rules between a tile and its parent: geometric error does not grow, and the child's
/// volume lies inside the parent's (3D Tiles' spatial coherence, which selection relies on).
fn nesting(t: &Tile, parent: &Tile, findings: &mut Vec<Finding>) {
    if t.geometric_error > parent.geometric_error {
        findings.push(Finding::warning(
            format!("{}.geometricError", t.path),
            format!(
                "{} is larger than its parent's {}: a child must not be coarser than its parent",
                t.geometric_error, parent.geometric_error
            ),
        ));
    }
    if let (Some(b), Some(pb)) = (t.bounds, parent.bounds)
        && let Some(out) = b.extremes().into_iter().find(|p| !pb.contains(*p, EPS))
    {
        findings.push(Finding::warning(
            format!("{}.boundingVolume", t.path),
            format!(
                "reaches ({:.4}, {:.4}, {:.4}), outside its parent's volume: children's volumes must lie inside their parent's",
                out.x, out.y, out.z
            ),
        ));
    }
}

/// Loads tile `t`'s content, reports what is wrong with it, and returns its splat count.
fn contents(ts: &Tileset, t: &Tile, opts: &LoadOptions, findings: &mut Vec<Finding>) -> u64 {
    let mut total = 0;
    for (i, uri) in t.content.iter().enumerate() {
        let at = match t.content.len() {
            1 => format!("{}.content", t.path),
            _ => format!("{}.contents[{i}]", t.path),
        };
        let scene = match ts.load_content(uri, opts) {
            Ok(s) => s,
            Err(ContentError::Unsupported(m)) => {
                findings.push(Finding::unsupported(&at, m));
                continue;
            }
            Err(ContentError::Unreadable(m)) => {
                findings.push(Finding::error(&at, m));
                continue;
            }
        };
        let format = scene.report.format;
        let (expected, what) = match ts.format {
            TilesetFormat::Tiles3d => (
                matches!(format, Format::Gltf | Format::Glb),
                "3D Tiles content is glTF (with KHR_gaussian_splatting for splats)",
            ),
            TilesetFormat::StreamedSog => (format == Format::Sog, "streamed SOG units are SOG"),
        };
        if !expected {
            findings.push(Finding::warning(
                &at,
                format!("{uri:?} is {}: {what}", format.name()),
            ));
        }
        let cloud = &scene.cloud;
        total += cloud.len() as u64;
        if let Some(b) = t.bounds {
            let m = t.transform * ts.content_frame();
            let outside = cloud
                .positions
                .iter()
                .filter(|p| {
                    let p = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
                    !b.contains(m.transform_point3(p), EPS)
                })
                .count();
            if outside > 0 {
                findings.push(Finding::warning(
                    &at,
                    format!(
                        "{outside} of its {} splat centres lie outside the tile's bounding volume{}",
                        cloud.len(),
                        match ts.format {
                            TilesetFormat::Tiles3d => " (content turned y-up → z-up, then the tile transform)",
                            TilesetFormat::StreamedSog => "",
                        }
                    ),
                ));
            }
        }
    }
    total
}
