//! The parallel LSD radix argsort core: per-chunk histograms, exclusive prefix sums, scatter.
//!
//! Input: one `u32` sort key per splat, in splat-index order, already mapped so that
//! *ascending* key order is the wanted draw order (see [`super::keys`]). Output: the splat
//! indices in ascending key order; equal keys keep ascending index order (LSD passes are
//! stable and the first pass reads the keys in index order).
//!
//! Layout of one sort:
//! 1. the caller fills `keys` and, fused in the same loop, per-chunk histograms of *every*
//!    digit ([`count_all`]);
//! 2. passes whose digit is the same for all keys are skipped (their histogram has one bucket
//!    holding all N);
//! 3. the first remaining pass scatters `(key << 32) | index` (one `u64`, so one write per
//!    element) from `keys` into buffer A; middle passes go A → B → A; the last pass writes only
//!    the low 32 bits (the index) into `out`. A pass after the first needs per-chunk counts of
//!    the current arrangement, so it counts its chunk before scattering it (a sequential read).
//!
//! Parallelism: the N elements are cut into `T` contiguous chunks (`T` = rayon threads, fewer
//! for small N); chunk `c` is counted and scattered by one rayon task. The destination of
//! element `e` of chunk `c` with digit `d` is `Σ_{d'<d} total[d'] + Σ_{c'<c} count[c'][d]` plus
//! the number of earlier elements of chunk `c` with digit `d`, so the writes of all tasks are
//! disjoint and cover `0..N` exactly once.

use rayon::prelude::*;

/// Most bits one pass handles (histogram size `2^MAX_DIGIT_BITS`).
pub(crate) const MAX_DIGIT_BITS: u32 = 11;
/// Buckets of one histogram.
pub(crate) const BUCKETS: usize = 1 << MAX_DIGIT_BITS;
/// Most passes (32 bits in 8-bit digits).
pub(crate) const MAX_PASSES: usize = 4;
/// Below this many elements per chunk, use fewer chunks (rayon overhead beats the gain).
const MIN_CHUNK: usize = 1 << 15;

/// Histograms per chunk: one per pass plus 3 spare tables for counting the top digit.
pub(crate) const STRIDE: usize = MAX_PASSES + 3;
/// Keys filled (then counted) at a time: 16 KiB, fits L1.
pub(crate) const BLOCK: usize = 4096;

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
    /// (nearly) equal width: 32 → 11+11+10 (max 11) or 4 × 8 (max 8); 16 → 2 × 8; 20 → 2 × 10.
    pub(crate) fn new(bits: u32, max_digit: u32) -> Self {
        let max_digit = max_digit.clamp(8, MAX_DIGIT_BITS);
        let bits = bits.clamp(1, 32);
        let passes = bits.div_ceil(max_digit) as usize;
        let mut d = Digits {
            passes,
            shift: [0; MAX_PASSES],
            mask: [0; MAX_PASSES],
        };
        let mut shift = 0;
        for p in 0..passes {
            let left = (passes - p) as u32;
            let w = (bits - shift).div_ceil(left);
            d.shift[p] = shift;
            d.mask[p] = (1u32 << w) - 1;
            shift += w;
        }
        d
    }

    /// The digit of `key` for pass `p` (always `< BUCKETS`).
    #[inline(always)]
    pub(crate) fn digit(&self, key: u32, p: usize) -> usize {
        ((key >> self.shift[p]) & self.mask[p]) as usize & (BUCKETS - 1)
    }
}

/// All buffers of the radix sort; grown on demand, never shrunk, so a sort of at most as many
/// elements as before allocates nothing.
#[derive(Debug, Default)]
pub(crate) struct RadixBuffers {
    /// Sort keys in splat-index order (filled by the caller).
    pub keys: Vec<u32>,
    /// Ping-pong buffers of `(key << 32) | index`.
    a: Vec<u64>,
    b: Vec<u64>,
    /// The result: indices in ascending key order.
    pub out: Vec<u32>,
    /// `hist[c * STRIDE + p]`: counts of pass `p`'s digit in chunk `c`.
    pub hist: Vec<Hist>,
}

/// Contiguous chunk `c` of `t` chunks over `0..n`.
#[inline]
pub(crate) fn chunk_range(c: usize, t: usize, n: usize) -> std::ops::Range<usize> {
    let len = n.div_ceil(t.max(1));
    (c * len).min(n)..((c + 1) * len).min(n)
}

/// How many chunks (= parallel tasks) to use for `n` elements.
pub(crate) fn chunk_count(n: usize) -> usize {
    rayon::current_num_threads().clamp(1, (n / MIN_CHUNK).max(1))
}

impl RadixBuffers {
    /// Sizes the buffers for `n` elements in `t` chunks (allocates only when growing) and
    /// zeroes the histograms.
    pub(crate) fn prepare(&mut self, n: usize, t: usize) {
        grow(&mut self.keys, n);
        grow(&mut self.out, n);
        if self.hist.len() < t * STRIDE {
            self.hist.resize(t * STRIDE, [0; BUCKETS]);
        }
        for h in &mut self.hist[..t * STRIDE] {
            h.fill(0);
        }
    }

    /// Sorts `keys[..n]` (already filled, with every chunk's histograms of every pass counted
    /// by the caller, chunked as [`chunk_range`]`(c, t, n)`) and leaves the indices in
    /// `out[..n]`.
    pub(crate) fn sort(&mut self, n: usize, t: usize, digits: &Digits) {
        let out = &mut self.out[..n];
        // Passes that actually reorder: skip those whose digit is constant.
        let mut live = [0usize; MAX_PASSES];
        let mut n_live = 0;
        for p in 0..digits.passes {
            let constant = (0..BUCKETS).any(|d| {
                (0..t)
                    .map(|c| self.hist[c * STRIDE + p][d] as usize)
                    .sum::<usize>()
                    == n
            });
            if !constant {
                live[n_live] = p;
                n_live += 1;
            }
        }
        if n_live == 0 {
            for (i, o) in out.iter_mut().enumerate() {
                *o = i as u32;
            }
            return;
        }
        if n_live > 1 {
            grow(&mut self.a, n);
        }
        if n_live > 2 {
            grow(&mut self.b, n);
        }
        let keys = &self.keys[..n];
        let hist = &mut self.hist[..t * STRIDE];
        let (a, b) = (&mut self.a, &mut self.b);

        for (k, &p) in live[..n_live].iter().enumerate() {
            let last = k + 1 == n_live;
            if k > 0 {
                // Per-chunk counts of the current arrangement (the first live pass reuses the
                // counts the caller made in index order).
                let src: &[u64] = if k % 2 == 1 { &a[..n] } else { &b[..n] };
                count_pass(src, hist, t, digits, p);
            }
            offsets(hist, t, p);
            match (k, last) {
                (0, true) => scatter(
                    keys,
                    out,
                    hist,
                    t,
                    p,
                    |key, _| digits.digit(key, p),
                    |_, i| i as u32,
                ),
                (0, false) => scatter(
                    keys,
                    &mut a[..n],
                    hist,
                    t,
                    p,
                    |key, _| digits.digit(key, p),
                    |key, i| (u64::from(key) << 32) | i as u64,
                ),
                (_, _) => {
                    let digit = |e: u64, _| digits.digit((e >> 32) as u32, p);
                    let (src, dst) = if k % 2 == 1 {
                        (&a[..], &mut b[..])
                    } else {
                        (&b[..], &mut a[..])
                    };
                    if last {
                        scatter(&src[..n], out, hist, t, p, digit, |e, _| e as u32);
                    } else {
                        scatter(&src[..n], &mut dst[..n], hist, t, p, digit, |e, _| e);
                    }
                }
            }
        }
    }
}

/// Grows `v` to at least `n` elements (never shrinks; new elements are zero).
pub(crate) fn grow<T: Copy + Default>(v: &mut Vec<T>, n: usize) {
    if v.len() < n {
        v.resize(n, T::default());
    }
}

/// Per-chunk counts of pass `p`'s digit over `src` (4 interleaved tables, summed, so that runs
/// of equal digits do not serialise on one counter).
fn count_pass(src: &[u64], hist: &mut [Hist], t: usize, digits: &Digits, p: usize) {
    let n = src.len();
    hist.par_chunks_mut(STRIDE).enumerate().for_each(|(c, h)| {
        let (main, extra) = h.split_at_mut(MAX_PASSES);
        let h = &mut main[p];
        let [e0, e1, e2] = extra else {
            unreachable!("STRIDE = MAX_PASSES + 3")
        };
        for table in [&mut *h, &mut *e0, &mut *e1, &mut *e2] {
            table.fill(0);
        }
        let digit = |e: u64| digits.digit((e >> 32) as u32, p);
        let mut quads = src[chunk_range(c, t, n)].chunks_exact(4);
        for q in &mut quads {
            h[digit(q[0])] += 1;
            e0[digit(q[1])] += 1;
            e1[digit(q[2])] += 1;
            e2[digit(q[3])] += 1;
        }
        for &e in quads.remainder() {
            h[digit(e)] += 1;
        }
        for d in 0..BUCKETS {
            h[d] += e0[d] + e1[d] + e2[d];
        }
    });
}

/// Turns pass `p`'s per-chunk counts into each chunk's first destination per digit.
fn offsets(hist: &mut [Hist], t: usize, p: usize) {
    let mut sum = 0u32;
    for d in 0..BUCKETS {
        for h in hist.iter_mut().skip(p).step_by(STRIDE).take(t) {
            let count = h[d];
            h[d] = sum;
            sum += count;
        }
    }
}

/// A raw destination pointer shared by the scatter tasks.
struct SharedMut<T>(*mut T);
impl<T> Clone for SharedMut<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for SharedMut<T> {}
// SAFETY: the tasks write disjoint positions (see `scatter`), and the pointer outlives them.
unsafe impl<T: Send> Send for SharedMut<T> {}
unsafe impl<T: Send> Sync for SharedMut<T> {}
impl<T> SharedMut<T> {
    #[inline(always)]
    fn get(self) -> *mut T {
        self.0
    }
}

/// Scatters every chunk of `src` into `dst` by its pass-`p` digit, starting at the chunk's
/// offsets in `hist`; `make(element, index)` is what gets written.
fn scatter<S, D>(
    src: &[S],
    dst: &mut [D],
    hist: &mut [Hist],
    t: usize,
    p: usize,
    digit: impl Fn(S, usize) -> usize + Sync,
    make: impl Fn(S, usize) -> D + Sync,
) where
    S: Copy + Sync,
    D: Send,
{
    let n = src.len();
    assert_eq!(dst.len(), n, "scatter: destination length");
    let dst = SharedMut(dst.as_mut_ptr());
    hist.par_chunks_mut(STRIDE).enumerate().for_each(|(c, h)| {
        let off = &mut h[p];
        let range = chunk_range(c, t, n);
        let base = range.start;
        for (i, &s) in src[range].iter().enumerate() {
            let d = digit(s, base + i);
            let o = off[d] as usize;
            off[d] += 1;
            // SAFETY: `offsets` gave chunk `c` the positions
            // `[Σ_{d'<d} total[d'] + Σ_{c'<c} count[c'][d], … + count[c][d])` for digit
            // `d`; they partition `0..n` over all chunks and digits, so `o < n` and no
            // other task writes position `o`.
            debug_assert!(o < n);
            unsafe { dst.get().add(o).write(make(s, base + i)) };
        }
    });
}

/// Fills `keys` (in blocks of [`BLOCK`] keys: `fill(first_index, block)`) and counts every
/// pass's digit per chunk, in parallel. Counting a block right after filling it reads it from
/// L1; the key computation itself is a plain loop the compiler can vectorise.
pub(crate) fn count_all(
    keys: &mut [u32],
    hist: &mut [Hist],
    t: usize,
    digits: &Digits,
    fill: impl Fn(usize, &mut [u32]) + Sync,
) {
    let n = keys.len();
    let len = n.div_ceil(t.max(1)).max(1);
    let top = digits.passes - 1;
    keys.par_chunks_mut(len)
        .zip(hist.par_chunks_mut(STRIDE))
        .enumerate()
        .for_each(|(c, (ks, h))| {
            let (main, extra) = h.split_at_mut(MAX_PASSES);
            let (lower, upper) = main.split_at_mut(top);
            let h_top = &mut upper[0];
            let [e0, e1, e2] = extra else {
                unreachable!("STRIDE = MAX_PASSES + 3")
            };
            for (b, block) in ks.chunks_mut(BLOCK).enumerate() {
                fill(c * len + b * BLOCK, block);
                for (p, hp) in lower.iter_mut().enumerate() {
                    for &k in block.iter() {
                        hp[digits.digit(k, p)] += 1;
                    }
                }
                // The most significant digit of float keys takes few values: spread its
                // counts over 4 tables so repeated increments do not wait on each other.
                let mut quads = block.chunks_exact(4);
                for q in &mut quads {
                    h_top[digits.digit(q[0], top)] += 1;
                    e0[digits.digit(q[1], top)] += 1;
                    e1[digits.digit(q[2], top)] += 1;
                    e2[digits.digit(q[3], top)] += 1;
                }
                for &k in quads.remainder() {
                    h_top[digits.digit(k, top)] += 1;
                }
            }
            for d in 0..BUCKETS {
                h_top[d] += e0[d] + e1[d] + e2[d];
            }
        });
}
