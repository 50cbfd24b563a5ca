//! [`SplatCloud::select`]: the splats at given indices, as a new cloud (budgets, crops).

use super::SplatCloud;

impl SplatCloud {
    /// The splats at `indices` (each `< len()`), in that order, with this cloud's metadata.
    ///
    /// # Panics
    /// If an index is out of range.
    pub fn select(&self, indices: &[u32]) -> SplatCloud {
        let mut out = SplatCloud::with_capacity(self.sh_degree, indices.len());
        out.meta = self.meta.clone();
        for &i in indices {
            let i = i as usize;
            out.push(
                self.positions[i],
                self.scales[i],
                self.rotations[i],
                self.opacities[i],
                self.sh_of(i),
            );
        }
        out
    }
}
