use super::*;

fn one(pos: [f32; 3], s: f32, alpha: f32, dc: f32) -> SplatCloud {
    let mut c = SplatCloud::new(0);
    c.push(pos, [s, s, s], [0.0, 0.0, 0.0, 1.0], alpha, &[[dc; 3]]);
    c
}

#[test]
fn merging_two_splats_keeps_their_mean_covariance_and_colour() {
    let mut c = one([-1.0, 0.0, 0.0], 0.5, 0.4, 1.0);
    c.append(one([1.0, 0.0, 0.0], 0.5, 0.4, 3.0));
    let (m, spread) = merge(&c, &[0, 1]);
    assert_eq!(m.position, [0.0, 0.0, 0.0]);
    let mut s = m.scale;
    s.sort_by(f32::total_cmp);
    // Σ = 0.25 I + diag(1, 0, 0): σ = 0.5, 0.5, √1.25.
    assert!(
        (s[0] - 0.5).abs() < 1e-6 && (s[2] - 1.25f32.sqrt()).abs() < 1e-6,
        "{s:?}"
    );
    assert!((m.sh[0][0] - 2.0).abs() < 1e-6);
    assert!((spread - 1.0).abs() < 1e-9, "{spread}");
    // Combined weight 2 × 0.4 × 0.25 over the merged area 0.5 × √1.25.
    let want = 0.2 / (0.5 * 1.25f64.sqrt());
    assert!((m.opacity as f64 - want).abs() < 1e-6, "{}", m.opacity);
}

#[test]
fn coincident_splats_merge_to_their_stacked_opacity_not_their_sum() {
    let mut c = one([0.0; 3], 0.5, 0.5, 0.0);
    c.append(one([0.0; 3], 0.5, 0.5, 0.0));
    let (m, spread) = merge(&c, &[0, 1]);
    assert!((m.opacity - 0.75).abs() < 1e-6, "{}", m.opacity);
    assert_eq!(spread, 0.0);
}

#[test]
fn a_built_tree_keeps_every_tile_within_its_chunk_and_errors_grow_to_the_root() {
    let cloud = crate::synthetic::random_cloud(1000, 1, 2.0, 3);
    let seen = std::sync::Mutex::new(Vec::new());
    let sink = |name: &str, c: &SplatCloud| {
        seen.lock().unwrap().push((name.to_owned(), c.len()));
        Ok(())
    };
    let root = build(&cloud, &BuildOptions { chunk_splats: 100 }, &sink).unwrap();
    let tiles = root.walk();
    assert_eq!(tiles.len(), seen.lock().unwrap().len());
    let leaves: usize = tiles
        .iter()
        .filter(|t| t.children.is_empty())
        .map(|t| t.splats)
        .sum();
    assert_eq!(leaves, 1000);
    for t in &tiles {
        assert!(t.splats <= 100 && t.splats > 0, "{} {}", t.name, t.splats);
        for c in &t.children {
            assert!(c.geometric_error < t.geometric_error, "{}", c.name);
            for k in 0..3 {
                assert!(c.min[k] >= t.min[k] && c.max[k] <= t.max[k]);
            }
        }
    }
}
