//! Frame statistics for the title bar (frame time average and 99th percentile over the last
//! second, sort time, staleness) and the `--bench-frames` summary.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use splatgl::sort::Freshness;

/// The frames of the last second.
#[derive(Debug, Default)]
pub struct Stats {
    frames: VecDeque<(Instant, f32, f32)>,
    /// Scratch for percentiles (kept to avoid an allocation per title update).
    scratch: Vec<f32>,
    /// How the last frame's order was obtained.
    pub last: Option<Freshness>,
}

/// The value at quantile `q` (0..=1, nearest rank) of `v` (sorted in place); 0 when empty.
pub fn quantile(v: &mut [f32], q: f64) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f32::total_cmp);
    let rank = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len());
    v[rank - 1]
}

impl Stats {
    /// Records a frame that took `frame` and whose order took `sort` to sort.
    pub fn push(&mut self, now: Instant, frame: Duration, sort: Duration, fresh: Freshness) {
        self.frames
            .push_back((now, frame.as_secs_f32() * 1e3, sort.as_secs_f32() * 1e3));
        while let Some(&(t, ..)) = self.frames.front() {
            if now.duration_since(t) > Duration::from_secs(1) {
                self.frames.pop_front();
            } else {
                break;
            }
        }
        self.last = Some(fresh);
    }

    /// Frames per second, mean frame ms, p99 frame ms and mean sort ms over the last second.
    pub fn summary(&mut self) -> (f32, f32, f32, f32) {
        let n = self.frames.len();
        if n == 0 {
            return (0.0, 0.0, 0.0, 0.0);
        }
        self.scratch.clear();
        self.scratch.extend(self.frames.iter().map(|f| f.1));
        let mean = self.scratch.iter().sum::<f32>() / n as f32;
        let sort = self.frames.iter().map(|f| f.2).sum::<f32>() / n as f32;
        let p99 = quantile(&mut self.scratch, 0.99);
        (1e3 / mean.max(1e-3), mean, p99, sort)
    }

    /// How the last frame's order was obtained: `exact`, `stale (0.012 moved)`, `waited`.
    pub fn order_text(&self) -> String {
        match self.last {
            Some(Freshness::Exact) => "exact".to_owned(),
            Some(Freshness::Waited) => "waited".to_owned(),
            Some(Freshness::Stale { moved }) => format!("stale ({moved:.3} moved)"),
            None => String::new(),
        }
    }

    /// The title's statistics part: `12.3 fps (81.2 ms, p99 95.0 ms) · sort 1.2 ms · order
    /// exact`.
    pub fn title_part(&mut self) -> String {
        let (fps, mean, p99, sort) = self.summary();
        let fresh = self.order_text();
        format!("{fps:.1} fps ({mean:.1} ms, p99 {p99:.1} ms) · sort {sort:.2} ms · order {fresh}")
    }
}

/// Thousands separators: 152746 → "152,746".
pub fn thousands(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// What `--bench-frames` measured.
#[derive(Debug, Default)]
pub struct BenchLog {
    /// Frame times, ms.
    pub frames: Vec<f32>,
    /// Sort times of the orders drawn, ms.
    pub sorts: Vec<f32>,
    /// Frames drawn with an exact / stale / waited-for order.
    pub exact: usize,
    /// See `exact`.
    pub stale: usize,
    /// See `exact`.
    pub waited: usize,
    /// CPU time of the interface per frame, ms (`--bench-panel`).
    pub ui: Vec<f32>,
    /// Of these, the layout times of the frames that laid it out (the others reused the
    /// last layout), and the painting times of every frame.
    pub ui_layout: Vec<f32>,
    /// See `ui_layout`.
    pub ui_paint: Vec<f32>,
}

impl BenchLog {
    /// Records one frame.
    pub fn push(&mut self, frame: Duration, sort: Duration, fresh: Freshness) {
        self.frames.push(frame.as_secs_f32() * 1e3);
        self.sorts.push(sort.as_secs_f32() * 1e3);
        match fresh {
            Freshness::Exact => self.exact += 1,
            Freshness::Stale { .. } => self.stale += 1,
            Freshness::Waited => self.waited += 1,
        }
    }

    /// Records the interface's CPU time of one frame (layout zero: a reused layout).
    pub fn push_panel(&mut self, layout: Duration, paint: Duration) {
        let ms = |d: Duration| d.as_secs_f32() * 1e3;
        self.ui.push(ms(layout + paint));
        self.ui_paint.push(ms(paint));
        if !layout.is_zero() {
            self.ui_layout.push(ms(layout));
        }
    }

    /// The report: frame time min/median/p99, sort median/p99, order counts, the GL strings.
    pub fn report(&mut self, what: &str, gl_info: &str) -> String {
        let n = self.frames.len();
        let min = self.frames.iter().copied().fold(f32::INFINITY, f32::min);
        let med = quantile(&mut self.frames, 0.5);
        let p99 = quantile(&mut self.frames, 0.99);
        let smed = quantile(&mut self.sorts, 0.5);
        let sp99 = quantile(&mut self.sorts, 0.99);
        let ui = if self.ui.is_empty() {
            String::new()
        } else {
            let (umed, up99) = (quantile(&mut self.ui, 0.5), quantile(&mut self.ui, 0.99));
            let (n, laid) = (self.ui.len(), self.ui_layout.len());
            let lmed = quantile(&mut self.ui_layout, 0.5);
            let lp99 = quantile(&mut self.ui_layout, 0.99);
            let pmed = quantile(&mut self.ui_paint, 0.5);
            format!(
                "; panel CPU ms median {umed:.3} p99 {up99:.3}: layout in {laid} of {n} frames \
                 (median {lmed:.3} p99 {lp99:.3}), paint median {pmed:.3}"
            )
        };
        let peak = splatgl::files::peak_memory().map_or(String::new(), |b| {
            format!("; peak memory {} MB", b.div_ceil(1 << 20))
        });
        format!(
            "bench: {what}: {n} frames: frame ms min {min:.2} median {med:.2} p99 {p99:.2}; \
             sort ms median {smed:.2} p99 {sp99:.2}; orders exact {} stale {} waited {}{ui}{peak}\n\
             bench: GL: {gl_info}",
            self.exact, self.stale, self.waited
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thousands_separators() {
        assert_eq!(thousands(152_746), "152,746");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1_000_000), "1,000,000");
    }

    #[test]
    fn quantiles_use_nearest_rank() {
        let mut v: Vec<f32> = (1..=100).rev().map(|x| x as f32).collect();
        assert_eq!(quantile(&mut v, 0.5), 50.0);
        assert_eq!(quantile(&mut v, 0.99), 99.0);
        assert_eq!(quantile(&mut v, 1.0), 100.0);
        assert_eq!(quantile(&mut [], 0.5), 0.0);
    }
}
