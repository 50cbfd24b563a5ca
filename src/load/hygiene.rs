//! Numeric hygiene: the one pass that keeps non-finite or overflowing splats out of every
//! [`SplatCloud`] a loader returns.
//!
//! [`clean`] tests every splat with [`SplatCloud::splat_problem`] (positions, scales,
//! rotations, opacity, every SH coefficient — so also a colour derived from `COLOR_0`) and
//! drops those that fail, with one finding per field naming the count and the first index; in
//! strict mode the first failing splat is an error instead. It runs at the exit of
//! `load::read` for every format, and inside the glTF reader after decoding each primitive and
//! after each node transform (so findings name the attribute or node).

use super::{Finding, Severity};
use crate::cloud::{Field, SplatCloud};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Where a pass runs, for its findings.
pub(crate) struct Site<'a> {
    /// Finding path (a JSON path, a PLY element, or empty for the whole file).
    pub path: &'a str,
    /// Prefix of the message (e.g. which primitive a node instantiates), may be empty.
    pub what: &'a str,
    /// Severity of a drop: an error where the format's spec makes the data invalid (glTF),
    /// else a warning.
    pub severity: Severity,
    /// Whether a bad splat fails the load instead of being dropped.
    pub strict: bool,
    /// Original index of each splat, where earlier passes already dropped some.
    pub origin: Option<&'a [u32]>,
}

/// Drops every splat that breaks the contract; see the module docs. Returns, when something
/// was dropped, the original index of every splat kept (through `site.origin`); in strict mode
/// a bad splat is returned as a blocking finding and the cloud is left as it was.
pub(crate) fn clean(
    cloud: &mut SplatCloud,
    site: &Site,
    findings: &mut Vec<Finding>,
) -> Result<Option<Vec<u32>>, Finding> {
    let bad: Vec<(usize, Field)> = (0..cloud.len())
        .into_par_iter()
        .filter_map(|i| cloud.splat_problem(i).map(|f| (i, f)))
        .collect();
    if bad.is_empty() {
        return Ok(None);
    }
    let origin = |i: usize| site.origin.map_or(i as u64, |o| o[i] as u64);
    let prefix = match site.what {
        "" => String::new(),
        w => format!("{w}: "),
    };
    if site.strict {
        let (i, f) = bad[0];
        return Err(Finding::fatal(
            site.path,
            format!("{prefix}{} {} (strict mode)", f.name(), f.rule()),
        )
        .at(origin(i)));
    }
    let mut by_field: BTreeMap<Field, (usize, usize)> = BTreeMap::new();
    for &(i, f) in &bad {
        by_field.entry(f).or_insert((0, i)).0 += 1;
    }
    for (f, (n, first)) in by_field {
        let s = if n == 1 { "" } else { "s" };
        let mut finding = Finding::warning(
            site.path,
            format!("{prefix}{n} splat{s} dropped: {} {}", f.name(), f.rule()),
        )
        .at(origin(first));
        finding.severity = site.severity;
        findings.push(finding);
    }
    let drop: Vec<usize> = bad.into_iter().map(|(i, _)| i).collect();
    let kept = (0..cloud.len())
        .filter(|i| drop.binary_search(i).is_err())
        .map(|i| origin(i) as u32)
        .collect();
    drop_splats(cloud, &drop);
    Ok(Some(kept))
}

/// Removes the splats at `drop` (sorted ascending) from every array, keeping the order.
pub(crate) fn drop_splats(cloud: &mut SplatCloud, drop: &[usize]) {
    if drop.is_empty() {
        return;
    }
    let k = cloud.coeffs_per_splat();
    let n = cloud.len();
    let mut next = drop.iter().peekable();
    let mut w = 0;
    for r in 0..n {
        if next.peek() == Some(&&r) {
            next.next();
            continue;
        }
        if w != r {
            cloud.positions[w] = cloud.positions[r];
            cloud.scales[w] = cloud.scales[r];
            cloud.rotations[w] = cloud.rotations[r];
            cloud.opacities[w] = cloud.opacities[r];
            cloud.sh.copy_within(r * k..(r + 1) * k, w * k);
        }
        w += 1;
    }
    cloud.positions.truncate(w);
    cloud.scales.truncate(w);
    cloud.rotations.truncate(w);
    cloud.opacities.truncate(w);
    cloud.sh.truncate(w * k);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud() -> SplatCloud {
        let mut c = SplatCloud::new(1);
        for i in 0..6 {
            let sh: Vec<[f32; 3]> = (0..4).map(|j| [(i * 10 + j) as f32; 3]).collect();
            c.push([i as f32; 3], [1.0; 3], [0.0, 0.0, 0.0, 1.0], 0.5, &sh);
        }
        c
    }

    fn site(strict: bool) -> Site<'static> {
        Site {
            path: "nodes[2]",
            what: "",
            severity: Severity::Error,
            strict,
            origin: None,
        }
    }

    #[test]
    fn bad_splats_are_dropped_with_a_count_per_field() {
        let mut c = cloud();
        c.positions[1][0] = f32::NAN;
        c.sh[3 * 4 + 2][1] = f32::INFINITY;
        c.sh[5 * 4][0] = f32::NAN;
        let mut f = Vec::new();
        let kept = clean(&mut c, &site(false), &mut f).unwrap().unwrap();
        assert_eq!(kept, [0, 2, 4]);
        assert!(c.validate().is_ok());
        assert_eq!(
            c.positions.iter().map(|p| p[0]).collect::<Vec<_>>(),
            [0.0, 2.0, 4.0]
        );
        assert_eq!(c.sh_of(2)[0], [40.0; 3], "SH moved with its splat");
        let lines: Vec<String> = f.iter().map(|f| f.to_string()).collect();
        assert_eq!(
            lines,
            [
                "error at nodes[2] [index 1]: 1 splat dropped: position is not finite",
                "error at nodes[2] [index 3]: 2 splats dropped: SH coefficient is not finite",
            ]
        );
    }

    #[test]
    fn strict_mode_fails_on_the_first_bad_splat_and_keeps_the_cloud() {
        let mut c = cloud();
        c.opacities[4] = f32::NAN;
        let before = c.clone();
        let e = clean(&mut c, &site(true), &mut Vec::new()).unwrap_err();
        assert!(e.blocks_loading && e.index == Some(4), "{e}");
        assert!(e.message.contains("opacity"), "{e}");
        assert_eq!(
            format!("{c:?}"),
            format!("{before:?}"),
            "NaN != NaN: compare the text"
        );
    }
}
