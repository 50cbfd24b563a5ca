//! The LSD passes of the radix argsort (step 4 of the [parent module](super)): a stable
//! LSD sort of one small MSD bucket inside one task, and chunked parallel LSD passes for a
//! bucket too big for one task.

use super::{BUCKETS, Digits, Hist, MAX_PASSES, STRIDE, SharedMut, TINY, chunk_range};
use rayon::prelude::*;

/// Stable LSD sort of the `tmp.len()` items at `a[s..]` by their `digits`, indices to
/// `out[s..]`, using `tmp` as scratch and `h` for histograms.
///
/// # Safety
/// `s + tmp.len()` is within `a` and `out` and no other thread accesses those ranges meanwhile.
pub(super) unsafe fn sort_bucket(
    a: SharedMut<u64>,
    b: &mut [u64],
    out: SharedMut<u32>,
    s: usize,
    digits: &Digits,
    h: &mut [Hist],
) {
    let m = b.len();
    // SAFETY: the caller guarantees exclusive access to these ranges.
    let (a, out) = unsafe {
        (
            std::slice::from_raw_parts_mut(a.get().add(s), m),
            std::slice::from_raw_parts_mut(out.get().add(s), m),
        )
    };
    // Below about an eighth of the table entries a comparison sort beats clearing and
    // prefix-summing the radix tables.
    let entries: usize = (0..digits.passes).map(|p| table_len(digits, p)).sum();
    if m <= TINY.max(entries / 8) {
        // Items are distinct (the index is in the low bits): any sort is the stable one.
        a.sort_unstable();
        copy_indices(out, a);
        return;
    }
    count_digits(a, digits, h);
    let (live, n_live) = live_passes(h, digits, m);
    if n_live == 0 {
        copy_indices(out, a);
        return;
    }
    for (k, &p) in live[..n_live].iter().enumerate() {
        let off = &mut h[p];
        exclusive_prefix_sum(&mut off[..table_len(digits, p)]);
        let (src, dst) = if k % 2 == 0 {
            (&*a, &mut *b)
        } else {
            (&*b, &mut *a)
        };
        // SAFETY: the offsets come from counting these very items (`src` holds the same `m`
        // items as `a`), and `out` and `dst` are `m` long.
        unsafe {
            if k + 1 == n_live {
                scatter(src, out, off, digits, p, |e| e as u32);
            } else {
                scatter(src, dst, off, digits, p, |e| e);
            }
        }
    }
}

/// Entries of pass `p`'s table that are used: `mask + 1`.
#[inline(always)]
fn table_len(digits: &Digits, p: usize) -> usize {
    digits.mask[p] as usize + 1
}

/// Writes the indices (low 32 bits) of the items `a` to `out`, in order.
#[inline(always)]
fn copy_indices(out: &mut [u32], a: &[u64]) {
    for (o, &e) in out.iter_mut().zip(a.iter()) {
        *o = e as u32;
    }
}

/// Clears the used part of every pass's table in `h` and counts the digits of the items `a`
/// (both digits in one sweep for two passes).
#[inline(always)]
fn count_digits(a: &[u64], digits: &Digits, h: &mut [Hist]) {
    let passes = digits.passes;
    for (p, table) in h[..passes].iter_mut().enumerate() {
        table[..table_len(digits, p)].fill(0);
    }
    if let [h0, h1, ..] = h {
        if passes == 2 {
            for &e in a.iter() {
                h0[digits.digit(e, 0)] += 1;
                h1[digits.digit(e, 1)] += 1;
            }
        } else {
            for &e in a.iter() {
                h0[digits.digit(e, 0)] += 1;
            }
            for p in 1..passes {
                for &e in a.iter() {
                    h[p][digits.digit(e, p)] += 1;
                }
            }
        }
    }
}

/// The passes whose digit is not the same for all `m` items (the others are skipped), and
/// how many there are.
#[inline(always)]
fn live_passes(h: &[Hist], digits: &Digits, m: usize) -> ([usize; MAX_PASSES], usize) {
    let mut live = [0usize; MAX_PASSES];
    let mut n_live = 0;
    for p in 0..digits.passes {
        if !h[p][..table_len(digits, p)]
            .iter()
            .any(|&c| c as usize == m)
        {
            live[n_live] = p;
            n_live += 1;
        }
    }
    (live, n_live)
}

/// Turns the counts `off` into exclusive prefix sums: each digit's first position.
#[inline(always)]
fn exclusive_prefix_sum(off: &mut [u32]) {
    let mut sum = 0;
    for c in off.iter_mut() {
        let count = *c;
        *c = sum;
        sum += count;
    }
}

/// One scatter of an LSD pass: each item `e` of `src` in order goes to `dst` as `item(e)` at
/// the running offset `off` of its digit `p`.
///
/// # Safety
/// `off` holds the exclusive prefix sums of the digit-`p` counts of exactly the items of
/// `src` (so every position is `< src.len()`), and `dst` is at least `src.len()` long.
#[inline(always)]
unsafe fn scatter<T>(
    src: &[u64],
    dst: &mut [T],
    off: &mut Hist,
    digits: &Digits,
    p: usize,
    item: impl Fn(u64) -> T,
) {
    for &e in src {
        let d = digits.digit(e, p);
        let pos = off[d] as usize;
        off[d] += 1;
        debug_assert!(pos < dst.len());
        // SAFETY: `pos < src.len() <= dst.len()` (see the contract).
        unsafe { *dst.get_unchecked_mut(pos) = item(e) };
    }
}

/// Stable LSD sort of the items `a` by their `digits` with every pass split over `t` chunks:
/// count per chunk, offsets, scatter (A → B → A …, the last pass writes indices to `out`).
pub(super) fn parallel_lsd(
    a: &mut [u64],
    b: &mut [u64],
    out: &mut [u32],
    hist: &mut [Hist],
    t: usize,
    digits: &Digits,
) {
    let n = a.len();
    let mut src_is_a = true;
    let mut wrote_out = false;
    for p in 0..digits.passes {
        let last = p + 1 == digits.passes;
        let src: &[u64] = if src_is_a { &*a } else { &*b };
        hist.par_chunks_mut(STRIDE).enumerate().for_each(|(c, h)| {
            let h = &mut h[p];
            h.fill(0);
            for &e in &src[chunk_range(c, t, n)] {
                h[digits.digit(e, p)] += 1;
            }
        });
        let constant =
            (0..BUCKETS).any(|d| hist.chunks(STRIDE).map(|h| h[p][d] as usize).sum::<usize>() == n);
        if constant {
            continue;
        }
        let mut sum = 0u32;
        for d in 0..BUCKETS {
            for h in hist.chunks_mut(STRIDE) {
                let count = h[p][d];
                h[p][d] = sum;
                sum += count;
            }
        }
        let (src, dst): (&[u64], &mut [u64]) = if src_is_a {
            (&*a, &mut *b)
        } else {
            (&*b, &mut *a)
        };
        let dst = SharedMut(dst.as_mut_ptr());
        let o = SharedMut(out.as_mut_ptr());
        let to_out = last;
        hist.par_chunks_mut(STRIDE).enumerate().for_each(|(c, h)| {
            let off = &mut h[p];
            for &e in &src[chunk_range(c, t, n)] {
                let d = digits.digit(e, p);
                let pos = off[d] as usize;
                off[d] += 1;
                debug_assert!(pos < n);
                // SAFETY: as in the MSD pass, chunk `c` owns its own positions of digit `d`,
                // and all chunks' positions partition `0..n`.
                unsafe {
                    if to_out {
                        o.get().add(pos).write(e as u32);
                    } else {
                        dst.get().add(pos).write(e);
                    }
                }
            }
        });
        if last {
            wrote_out = true;
        } else {
            src_is_a = !src_is_a;
        }
    }
    if !wrote_out {
        // The last pass(es) had a constant digit: the current source is already sorted.
        let src: &[u64] = if src_is_a { &*a } else { &*b };
        for (o, &e) in out.iter_mut().zip(src) {
            *o = e as u32;
        }
    }
}
