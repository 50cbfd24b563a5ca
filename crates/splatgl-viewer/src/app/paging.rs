//! A streamed tileset on the GPU: the renderer's paged storage and its [`PageTable`]. Each
//! new selection writes only the pages of tiles that were not resident; the draw order, sorted
//! over the selection's splats, is mapped to their slots before it is uploaded.

use std::sync::Arc;

use splatgl::cloud::SplatCloud;
use splatgl::gl::SplatRenderer;
use splatgl::tiles::pages::{PAGE, PageTable, pages_for};

/// The pages of a streamed tileset.
#[derive(Debug)]
pub(super) struct Paged {
    table: PageTable,
    degree: u8,
    /// Slot of each splat of the current selection (the sorter's indices).
    slots: Vec<u32>,
    /// The last order, mapped to slots (reused: no allocation per frame).
    mapped: Vec<u32>,
}

/// What one placement did (printed with the stream's counts).
#[derive(Debug, Clone, Copy)]
pub(super) struct Placed {
    /// Pages written now.
    pub(super) written: usize,
    /// Splats written now.
    pub(super) splats_written: usize,
    /// Pages holding tiles, and in all.
    pub(super) used: usize,
    pub(super) pages: usize,
    /// Tiles evicted from the GPU to make room.
    pub(super) evicted: usize,
    /// Whether the storage was (re)allocated (everything written again).
    pub(super) reallocated: bool,
}

impl Placed {
    /// One line, as the viewer prints it.
    pub(super) fn summary(&self) -> String {
        format!(
            "gpu: {} pages written ({} splats){}, {} of {} pages used, {} tiles evicted",
            self.written,
            self.splats_written,
            if self.reallocated {
                ", storage allocated"
            } else {
                ""
            },
            self.used,
            self.pages,
            self.evicted
        )
    }
}

impl Paged {
    /// `order` (indices into the selection) as slots.
    pub(super) fn map(&mut self, order: &[u32]) -> &[u32] {
        self.mapped.clear();
        let slots = &self.slots;
        self.mapped.extend(
            order
                .iter()
                .map(|&i| slots.get(i as usize).copied().unwrap_or(0)),
        );
        &self.mapped
    }
}

/// Places `tiles` (a selection, in order) in the renderer's pages: into the current storage
/// when it has room (evicting unused tiles) and the SH degree fits, else into new storage
/// sized for the selection and the budget, written whole.
pub(super) fn place(
    renderer: &mut SplatRenderer,
    gl: &glow::Context,
    paged: &mut Option<Paged>,
    tiles: &[(String, Arc<SplatCloud>)],
    budget: u64,
) -> Result<Placed, String> {
    let sel: Vec<(&str, usize)> = tiles.iter().map(|(p, c)| (p.as_str(), c.len())).collect();
    let degree = tiles.iter().map(|(_, c)| c.sh_degree).max().unwrap_or(0);
    let mut reallocated = false;
    let placement = match paged.as_mut() {
        Some(p) if p.degree >= degree && renderer.pages() == p.table.pages() => p.table.place(&sel),
        _ => None,
    };
    let placement = match placement {
        Some(pl) => pl,
        None => {
            let needed: usize = sel.iter().map(|(_, n)| pages_for(*n)).sum::<usize>().max(1);
            let old = paged.as_ref().map_or(0, |p| p.table.pages());
            // Room for the budget in tiles of this selection's size (pages per splat as now).
            let splats: usize = sel.iter().map(|(_, n)| n).sum::<usize>().max(1);
            let per_splat = needed as f64 / splats as f64;
            let budget_pages = (budget as f64 * per_splat).ceil().min(1e9) as usize + sel.len();
            // Half as much again keeps recently used tiles on the GPU for when the view
            // returns.
            let want = (budget_pages.min(4 * needed + 64) + budget_pages / 2)
                .max(needed + needed / 2)
                .max(2 * old);
            let colour = tiles
                .iter()
                .find(|(_, c)| !c.is_empty())
                .map_or(Default::default(), |(_, c)| c.meta.color_space.effective());
            let degree = degree.max(paged.as_ref().map_or(0, |p| p.degree));
            let pages = match renderer.allocate_pages(gl, want, degree, colour) {
                Ok(()) => want,
                Err(_) => {
                    renderer
                        .allocate_pages(gl, needed, degree, colour)
                        .map_err(|e| e.to_string())?;
                    needed
                }
            };
            reallocated = true;
            let mut table = PageTable::new(pages);
            let pl = table
                .place(&sel)
                .ok_or("the selection does not fit the pages allocated for it")?;
            *paged = Some(Paged {
                table,
                degree,
                slots: Vec::new(),
                mapped: Vec::new(),
            });
            pl
        }
    };
    let mut splats_written = 0;
    for w in &placement.writes {
        let cloud = &tiles[w.tile].1;
        if let Err(e) = renderer.write_page(gl, w.page as usize, cloud, w.first) {
            // The table no longer says what the pages hold: start again next time.
            *paged = None;
            return Err(e.to_string());
        }
        splats_written += cloud.len().saturating_sub(w.first).min(PAGE);
    }
    let p = paged.as_mut().ok_or("no pages")?;
    p.slots = placement.slots;
    Ok(Placed {
        written: placement.writes.len(),
        splats_written,
        used: p.table.used_pages(),
        pages: p.table.pages(),
        evicted: placement.evicted,
        reallocated,
    })
}
