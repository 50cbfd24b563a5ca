//! `.ksplat` records → splats: each splat's record found in its section and its centre,
//! scale, rotation, colour and SH decoded at the file's compression level.

use super::{Section, component_bytes};
use crate::load::codec::{self, SplatMut, f16_to_f32};

/// Where each splat's record lies in the file and how its values are stored.
pub(super) struct Records<'a> {
    bytes: &'a [u8],
    secs: &'a [Section],
    /// Global splat index → section: start index of each section.
    starts: Vec<usize>,
    level: u16,
    /// Bytes per centre, scale and rotation component, and per SH value.
    cb: usize,
    shb: usize,
    /// The main header's SH range of level 2 (0 meaning ∓1.5).
    lo: f32,
    hi: f32,
}

impl<'a> Records<'a> {
    /// The records of `secs` in `bytes`, a level-`level` file.
    pub(super) fn new(bytes: &'a [u8], secs: &'a [Section], level: u16) -> Records<'a> {
        let (lo, hi) = match (codec::f32_at(bytes, 36), codec::f32_at(bytes, 40)) {
            (a, b) if a != 0.0 && b != 0.0 => (a, b),
            _ => (-1.5, 1.5),
        };
        let starts: Vec<usize> = secs
            .iter()
            .scan(0, |acc, s| {
                let st = *acc;
                *acc += s.count;
                Some(st)
            })
            .collect();
        let (cb, shb) = component_bytes(level);
        Records {
            bytes,
            secs,
            starts,
            level,
            cb,
            shb,
            lo,
            hi,
        }
    }

    /// Decodes global splat `g` into its slots.
    #[inline]
    pub(super) fn fill(&self, g: usize, s: SplatMut<'_>) {
        let (bytes, cb) = (self.bytes, self.cb);
        let si = self.starts.partition_point(|&st| st <= g) - 1;
        let sec = &self.secs[si];
        let i = g - self.starts[si];
        let r = &bytes[sec.data + i * sec.bytes_per_splat..][..sec.bytes_per_splat];
        let val = |k: usize| match cb {
            4 => codec::f32_at(r, 4 * k),
            _ => f16_to_f32(codec::u16_at(r, 2 * k)),
        };
        *s.position = if self.level == 0 {
            std::array::from_fn(|a| codec::f32_at(r, 4 * a))
        } else {
            let c = sec.centers + 12 * sec.bucket_of(i);
            std::array::from_fn(|a| {
                (codec::u16_at(r, 2 * a) as f32 - sec.range) * sec.factor
                    + codec::f32_at(bytes, c + 4 * a)
            })
        };
        *s.scale = std::array::from_fn(|a| val(3 + a));
        *s.rotation = [val(7), val(8), val(9), val(6)];
        let col = &r[10 * cb..];
        s.sh[0] = std::array::from_fn(|c| crate::sh::dc_from_color(col[c] as f64 / 255.0));
        *s.opacity = col[3] as f32 / 255.0;
        self.fill_sh(sec.degree, &col[4..], s.sh);
    }

    /// Decodes the higher SH of a record (`sh`, of a section of degree `degree`) into `out`:
    /// degree l's 2l+1 coefficients per channel, channel-major, one degree after another.
    #[inline]
    fn fill_sh(&self, degree: u8, sh: &[u8], out: &mut [[f32; 3]]) {
        let (lo, hi) = (self.lo, self.hi);
        let value = |k: usize| match self.shb {
            4 => codec::f32_at(sh, 4 * k),
            2 => f16_to_f32(codec::u16_at(sh, 2 * k)),
            _ => lo + sh[k] as f32 / 255.0 * (hi - lo),
        };
        let mut base = 0;
        for l in 1..=degree as usize {
            let m = 2 * l + 1;
            for (j, coef) in out[l * l..l * l + m].iter_mut().enumerate() {
                *coef = std::array::from_fn(|c| value(base + c * m + j));
            }
            base += 3 * m;
        }
    }
}
