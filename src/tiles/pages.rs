//! Which GPU pages hold which tile, for the viewer's streamed tilesets: GPU memory is a fixed
//! number of pages of [`PAGE`] splat slots ((the GL backend's `SplatRenderer::allocate_pages`));
//! each resident tile holds ⌈splats / PAGE⌉ pages of its own. A new selection places the tiles
//! that are not resident into free pages — evicting resident tiles it does not use, least
//! recently used first — and leaves every other tile where it is, so loading or evicting a
//! tile never re-uploads the rest. The draw order is then over slots: splat `i` of the
//! selection (its tiles' splats in selection order) is slot [`Placement::slots`]`[i]`.

use std::collections::HashMap;

/// Splat slots per page ([`crate::profile::PAGE_SPLATS`]).
pub const PAGE: usize = crate::profile::PAGE_SPLATS;

/// The page table of one GPU storage.
#[derive(Debug)]
pub struct PageTable {
    pages: usize,
    free: Vec<u32>,
    tiles: HashMap<String, Placed>,
    tick: u64,
}

/// One resident tile's pages and when a selection last used it.
#[derive(Debug)]
struct Placed {
    pages: Vec<u32>,
    used: u64,
}

/// A page to write: splats `first .. first + PAGE` of selected tile `tile` go to `page`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PageWrite {
    /// Index of the tile in the selection.
    pub tile: usize,
    /// Its first splat written.
    pub first: usize,
    /// The page.
    pub page: u32,
}

/// Where a selection lives.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Placement {
    /// Pages to write now (the tiles that were not resident).
    pub writes: Vec<PageWrite>,
    /// The slot of each selected splat, in selection order.
    pub slots: Vec<u32>,
    /// Resident tiles evicted to make room.
    pub evicted: usize,
}

/// Pages a tile of `splats` splats takes.
pub fn pages_for(splats: usize) -> usize {
    splats.div_ceil(PAGE)
}

impl PageTable {
    /// A table of `pages` free pages.
    pub fn new(pages: usize) -> Self {
        PageTable {
            pages,
            free: (0..pages as u32).rev().collect(),
            tiles: HashMap::new(),
            tick: 0,
        }
    }

    /// Pages in all.
    pub fn pages(&self) -> usize {
        self.pages
    }

    /// Pages holding a tile.
    pub fn used_pages(&self) -> usize {
        self.pages - self.free.len()
    }

    /// Tiles resident.
    pub fn resident_tiles(&self) -> usize {
        self.tiles.len()
    }

    /// Places a selection (`(tile id, splats)` in selection order; ids distinct). `None` when
    /// it needs more pages than the table has, even with every unused tile evicted (the table
    /// is then unchanged): allocate a larger one.
    pub fn place(&mut self, selection: &[(&str, usize)]) -> Option<Placement> {
        let needed: usize = selection
            .iter()
            .filter(|(id, _)| !self.tiles.contains_key(*id))
            .map(|(_, n)| pages_for(*n))
            .sum();
        let kept: usize = selection
            .iter()
            .filter_map(|(id, _)| self.tiles.get(*id))
            .map(|p| p.pages.len())
            .sum();
        if needed + kept > self.pages {
            return None;
        }
        self.tick += 1;
        let mut evicted = 0;
        if needed > self.free.len() {
            let wanted: std::collections::HashSet<&str> =
                selection.iter().map(|(id, _)| *id).collect();
            let mut unused: Vec<(u64, String)> = self
                .tiles
                .iter()
                .filter(|(id, _)| !wanted.contains(id.as_str()))
                .map(|(id, p)| (p.used, id.clone()))
                .collect();
            unused.sort();
            for (_, id) in unused {
                if needed <= self.free.len() {
                    break;
                }
                if let Some(p) = self.tiles.remove(&id) {
                    self.free.extend(p.pages);
                    evicted += 1;
                }
            }
        }
        let mut writes = Vec::new();
        let mut slots = Vec::with_capacity(selection.iter().map(|(_, n)| n).sum());
        for (k, (id, n)) in selection.iter().enumerate() {
            let placed = match self.tiles.get_mut(*id) {
                Some(p) => p,
                None => {
                    let pages: Vec<u32> = (0..pages_for(*n))
                        .map(|_| self.free.pop().unwrap_or_default())
                        .collect();
                    for (j, &page) in pages.iter().enumerate() {
                        let first = j * PAGE;
                        writes.push(PageWrite {
                            tile: k,
                            first,
                            page,
                        });
                    }
                    let p = Placed { pages, used: 0 };
                    self.tiles.entry((*id).to_owned()).or_insert(p)
                }
            };
            placed.used = self.tick;
            for i in 0..*n {
                slots.push(placed.pages[i / PAGE] * PAGE as u32 + (i % PAGE) as u32);
            }
        }
        Some(Placement {
            writes,
            slots,
            evicted,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_new_selection_writes_only_the_tiles_that_were_not_resident() {
        let mut t = PageTable::new(4);
        let a = t.place(&[("a", PAGE + 10), ("b", 5)]).unwrap();
        assert_eq!(a.writes.len(), 3);
        assert_eq!(a.slots.len(), PAGE + 15);
        let b = t.place(&[("b", 5), ("c", 7)]).unwrap();
        // b stays where it was; c takes the last free page; nothing evicted yet.
        assert_eq!(
            b.writes,
            vec![PageWrite {
                tile: 1,
                first: 0,
                page: 3
            }]
        );
        assert_eq!(b.slots[..5], a.slots[PAGE + 10..]);
        assert_eq!(b.evicted, 0);
        // d needs two pages: a (unused, least recent) is evicted, b and c stay.
        let c = t.place(&[("c", 7), ("b", 5), ("d", PAGE + 1)]).unwrap();
        assert_eq!(c.evicted, 1);
        assert_eq!(c.writes.iter().map(|w| w.tile).collect::<Vec<_>>(), [2, 2]);
        assert_eq!(c.slots[..7], b.slots[5..]);
        assert_eq!(t.used_pages(), 4);
        // Every slot of one selection is distinct.
        let mut s = c.slots.clone();
        s.sort();
        s.dedup();
        assert_eq!(s.len(), c.slots.len());
    }

    #[test]
    fn a_selection_larger_than_the_table_changes_nothing() {
        let mut t = PageTable::new(2);
        t.place(&[("a", 3)]).unwrap();
        assert!(t.place(&[("a", 3), ("b", 2 * PAGE)]).is_none());
        assert_eq!((t.used_pages(), t.resident_tiles()), (1, 1));
        assert!(t.place(&[("b", 2 * PAGE)]).is_some());
    }
}
