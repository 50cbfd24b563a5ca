//! Property tests of `splatgl::sort`: every order equals a stable std sort of the same keys
//! (key descending, NaN first, ties by ascending index), quantized orders stay within the
//! documented error bound, reuse is sound, the async sorter delivers the newest order, and a
//! warm sorter allocates nothing.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::cmp::Ordering;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering as AtOrd};

use glam::Vec3;
use splatgl::camera::Camera;
use splatgl::cull::{CropBox, CullBounds, Frustum};
use splatgl::sort::{
    AsyncSorter, Outcome, Precision, Reuse, SortMode, SortRequest, Sorter, quantized_bucket_width,
    squared_distance, view_depth,
};

// ---------------------------------------------------------------- allocation counting

/// Counts allocations made on threads marked `TRACK` while `ARMED`.
struct Counting;
static ARMED: AtomicBool = AtomicBool::new(false);
static ALLOCS: AtomicUsize = AtomicUsize::new(0);
thread_local! {
    static TRACK: Cell<bool> = const { Cell::new(false) };
}
fn note_alloc() {
    if ARMED.load(AtOrd::Relaxed) && TRACK.try_with(Cell::get).unwrap_or(false) {
        ALLOCS.fetch_add(1, AtOrd::Relaxed);
    }
}
// SAFETY: every call is passed on to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        note_alloc();
        // SAFETY: the caller's contract, passed on to the system allocator.
        unsafe { System.alloc(l) }
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        note_alloc();
        // SAFETY: the caller's contract, passed on to the system allocator.
        unsafe { System.alloc_zeroed(l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        note_alloc();
        // SAFETY: the caller's contract, passed on to the system allocator.
        unsafe { System.realloc(p, l, n) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        // SAFETY: the caller's contract, passed on to the system allocator.
        unsafe { System.dealloc(p, l) }
    }
}
#[global_allocator]
static GLOBAL: Counting = Counting;

// ---------------------------------------------------------------- helpers

use splatgl::synthetic::Rng;

/// The documented draw order: NaN first, then larger keys first (−0 = +0).
fn far_first(a: f32, b: f32) -> Ordering {
    match (a.is_nan(), b.is_nan()) {
        (true, true) => Ordering::Equal,
        (true, false) => Ordering::Less,
        (false, true) => Ordering::Greater,
        _ => b.partial_cmp(&a).expect("not NaN"),
    }
}

/// Stable std sort of the indices by `far_first` keys.
fn reference(keys: &[f32]) -> Vec<u32> {
    let mut idx: Vec<u32> = (0..keys.len() as u32).collect();
    idx.sort_by(|&i, &j| far_first(keys[i as usize], keys[j as usize]));
    idx
}

fn random_positions(rng: &mut Rng, n: usize, half: f32) -> Vec<[f32; 3]> {
    (0..n)
        .map(|_| {
            [
                rng.range(-half, half),
                rng.range(-half, half),
                rng.range(-half, half),
            ]
        })
        .collect()
}

/// Adversarial and random key sets, named.
fn key_cases() -> Vec<(&'static str, Vec<f32>)> {
    let mut rng = Rng::new(7);
    let mut cases = vec![
        ("empty", vec![]),
        ("one", vec![3.5]),
        ("two ascending", vec![1.0, 2.0]),
        ("two equal", vec![2.0, 2.0]),
        ("all equal", vec![0.25; 100_000]),
        ("ascending", (0..100_000).map(|i| i as f32).collect()),
        (
            "descending",
            (0..100_000).rev().map(|i| i as f32 * 0.5).collect(),
        ),
        (
            "specials",
            vec![
                f32::NAN,
                1.0,
                f32::INFINITY,
                -0.0,
                0.0,
                f32::NEG_INFINITY,
                -f32::NAN,
                f32::MIN_POSITIVE,
                -f32::MIN_POSITIVE,
                f32::MAX,
                f32::MIN,
                f32::from_bits(1),
                -f32::from_bits(1),
                0.0,
                f32::NAN,
                1.0,
            ],
        ),
    ];
    // Random, with duplicates, negatives and sprinkled specials.
    let specials = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.0, 0.0];
    let n = (1 << 20) + 1;
    let big: Vec<f32> = (0..n)
        .map(|_| match rng.below(1000) {
            0 => specials[rng.below(5) as usize],
            1..=200 => (rng.below(64) as f32) * 0.125,
            _ => rng.range(-100.0, 1000.0),
        })
        .collect();
    cases.push(("2^20+1 mixed", big));
    // Keys differing in one radix digit only (exercises skipped passes).
    cases.push((
        "low digit only",
        (0..70_000)
            .map(|_| f32::from_bits(0x4000_0000 | rng.below(1 << 11) as u32))
            .collect(),
    ));
    // A range of ≤ 10 significant bits: the MSD pass alone sorts (writes indices directly).
    cases.push((
        "msd only",
        (0..70_000)
            .map(|_| f32::from_bits(0x4000_0000 | rng.below(1 << 10) as u32))
            .collect(),
    ));
    cases.push((
        "high bits only",
        (0..70_000)
            .map(|_| f32::from_bits(0x4000_0000 | ((rng.below(1 << 8) as u32) << 22)))
            .collect(),
    ));
    // A dense cluster (most keys in one MSD bucket, sorted by the parallel big-bucket path)
    // plus far outliers; once with all low digits live, once with a constant top low digit.
    let mut cluster: Vec<f32> = (0..300_000)
        .map(|_| f32::from_bits(0x3F80_0000 | rng.below(1 << 20) as u32))
        .collect();
    cluster.extend([1.0e6, -3.0, 5.0e5, f32::INFINITY]);
    cases.push(("dense cluster", cluster));
    let mut cluster: Vec<f32> = (0..300_000)
        .map(|_| f32::from_bits(0x3F80_0000 | rng.below(1 << 11) as u32))
        .collect();
    cluster.extend([1.0e6, 0.0, 7.0]);
    cases.push(("dense cluster, constant digit", cluster));
    cases.push((
        "tiny random",
        (0..1000).map(|_| rng.below(10) as f32).collect(),
    ));
    cases
}

// ---------------------------------------------------------------- exact order

#[test]
#[cfg(feature = "testing")] // Sorter::set_max_digit_bits
fn full_precision_equals_stable_std_sort() {
    for max_digit in [11, 8] {
        let mut sorter = Sorter::new();
        sorter.set_max_digit_bits(max_digit);
        for (name, keys) in key_cases() {
            let got = sorter.sort_keys(&keys).to_vec();
            assert_eq!(got, reference(&keys), "case {name}, max digit {max_digit}");
        }
    }
}

#[test]
fn result_does_not_depend_on_thread_count() {
    let mut rng = Rng::new(11);
    let positions = random_positions(&mut rng, 300_001, 50.0);
    let eye = [3.0, -120.0, 7.5];
    let mut orders = Vec::new();
    for threads in [1, 2, 3, 5] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let order = pool.install(|| Sorter::new().sort_by_distance(&positions, eye).to_vec());
        orders.push(order);
    }
    let keys: Vec<f32> = positions
        .iter()
        .map(|&p| squared_distance(p, eye))
        .collect();
    let want = reference(&keys);
    for o in &orders {
        assert_eq!(o, &want);
    }
    // Every key case, on pools of 1, 2 and 3 threads (different chunkings and groupings).
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let mut sorter = Sorter::new();
        for (name, keys) in key_cases() {
            let got = pool.install(|| sorter.sort_keys(&keys).to_vec());
            assert_eq!(got, reference(&keys), "case {name}, {threads} threads");
        }
    }
}

#[test]
fn distance_and_depth_sorts_equal_reference() {
    let mut rng = Rng::new(3);
    let mut positions = random_positions(&mut rng, 200_000, 10.0);
    // Duplicated positions (bit-equal keys) and a few NaN / inf positions.
    for i in 0..2000 {
        positions[100_000 + i] = positions[i];
    }
    positions[5] = [f32::NAN, 0.0, 0.0];
    positions[77] = [f32::INFINITY, 0.0, 0.0];
    positions[78] = [0.0, f32::NEG_INFINITY, 1.0];
    let mut sorter = Sorter::new();
    for eye in [[0.0, 0.0, 0.0], [30.0, -2.0, 5.0], [1.0e-3, 4.0, -9.5]] {
        let keys: Vec<f32> = positions
            .iter()
            .map(|&p| squared_distance(p, eye))
            .collect();
        assert_eq!(
            sorter.sort_by_distance(&positions, eye),
            reference(&keys).as_slice()
        );
        assert_eq!(sorter.order()[0], 5, "NaN position drawn first");
        let fwd = {
            let v = [0.3f32, -0.5, 0.8];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|c| c / l)
        };
        let keys: Vec<f32> = positions.iter().map(|&p| view_depth(p, eye, fwd)).collect();
        assert_eq!(
            sorter.sort_by_view_depth(&positions, eye, fwd),
            reference(&keys).as_slice()
        );
    }
    // Back to front really means farthest first.
    let order = sorter
        .sort_by_distance(&positions[200..210], [0.0; 3])
        .to_vec();
    let d: Vec<f32> = order
        .iter()
        .map(|&i| squared_distance(positions[200 + i as usize], [0.0; 3]))
        .collect();
    assert!(d.windows(2).all(|w| w[0] >= w[1]), "{d:?}");
}

#[test]
fn camera_sort_matches_view_depth_order() {
    use glam::Vec3;
    use splatgl::camera::Camera;
    let mut rng = Rng::new(5);
    let positions = random_positions(&mut rng, 5000, 4.0);
    let cam = Camera::look_at(
        Vec3::new(2.0, 1.0, -9.0),
        Vec3::ZERO,
        Vec3::new(0.0, -1.0, 0.0),
        0.8,
        64,
        48,
    );
    let mut sorter = Sorter::new();
    let order = sorter
        .sort_for_camera(&positions, &cam, SortMode::ViewDepth)
        .to_vec();
    // Camera-space z along the order never increases by more than rounding.
    let z: Vec<f32> = order
        .iter()
        .map(|&i| cam.to_camera(Vec3::from_array(positions[i as usize])).z)
        .collect();
    assert!(
        z.windows(2).all(|w| w[0] >= w[1] - 1e-4),
        "not back to front"
    );
    let order_d = sorter
        .sort_for_camera(&positions, &cam, SortMode::Distance)
        .to_vec();
    let eye = cam.eye().to_array();
    let keys: Vec<f32> = positions
        .iter()
        .map(|&p| squared_distance(p, eye))
        .collect();
    assert_eq!(order_d, reference(&keys));
}

// ---------------------------------------------------------------- quantized

/// Largest key difference of a misordered pair (an earlier splat nearer than a later one).
fn worst_inversion(keys: &[f32], order: &[u32]) -> f64 {
    let mut min_before = f64::INFINITY;
    let mut worst = 0.0f64;
    for &i in order {
        let k = f64::from(keys[i as usize]);
        worst = worst.max(k - min_before);
        min_before = min_before.min(k);
    }
    worst
}

fn is_permutation(order: &[u32], n: usize) -> bool {
    let mut seen = vec![false; n];
    order.len() == n
        && order
            .iter()
            .all(|&i| (i as usize) < n && !std::mem::replace(&mut seen[i as usize], true))
}

#[test]
fn quantized_error_is_below_one_bucket() {
    let mut rng = Rng::new(9);
    let keys: Vec<f32> = (0..300_000)
        .map(|i| {
            if i % 3 == 0 {
                rng.range(1.0, 2.0) // dense cluster
            } else {
                rng.range(0.5, 80.0)
            }
        })
        .collect();
    let (lo, hi) = keys
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &k| {
            (a.min(k), b.max(k))
        });
    for bits in [16, 20, 24] {
        let mut sorter = Sorter::new().with_precision(Precision::Quantized { bits });
        let order = sorter.sort_keys(&keys).to_vec();
        assert!(is_permutation(&order, keys.len()));
        let w = quantized_bucket_width(lo, hi, bits);
        let worst = worst_inversion(&keys, &order);
        assert!(
            worst < w * (1.0 + 1e-6),
            "{bits} bits: {worst} vs bucket {w}"
        );
        // The bound is not vacuous: some pairs do share buckets at 16 bits.
        if bits == 16 {
            assert!(worst > 0.0);
        }
    }
    // Keys further apart than a bucket come out exactly ordered.
    let spread: Vec<f32> = (0..1000).map(|_| rng.below(1000) as f32).collect();
    let mut sorter = Sorter::new().with_precision(Precision::Quantized { bits: 16 });
    assert_eq!(sorter.sort_keys(&spread), reference(&spread).as_slice());
}

#[test]
fn quantized_handles_specials_and_camera_modes() {
    let keys = [f32::NAN, 1.0, f32::INFINITY, f32::NEG_INFINITY, 3.0, 2.0];
    let mut sorter = Sorter::new().with_precision(Precision::Quantized { bits: 16 });
    let order = sorter.sort_keys(&keys).to_vec();
    // NaN and +inf share the farthest bucket (index order), −inf the nearest.
    assert_eq!(order, [0, 2, 4, 5, 1, 3]);
    for n in [0usize, 1, 2] {
        assert_eq!(sorter.sort_keys(&vec![1.0; n]).len(), n);
    }
    let mut rng = Rng::new(13);
    let positions = random_positions(&mut rng, 100_000, 10.0);
    let eye = [0.5, 0.0, -20.0];
    for bits in [16, 24] {
        let mut s = Sorter::new().with_precision(Precision::Quantized { bits });
        let order = s.sort_by_distance(&positions, eye).to_vec();
        let dist: Vec<f32> = positions
            .iter()
            .map(|&p| squared_distance(p, eye).sqrt())
            .collect();
        let (lo, hi) = dist
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &k| {
                (a.min(k), b.max(k))
            });
        let w = quantized_bucket_width(lo, hi, bits);
        assert!(worst_inversion(&dist, &order) < w * (1.0 + 1e-6));
        // View depth: the range is that of the splats in front; those behind the camera
        // clamp into the nearest bucket, so they come after every splat beyond it.
        let fwd = [0.0, 0.0, 1.0];
        let order = s.sort_by_view_depth(&positions, [0.0; 3], fwd).to_vec();
        let (lo, hi) = positions
            .iter()
            .map(|p| p[2])
            .filter(|&z| z > 0.0)
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), k| {
                (a.min(k), b.max(k))
            });
        let w = quantized_bucket_width(lo, hi, bits);
        let first_behind = order
            .iter()
            .position(|&i| positions[i as usize][2] <= 0.0)
            .expect("some behind");
        assert!(
            order[first_behind..]
                .iter()
                .all(|&i| f64::from(positions[i as usize][2]) < f64::from(lo) + w * (1.0 + 1e-6))
        );
    }
}

// ---------------------------------------------------------------- reuse

#[test]
fn same_view_reuse_and_invalidate() {
    let mut rng = Rng::new(17);
    let positions = random_positions(&mut rng, 1000, 5.0);
    let mut s = Sorter::new().with_reuse(Reuse::SameView);
    let a = s.sort_by_distance(&positions, [1.0, 2.0, 3.0]).to_vec();
    assert_eq!(s.last_outcome(), Outcome::Sorted);
    let b = s.sort_by_distance(&positions, [1.0, 2.0, 3.0]).to_vec();
    assert_eq!(s.last_outcome(), Outcome::ReusedSameView);
    assert_eq!(a, b);
    s.sort_by_distance(&positions, [1.0, 2.0, 3.0001]);
    assert_eq!(s.last_outcome(), Outcome::Sorted);
    s.invalidate();
    s.sort_by_distance(&positions, [1.0, 2.0, 3.0001]);
    assert_eq!(s.last_outcome(), Outcome::Sorted);
    // A different slice (same contents, other address) is not reused.
    let copy = positions.clone();
    s.sort_by_distance(&copy, [1.0, 2.0, 3.0001]);
    assert_eq!(s.last_outcome(), Outcome::Sorted);
    // Never: always sorts.
    let mut never = Sorter::new();
    never.sort_by_distance(&positions, [0.0; 3]);
    never.sort_by_distance(&positions, [0.0; 3]);
    assert_eq!(never.last_outcome(), Outcome::Sorted);
}

#[test]
fn motion_bound_reuse_is_sound() {
    let mut rng = Rng::new(19);
    let mut checked = 0;
    for trial in 0..40 {
        let positions = random_positions(&mut rng, 50 + trial * 10, 3.0);
        let eye = [rng.range(-20.0, 20.0), rng.range(-20.0, 20.0), 15.0];
        let mut s = Sorter::new().with_reuse(Reuse::MotionBound);
        let base = s.sort_by_distance(&positions, eye).to_vec();
        let r = s.reuse_radius();
        assert!(r.is_finite() && r >= 0.0);
        if r == 0.0 {
            continue;
        }
        for _ in 0..20 {
            // A random direction, moved 0.999 R (the eye bits must differ).
            let d = [
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ];
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-6);
            let step = (0.999 * r) as f32 / l;
            let moved = [
                eye[0] + d[0] * step,
                eye[1] + d[1] * step,
                eye[2] + d[2] * step,
            ];
            let reused = s.sort_by_distance(&positions, moved).to_vec();
            match s.last_outcome() {
                Outcome::ReusedWithinBound { moved: m, radius } => assert!(m < radius),
                Outcome::ReusedSameView | Outcome::Sorted => {}
                o => panic!("unexpected {o:?}"),
            }
            assert_eq!(reused, base);
            let fresh = Sorter::new().sort_by_distance(&positions, moved).to_vec();
            assert_eq!(
                fresh, base,
                "moving within the safe radius changed the order"
            );
            checked += 1;
        }
        // Far away: sorts again.
        s.sort_by_distance(&positions, [eye[0] + 100.0, eye[1], eye[2]]);
        assert_eq!(s.last_outcome(), Outcome::Sorted);
    }
    assert!(checked > 100, "only {checked} motions checked");
}

// ---------------------------------------------------------------- async

#[test]
fn async_sorter_delivers_newest_order() {
    let mut rng = Rng::new(23);
    let positions: Arc<[[f32; 3]]> = random_positions(&mut rng, 100_000, 10.0).into();
    let mut asorter = AsyncSorter::new(Arc::clone(&positions), Sorter::new()).expect("thread");
    assert!(asorter.latest().is_none());
    let eyes: Vec<[f32; 3]> = (0..10).map(|i| [i as f32, 20.0 - i as f32, 5.0]).collect();
    let mut last_gen = 0;
    for &eye in &eyes {
        last_gen = asorter.request(SortRequest::distance(eye));
    }
    assert_eq!(last_gen, 10);
    let frame = asorter.wait_for(last_gen).expect("finished");
    assert_eq!(frame.generation(), last_gen);
    let want = Sorter::new().sort_by_distance(&positions, eyes[9]).to_vec();
    assert_eq!(frame.order(), want.as_slice());
    assert_eq!(frame.request(), Some(SortRequest::distance(eyes[9])));
    let g = asorter.request(SortRequest::distance(eyes[0]));
    // `current` keeps the order taken last, even once a newer one has finished.
    let newer = asorter.wait_for(g).unwrap().generation();
    assert_eq!(newer, g);
    assert_eq!(asorter.current().unwrap().generation(), g);
    asorter.request(SortRequest::distance(eyes[1]));
    std::thread::sleep(std::time::Duration::from_millis(50));
    assert_eq!(asorter.current().unwrap().generation(), g);
    // Round trips keep working with recycled buffers.
    for &eye in &eyes[..4] {
        let g = asorter.request(SortRequest::distance(eye));
        let f = asorter.wait_for(g).expect("finished");
        assert_eq!(f.order(), Sorter::new().sort_by_distance(&positions, eye));
    }
    assert!(asorter.wait_for(1000).is_none(), "never issued");
}

/// A crop box cuts the orders of the requests posted after it is set, and only those: the
/// cut order is the full order with the splats outside removed (same relative order, every
/// splat inside kept), also when the sorter reuses an earlier order.
#[test]
fn async_crop_cuts_later_orders_to_the_splats_inside() {
    let mut rng = Rng::new(31);
    let positions: Arc<[[f32; 3]]> = random_positions(&mut rng, 20_000, 10.0).into();
    let sorter = Sorter::new().with_reuse(Reuse::MotionBound);
    let mut a = AsyncSorter::new(Arc::clone(&positions), sorter).expect("thread");
    let eye = [3.0, -20.0, 4.0];
    let before = a.request(SortRequest::distance(eye));
    let crop = CropBox {
        min: [-2.0, -5.0, -10.0],
        max: [6.0, 1.0, 10.0],
    };
    a.set_crop(Some(crop));
    let after = a.request(SortRequest::distance(eye));
    let full = Sorter::new().sort_by_distance(&positions, eye).to_vec();
    let want: Vec<u32> = full
        .iter()
        .copied()
        .filter(|&i| crop.contains(positions[i as usize]))
        .collect();
    assert!(
        want.len() > 1000 && want.len() < full.len() / 2,
        "{}",
        want.len()
    );
    let f = a.wait_for(after).expect("finished");
    assert_eq!(f.generation(), after);
    assert_eq!(f.crop(), Some(crop));
    assert_eq!(f.order(), want.as_slice());
    // A request posted before the crop keeps its full order.
    let mut b = AsyncSorter::new(Arc::clone(&positions), Sorter::new()).expect("thread");
    let g = b.request(SortRequest::distance(eye));
    let f = b.wait_for(g).expect("finished");
    assert_eq!((f.crop(), f.order().len()), (None, full.len()));
    assert!(before < after);
    // Reused order (same eye, MotionBound), cut again; then no crop: everything.
    let g = a.request(SortRequest::distance([3.0, -20.0, 4.000_001]));
    assert_eq!(a.wait_for(g).unwrap().order(), want.as_slice());
    a.set_crop(None);
    let g = a.request(SortRequest::distance(eye));
    assert_eq!(a.wait_for(g).unwrap().order(), full.as_slice());
}

/// `SortedFrame::exact_radius` (the viewer's staleness bound) is sound for sorted and for
/// reused orders: any eye within it of the request's eye gets the same order from a fresh sort.
#[test]
fn async_exact_radius_is_sound_for_sorted_and_reused_orders() {
    let mut rng = Rng::new(29);
    let mut checked = 0;
    for trial in 0..20 {
        let positions: Arc<[[f32; 3]]> = random_positions(&mut rng, 40 + trial * 5, 3.0).into();
        let mut a = AsyncSorter::new(
            Arc::clone(&positions),
            Sorter::new().with_reuse(Reuse::MotionBound),
        )
        .expect("thread");
        let eye = [rng.range(-20.0, 20.0), rng.range(-20.0, 20.0), 15.0];
        let r0 = {
            let f = a.wait_for(a.request(SortRequest::distance(eye))).unwrap();
            f.exact_radius()
        };
        if r0 == 0.0 {
            continue;
        }
        // A request 0.5 R away is reused; its own radius shrinks by the distance moved.
        let near = [eye[0] + 0.5 * r0 as f32, eye[1], eye[2]];
        let f = a.wait_for(a.request(SortRequest::distance(near))).unwrap();
        assert!(matches!(f.outcome(), Outcome::ReusedWithinBound { .. }));
        let r1 = f.exact_radius();
        // (The f32 eye is 0.5 R away to within an f32 ulp of its coordinates.)
        assert!(r1 > 0.0 && r1 <= 0.5 * r0 + 1e-5, "{r1} vs {r0}");
        for _ in 0..10 {
            let d = [
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ];
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-6);
            let step = (0.99 * r1) as f32 / l;
            let moved = [
                near[0] + d[0] * step,
                near[1] + d[1] * step,
                near[2] + d[2] * step,
            ];
            let fresh = Sorter::new().sort_by_distance(&positions, moved).to_vec();
            assert_eq!(fresh.as_slice(), f.order(), "moved within the exact radius");
            checked += 1;
        }
    }
    assert!(checked >= 50, "only {checked} motions checked");
}

// ---------------------------------------------------------------- allocations

#[test]
fn warm_sorter_allocates_nothing() {
    let mut rng = Rng::new(29);
    let positions = random_positions(&mut rng, 200_000, 10.0);
    let keys: Vec<f32> = positions.iter().map(|p| p[0]).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .start_handler(|_| TRACK.with(|t| t.set(true)))
        .build()
        .expect("pool");
    let count = pool.install(|| {
        TRACK.with(|t| t.set(true));
        let mut full = Sorter::new();
        let mut quant = Sorter::new().with_precision(Precision::Quantized { bits: 16 });
        // Warm up at the largest size.
        full.sort_by_distance(&positions, [0.0; 3]);
        full.sort_keys(&keys);
        quant.sort_by_distance(&positions, [0.0; 3]);
        ALLOCS.store(0, AtOrd::SeqCst);
        ARMED.store(true, AtOrd::SeqCst);
        let (bounds, frustum) = culled_view(&positions);
        let request = SortRequest::distance([0.0, 1.0, -3.0]);
        full.sort_visible(&positions, &bounds, &frustum, &request);
        ALLOCS.store(0, AtOrd::SeqCst);
        for i in 0..5 {
            let eye = [i as f32, 1.0, -3.0];
            full.sort_visible(&positions, &bounds, &frustum, &SortRequest::distance(eye));
            full.sort_by_distance(&positions, eye);
            full.sort_by_view_depth(&positions[..1000], eye, [0.0, 0.0, 1.0]);
            full.sort_keys(&keys);
            quant.sort_by_distance(&positions, eye);
        }
        ARMED.store(false, AtOrd::SeqCst);
        ALLOCS.load(AtOrd::SeqCst)
    });
    assert_eq!(count, 0, "allocations in warm sorts");
}

#[test]
fn quantized_sort_puts_infinities_at_the_ends() {
    let mut s = Sorter::new().with_precision(Precision::Quantized { bits: 16 });
    assert_eq!(s.sort_keys(&[1.0, f32::INFINITY]), &[1, 0]);
    assert_eq!(s.sort_keys(&[f32::NEG_INFINITY, 1.0]), &[1, 0]);
}

// ---------------------------------------------------------------- culled sorts

/// Cull radii (a few never visible) and a camera's frustum for `positions` (±10 cube): the
/// camera at (0, 1, −15) looks at (6, 0, 0), so part of the cube is out of view.
fn culled_view(positions: &[[f32; 3]]) -> (CullBounds, Frustum) {
    let radii = (0..positions.len())
        .map(|i| {
            if i % 97 == 0 {
                -1.0
            } else {
                (i % 11) as f32 * 0.05
            }
        })
        .collect();
    let cam = Camera::look_at(
        Vec3::new(0.0, 1.0, -15.0),
        Vec3::new(6.0, 0.0, 0.0),
        Vec3::Y,
        0.7,
        320,
        200,
    );
    (
        CullBounds::from_radii(radii),
        Frustum::from_camera(&cam, 0.2),
    )
}

/// The culled order is the full order with the culled splats left out (same keys, same
/// ties), for every mode and precision, and its reuse only fires for the same frustum.
#[test]
fn visible_sort_is_the_full_order_filtered() {
    let mut rng = Rng::new(41);
    let mut positions = random_positions(&mut rng, 90_000, 10.0);
    // Ties: duplicates of earlier means.
    for i in (0..positions.len()).step_by(13) {
        positions[i] = positions[i / 2];
    }
    positions[5] = [f32::NAN, 0.0, 0.0];
    let (bounds, frustum) = culled_view(&positions);
    let visible: Vec<bool> = positions
        .iter()
        .zip(bounds.radii())
        .map(|(p, r)| frustum.may_see(*p, *r))
        .collect();
    let seen = visible.iter().filter(|v| **v).count();
    assert!(seen > 10_000 && seen < 80_000, "{seen}");
    let eye = [0.0, 1.0, -15.0];
    let forward = [0.37, -0.06, 0.93];
    for precision in [Precision::Full, Precision::Quantized { bits: 16 }] {
        for (mode, request) in [
            (SortMode::Distance, SortRequest::distance(eye)),
            (
                SortMode::ViewDepth,
                SortRequest {
                    mode: SortMode::ViewDepth,
                    eye,
                    forward,
                },
            ),
        ] {
            let mut s = Sorter::new().with_precision(precision);
            let culled = s
                .sort_visible(&positions, &bounds, &frustum, &request)
                .to_vec();
            assert_eq!(culled.len(), seen);
            if precision == Precision::Full {
                let full = match mode {
                    SortMode::Distance => Sorter::new().sort_by_distance(&positions, eye).to_vec(),
                    SortMode::ViewDepth => Sorter::new()
                        .sort_by_view_depth(&positions, eye, forward)
                        .to_vec(),
                };
                let want: Vec<u32> = full.into_iter().filter(|&i| visible[i as usize]).collect();
                assert_eq!(culled, want, "{mode:?}");
            } else {
                let mut sorted = culled.clone();
                sorted.sort();
                let want: Vec<u32> = (0..positions.len() as u32)
                    .filter(|&i| visible[i as usize])
                    .collect();
                assert_eq!(sorted, want, "{mode:?} quantized: the visible set");
            }
        }
    }
    // Reuse: the same request and frustum reuse; another frustum (same eye) sorts again.
    let mut s = Sorter::new().with_reuse(Reuse::MotionBound);
    let request = SortRequest::distance(eye);
    let first = s
        .sort_visible(&positions, &bounds, &frustum, &request)
        .to_vec();
    s.sort_visible(&positions, &bounds, &frustum, &request);
    assert_eq!(s.last_outcome(), Outcome::ReusedSameView);
    let cam = Camera::look_at(Vec3::from_array(eye), Vec3::ZERO, Vec3::Y, 0.7, 320, 200);
    let other = Frustum::from_camera(&cam, 0.2);
    let second = s
        .sort_visible(&positions, &bounds, &other, &request)
        .to_vec();
    assert_eq!(s.last_outcome(), Outcome::Sorted);
    assert_ne!(first, second);
    // A full sort after a culled one does not reuse it.
    s.sort_by_distance(&positions, eye);
    assert_eq!(s.last_outcome(), Outcome::Sorted);
    assert_eq!(s.order().len(), positions.len());
}

/// The background sorter culls like `Sorter::sort_visible` when it has the bounds, and
/// keeps sorting everything for plain requests (and without bounds).
#[test]
fn async_sorter_culls_with_bounds() {
    let mut rng = Rng::new(43);
    let positions = random_positions(&mut rng, 50_000, 10.0);
    let (bounds, frustum) = culled_view(&positions);
    let request = SortRequest::distance([0.0, 1.0, -15.0]);
    let want = Sorter::new()
        .sort_visible(&positions, &bounds, &frustum, &request)
        .to_vec();
    let shared: Arc<[[f32; 3]]> = positions.clone().into();
    let mut bg = AsyncSorter::with_bounds(shared.clone(), Arc::new(bounds), Sorter::new()).unwrap();
    let g = bg.request_visible(request, frustum);
    let frame = bg.wait_for(g).unwrap();
    assert_eq!(frame.order(), &want[..]);
    assert_eq!(frame.frustum(), Some(frustum));
    let g = bg.request(request);
    let frame = bg.wait_for(g).unwrap();
    assert_eq!(frame.order().len(), positions.len());
    assert_eq!(frame.frustum(), None);
    let mut plain = AsyncSorter::new(shared, Sorter::new()).unwrap();
    let g = plain.request_visible(request, frustum);
    assert_eq!(plain.wait_for(g).unwrap().order().len(), positions.len());
}
