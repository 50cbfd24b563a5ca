//! The culled sort: only the splats a view may see ([`crate::cull`]) are keyed and sorted.

use rayon::prelude::*;

use super::radix::chunk_count;
use super::{
    LastView, Outcome, Precision, SortMode, SortRequest, Sorter, far_first_key, radix,
    squared_distance, view_depth,
};
use crate::cull::{CullBounds, Frustum, visible_into};

impl Sorter {
    /// The splats of `positions` that `frustum` may see (with their cull radii `bounds`,
    /// [`CullBounds::new`] of the same cloud), back to front for `request`: exactly the
    /// full order of [`Sorter::sort_by_distance`] / [`Sorter::sort_by_view_depth`] with the
    /// culled splats left out (same keys, same ties by ascending index), so an image drawn
    /// from it equals one drawn from the full order (the cull is conservative). Costs one
    /// pass over all splats (≈ 20 flops each); keys and sort run over the visible ones only.
    ///
    /// Reuse: [`Reuse::SameView`](super::Reuse::SameView) and `MotionBound` reuse the last
    /// order only for the bit-identical request and frustum (no motion bound: a culled order
    /// is valid for its own frustum only).
    ///
    /// # Panics
    /// If `bounds` does not have one radius per position.
    pub fn sort_visible(
        &mut self,
        positions: &[[f32; 3]],
        bounds: &CullBounds,
        frustum: &Frustum,
        request: &SortRequest,
    ) -> &[u32] {
        let SortRequest { mode, eye, forward } = *request;
        let cull = Some((bounds.radii().as_ptr() as usize, *frustum));
        let view = LastView::new(positions, mode, self.precision, eye, forward, cull);
        if self.reuse_last(&view) {
            return self.order();
        }
        if bounds.all_visible(frustum) {
            // Every splat is in view: the full sort, with nothing to test or map.
            assert_eq!(bounds.len(), positions.len(), "one cull radius per splat");
            self.sort_positions(positions, mode, eye, forward);
            self.last = Some(view);
            return self.order();
        }
        let mut ids = std::mem::take(&mut self.scratch.visible);
        let m = visible_into(frustum, positions, bounds, &mut ids);
        let visible = &ids[..m];
        match self.precision {
            // Keys straight from the visible splats' means; the radix carries their indices.
            Precision::Full => {
                let t = chunk_count(m);
                let key = |i: u32| {
                    let p = positions[i as usize];
                    far_first_key(match mode {
                        SortMode::Distance => squared_distance(p, eye),
                        SortMode::ViewDepth => view_depth(p, eye, forward),
                    })
                };
                let fill = |start: usize, block: &mut [u32]| {
                    for (k, &i) in block.iter_mut().zip(&visible[start..]) {
                        *k = key(i);
                    }
                };
                self.sort_u32_ids(m, t, fill, Some(visible));
                self.outcome = Outcome::Sorted;
            }
            // Quantized: the visible means gathered, sorted by the shared core, mapped back.
            Precision::Quantized { .. } => {
                let mut vis = std::mem::take(&mut self.scratch.visible_positions);
                radix::grow(&mut vis, m);
                vis[..m]
                    .par_iter_mut()
                    .zip(visible)
                    .for_each(|(v, &i)| *v = positions[i as usize]);
                self.sort_positions(&vis[..m], mode, eye, forward);
                self.scratch.radix.out[..m]
                    .par_iter_mut()
                    .for_each(|o| *o = visible[*o as usize]);
                self.scratch.visible_positions = vis;
            }
        }
        self.scratch.visible = ids;
        self.last = Some(view);
        self.order()
    }
}
