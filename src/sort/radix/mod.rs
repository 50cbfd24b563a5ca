//! The parallel radix argsort core: one parallel MSD pass, then LSD passes inside each bucket.
//!
//! Input: one `u32` key per splat in splat-index order, mapped so that *ascending* key order is
//! the wanted draw order (see [`super::keys`]). Output: the splat indices in ascending key
//! order; **equal keys keep ascending index order**, whatever the thread count.
//!
//! 1. [`fill_keys`]: the caller's key function fills `keys` in L1-sized blocks (a plain loop
//!    the compiler vectorises) while each chunk tracks its min and max key.
//! 2. Keys are rebased to `k − min`; only the `rbits` bits of the range `max − min` matter.
//!    The top `≤ 10` of those bits are the **MSD digit**, the rest (`low` bits) are sorted later.
//! 3. **MSD pass**, parallel over `T` contiguous chunks: per-chunk histograms of the MSD digit,
//!    exclusive prefix sums over (digit, chunk), scatter of `((k − min) << 32) | index` (one
//!    `u64` per element) into buffer A. Each chunk writes its elements of digit `d` in index
//!    order to its own sub-range, so the pass is stable and the writes of all tasks are
//!    disjoint and cover `0..N` exactly once.
//! 4. **Buckets**: each MSD bucket is now a contiguous range of A holding its elements in index
//!    order. Small buckets (the usual case) are sorted one task per group of buckets: a
//!    stable LSD radix sort of their `low` bits (≤ 11 bits a pass, passes with a constant digit
//!    skipped) that stays in L2, ping-ponging between the bucket's ranges of A and B and
//!    writing the indices of the last pass straight into `out`. Buckets too big for one task
//!    (more than `N / 2T`, e.g. a dense cluster) get parallel chunked LSD passes like step 3.
//!
//! Every step is a stable partition or a stable sort of disjoint ranges, so the output is the
//! unique order by `(key, index)`: deterministic and independent of `T`.

mod lsd;

use lsd::{parallel_lsd, sort_bucket};
use rayon::prelude::*;

/// Most bits one pass handles (histogram size `2^MAX_DIGIT_BITS`).
pub(crate) const MAX_DIGIT_BITS: u32 = 11;
/// Bits of the MSD digit: 1024 buckets. Measured against 9 and 11 at 1M and 4M: 11 bits (2048
/// destination streams) is slower at 4M (more pages written at once than the TLB holds), 9
/// leaves bigger buckets for the local passes.
const MSD_BITS: u32 = 10;
/// Buckets of one histogram.
pub(crate) const BUCKETS: usize = 1 << MAX_DIGIT_BITS;
/// Most LSD passes inside a bucket (21 low bits in 8-bit digits).
pub(crate) const MAX_PASSES: usize = 3;
/// Histograms per chunk/task: one per LSD pass plus 4 for the MSD digit (counted over four
/// interleaved tables so runs of equal digits do not serialise on one counter).
pub(crate) const STRIDE: usize = MAX_PASSES + 4;
/// Keys filled at a time: 16 KiB, fits L1.
pub(crate) const BLOCK: usize = 4096;
/// Below this many elements per chunk, use fewer chunks (rayon overhead beats the gain).
const MIN_CHUNK: usize = 1 << 15;
/// Buckets at most this small are always sorted by comparison (their `u64` items are
/// distinct, so any sort is the stable one).
const TINY: usize = 48;

/// One histogram (or one table of running offsets).
pub(crate) type Hist = [u32; BUCKETS];

/// The digits of a key: pass `p` sorts by `(key >> shift[p]) & mask[p]`, least significant
/// digit first.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Digits {
    pub passes: usize,
    pub shift: [u32; MAX_PASSES],
    pub mask: [u32; MAX_PASSES],
}

impl Digits {
    /// `bits`-bit keys cut into as few passes of at most `max_digit` bits as possible, of
    /// (nearly) equal width: 21 → 11 + 10, 14 → 7 + 7, 9 → 9.
    pub(crate) fn new(bits: u32, max_digit: u32) -> Self {
        let max_digit = max_digit.clamp(8, MAX_DIGIT_BITS);
        let passes = (bits.div_ceil(max_digit) as usize).min(MAX_PASSES);
        let mut d = Digits {
            passes,
            shift: [0; MAX_PASSES],
            mask: [0; MAX_PASSES],
        };
        let mut shift = 0;
        for p in 0..passes {
            let w = (bits - shift).div_ceil((passes - p) as u32);
            d.shift[p] = shift;
            d.mask[p] = (1u32 << w) - 1;
            shift += w;
        }
        d
    }

    /// The digit of item `e` (rebased key in the high 32 bits) for pass `p`, `< BUCKETS`.
    #[inline(always)]
    fn digit(&self, e: u64, p: usize) -> usize {
        ((((e >> 32) as u32) >> self.shift[p]) & self.mask[p]) as usize & (BUCKETS - 1)
    }
}

/// All buffers of the radix sort; grown on demand, never shrunk, so a sort of at most as many
/// elements as before allocates nothing.
#[derive(Debug, Default)]
pub(crate) struct RadixBuffers {
    /// Sort keys in splat-index order (filled by [`fill_keys`]).
    pub keys: Vec<u32>,
    /// Ping-pong buffers of `((key − min) << 32) | index`.
    a: Vec<u64>,
    b: Vec<u64>,
    /// The result: indices in ascending key order.
    pub out: Vec<u32>,
    /// `hist[c * STRIDE ..][..STRIDE]`: the tables of chunk / task `c`.
    hist: Vec<Hist>,
    /// Per-chunk (min, max) key.
    minmax: Vec<(u32, u32)>,
    /// Start of every MSD bucket in the sorted order, and the end.
    starts: Vec<u32>,
    /// First MSD bucket of every task, and the end.
    groups: Vec<usize>,
}

/// Contiguous chunk `c` of `t` chunks over `0..n`.
#[inline]
fn chunk_range(c: usize, t: usize, n: usize) -> std::ops::Range<usize> {
    let len = n.div_ceil(t.max(1));
    (c * len).min(n)..((c + 1) * len).min(n)
}

/// How many chunks (= parallel tasks) to use for `n` elements.
pub(crate) fn chunk_count(n: usize) -> usize {
    rayon::current_num_threads().clamp(1, (n / MIN_CHUNK).max(1))
}

/// Grows `v` to at least `n` elements (never shrinks; new elements are zero).
pub(crate) fn grow<T: Copy + Default>(v: &mut Vec<T>, n: usize) {
    if v.len() < n {
        v.resize(n, T::default());
    }
}

/// Fills `keys` in blocks of [`BLOCK`] (`fill(first_index, block)`) in `t` parallel chunks and
/// records each chunk's (min, max) key in `minmax`.
pub(crate) fn fill_keys(
    keys: &mut [u32],
    minmax: &mut [(u32, u32)],
    t: usize,
    fill: impl Fn(usize, &mut [u32]) + Sync,
) {
    let len = keys.len().div_ceil(t.max(1)).max(1);
    keys.par_chunks_mut(len)
        .zip(minmax.par_iter_mut())
        .enumerate()
        .for_each(|(c, (ks, mm))| {
            let (mut lo, mut hi) = (u32::MAX, 0u32);
            for (b, block) in ks.chunks_mut(BLOCK).enumerate() {
                fill(c * len + b * BLOCK, block);
                for &k in block.iter() {
                    lo = lo.min(k);
                    hi = hi.max(k);
                }
            }
            *mm = (lo, hi);
        });
}

/// A raw pointer shared by tasks that write provably disjoint positions.
struct SharedMut<T>(*mut T);
impl<T> Clone for SharedMut<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for SharedMut<T> {}
// SAFETY: users only write disjoint positions from different tasks (argued at each use), and
// the pointee outlives the tasks.
unsafe impl<T: Send> Send for SharedMut<T> {}
// SAFETY: as for `Send`: shared between tasks that write disjoint positions only.
unsafe impl<T: Send> Sync for SharedMut<T> {}
impl<T> SharedMut<T> {
    #[inline(always)]
    fn get(self) -> *mut T {
        self.0
    }
}

impl RadixBuffers {
    /// Sizes the buffers for `n` elements in `t` chunks (allocates only when growing).
    pub(crate) fn prepare(&mut self, n: usize, t: usize) {
        grow(&mut self.keys, n);
        grow(&mut self.out, n);
        grow(&mut self.a, n);
        grow(&mut self.b, n);
        if self.hist.len() < t * STRIDE {
            self.hist.resize(t * STRIDE, [0; BUCKETS]);
        }
        grow(&mut self.minmax, t);
        grow(&mut self.starts, BUCKETS + 1);
        grow(&mut self.groups, t + 1);
        self.minmax[..t].fill((u32::MAX, 0));
    }

    /// Per-chunk (min, max) tables for [`fill_keys`].
    pub(crate) fn keys_and_minmax(
        &mut self,
        n: usize,
        t: usize,
    ) -> (&mut [u32], &mut [(u32, u32)]) {
        (&mut self.keys[..n], &mut self.minmax[..t])
    }

    /// Sorts `keys[..n]` (filled by [`fill_keys`] in `t` chunks) into `out[..n]`: the
    /// positions `0..n` in ascending key order, or with `ids` (`n` ascending values, e.g. the
    /// visible splats) `ids[position]` — carried through the passes instead of a remap after.
    pub(crate) fn sort(&mut self, n: usize, t: usize, max_digit: u32, ids: Option<&[u32]>) {
        let ids = ids.map(|v| &v[..n]);
        let (kmin, kmax) = self.minmax[..t]
            .iter()
            .fold((u32::MAX, 0), |(a, b), &(l, h)| (a.min(l), b.max(h)));
        if n == 0 || kmin == kmax {
            for (i, o) in self.out[..n].iter_mut().enumerate() {
                *o = id(ids, i);
            }
            return;
        }
        let rbits = 32 - (kmax - kmin).leading_zeros();
        let msd_bits = rbits.min(MSD_BITS);
        let low = rbits - msd_bits;
        let msd = |k: u32| msd_digit(k, kmin, low);
        msd_offsets(
            &self.keys[..n],
            &mut self.hist[..t * STRIDE],
            &mut self.starts[..=BUCKETS],
            t,
            msd,
        );
        self.msd_scatter(n, t, kmin, low, ids);
        if low == 0 {
            return;
        }
        let digits = Digits::new(low, max_digit);
        let big = if t > 1 { n / (2 * t) } else { usize::MAX };
        self.sort_small_buckets(n, t, big, &digits);
        self.sort_big_buckets(n, t, big, &digits);
    }

    /// Step 3, the MSD scatter: every chunk writes its items to its own offsets (from
    /// [`msd_offsets`]), as `((k − kmin) << 32) | id` into A, or with no `low` bits left as
    /// the ids straight into `out`.
    fn msd_scatter(&mut self, n: usize, t: usize, kmin: u32, low: u32, ids: Option<&[u32]>) {
        let keys = &self.keys[..n];
        let hist = &mut self.hist[..t * STRIDE];
        let a = SharedMut(self.a.as_mut_ptr());
        let o = SharedMut(self.out[..n].as_mut_ptr());
        hist.par_chunks_mut(STRIDE).enumerate().for_each(|(c, h)| {
            let off = &mut h[MAX_PASSES];
            let range = chunk_range(c, t, n);
            let base = range.start;
            for (i, &k) in keys[range].iter().enumerate() {
                let d = msd_digit(k, kmin, low);
                let pos = off[d] as usize;
                off[d] += 1;
                debug_assert!(pos < n);
                // SAFETY: chunk `c` owns positions `[start_d + Σ_{c'<c} count[c'][d], … +
                // count[c][d])` of digit `d`; these partition `0..n`, so `pos < n` and no other
                // task writes `pos`.
                unsafe {
                    if low == 0 {
                        o.get().add(pos).write(id(ids, base + i));
                    } else {
                        a.get()
                            .add(pos)
                            .write((u64::from(k - kmin) << 32) | u64::from(id(ids, base + i)));
                    }
                }
            }
        });
    }

    /// Step 4, small buckets (at most `big` items): in `t` groups of about equal element
    /// count, one task per group, each bucket sorted by [`sort_bucket`] into `out`.
    fn sort_small_buckets(&mut self, n: usize, t: usize, big: usize, digits: &Digits) {
        let starts = &self.starts[..=BUCKETS];
        let size = |d: usize| (starts[d + 1] - starts[d]) as usize;
        let small_total: usize = (0..BUCKETS).map(size).filter(|&m| m <= big).sum();
        let groups = &mut self.groups[..=t];
        group_buckets(groups, small_total, big, t, size);
        let groups = &*groups;
        let a = SharedMut(self.a.as_mut_ptr());
        let o = SharedMut(self.out[..n].as_mut_ptr());
        // Each task's scratch for the middle passes: its own slice of B (B is free until the
        // big buckets), reused bucket after bucket so it stays in L1/L2.
        let cap = big.min(n).max(1);
        self.hist[..t * STRIDE]
            .par_chunks_mut(STRIDE)
            .zip(self.b[..t * cap].par_chunks_mut(cap))
            .enumerate()
            .for_each(|(c, (h, tmp))| {
                for d in groups[c]..groups[c + 1] {
                    let (s, e) = (starts[d] as usize, starts[d + 1] as usize);
                    if e - s <= big {
                        // SAFETY: bucket `d` is the range `s..e` of A and `out`; buckets are
                        // disjoint and each is handled by exactly one task (its group), so
                        // this task has exclusive access to those ranges.
                        unsafe { sort_bucket(a, &mut tmp[..e - s], o, s, digits, h) };
                    }
                }
            });
    }

    /// Step 4, big buckets (more than `big` items): each sorted with parallel chunked LSD
    /// passes ([`parallel_lsd`]) into `out`.
    fn sort_big_buckets(&mut self, n: usize, t: usize, big: usize, digits: &Digits) {
        let out = &mut self.out[..n];
        let hist = &mut self.hist[..t * STRIDE];
        for d in 0..BUCKETS {
            let (s, e) = (self.starts[d] as usize, self.starts[d + 1] as usize);
            if e - s > big {
                let (a, b) = (&mut self.a[s..e], &mut self.b[s..e]);
                parallel_lsd(a, b, &mut out[s..e], hist, t, digits);
            }
        }
    }
}

/// The id of position `j`: `ids[j]`, or `j` itself without `ids`.
#[inline(always)]
fn id(ids: Option<&[u32]>, j: usize) -> u32 {
    ids.map_or(j as u32, |v| v[j])
}

/// The MSD digit of key `k`: the top bits of `k − kmin` above its `low` bits.
#[inline(always)]
fn msd_digit(k: u32, kmin: u32, low: u32) -> usize {
    ((k - kmin) >> low) as usize & (BUCKETS - 1)
}

/// MSD counts per chunk (`h[MAX_PASSES]` of every chunk's tables, counted over four
/// interleaved tables), then turned into each chunk's first output position per digit, and
/// the start of every MSD bucket (`starts[BUCKETS]` = `n`).
fn msd_offsets(
    keys: &[u32],
    hist: &mut [Hist],
    starts: &mut [u32],
    t: usize,
    msd: impl Fn(u32) -> usize + Sync,
) {
    let n = keys.len();
    hist.par_chunks_mut(STRIDE).enumerate().for_each(|(c, h)| {
        let [h0, h1, h2, h3] = &mut h[MAX_PASSES..] else {
            unreachable!("STRIDE = MAX_PASSES + 4")
        };
        for table in [&mut *h0, &mut *h1, &mut *h2, &mut *h3] {
            table.fill(0);
        }
        let mut quads = keys[chunk_range(c, t, n)].chunks_exact(4);
        for q in &mut quads {
            h0[msd(q[0])] += 1;
            h1[msd(q[1])] += 1;
            h2[msd(q[2])] += 1;
            h3[msd(q[3])] += 1;
        }
        for &k in quads.remainder() {
            h0[msd(k)] += 1;
        }
        for d in 0..BUCKETS {
            h0[d] += h1[d] + h2[d] + h3[d];
        }
    });
    let mut sum = 0u32;
    for (d, start) in starts.iter_mut().enumerate().take(BUCKETS) {
        *start = sum;
        for h in hist.chunks_mut(STRIDE) {
            let count = h[MAX_PASSES][d];
            h[MAX_PASSES][d] = sum;
            sum += count;
        }
    }
    starts[BUCKETS] = sum;
}

/// Splits the MSD buckets into `t` groups of about equal count of elements in small buckets
/// (`size(d) <= big`): task `c` sorts buckets `groups[c]..groups[c + 1]`.
fn group_buckets(
    groups: &mut [usize],
    small_total: usize,
    big: usize,
    t: usize,
    size: impl Fn(usize) -> usize,
) {
    let (mut g, mut acc) = (1, 0);
    groups.fill(BUCKETS);
    groups[0] = 0;
    for d in 0..BUCKETS {
        while g < t && acc >= small_total * g / t {
            groups[g] = d;
            g += 1;
        }
        if size(d) <= big {
            acc += size(d);
        }
    }
}
