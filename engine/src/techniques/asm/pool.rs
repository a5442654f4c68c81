//! The physical page pool: every resident tile holds one page (one layer of the tile array
//! the GPU renders into), and the pool holds as many pages as its byte budget allows, never
//! more. The root is allocated first and never evicted, so every lookup finds a tile.
//!
//! Eviction follows the paper: among the evictable tiles (resident leaves other than the root:
//! evicting a tile with resident children would cut them off from the lookup's descent) the
//! least recently used one not used in the current frame goes first; if every evictable tile
//! was used this frame, the one of least benefit goes, and only for a tile of larger benefit.
use super::tile::TileKey;
use crate::error::{Error, Result};
use crate::layouts::constants::ASM_TILE_TEXELS;
use std::collections::HashMap;

/// Bytes of one page for the depth test with bias: a tile of D32 depth texels.
pub const DEPTH_PAGE_BYTES: u64 = 4 * ASM_TILE_TEXELS as u64 * ASM_TILE_TEXELS as u64;
/// Bytes of one page for the polygon-ID test: D32 depth and an R32_UINT polygon ID per texel.
pub const ID_PAGE_BYTES: u64 = 2 * DEPTH_PAGE_BYTES;

#[derive(Clone, Copy, Debug)]
struct Resident {
    page: u32,
    last_used: u64,
    benefit: f32,
}

/// What [`PagePool::insert`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Insert {
    /// The tile was resident already (now marked used).
    Present { page: u32 },
    /// The tile got a free page.
    Allocated { page: u32 },
    /// The tile got the page of `evicted`, which is no longer resident.
    Replaced { page: u32, evicted: TileKey },
    /// No page could be freed for it: it stays missing and lookups use an ancestor.
    Refused,
}

#[derive(Debug)]
pub struct PagePool {
    capacity: u32,
    page_bytes: u64,
    free: Vec<u32>,
    tiles: HashMap<TileKey, Resident>,
}

impl PagePool {
    /// A pool of pages of `page_bytes` within `budget_bytes`, with the root resident (used at
    /// frame 0); the budget must hold at least the root's page.
    pub fn new(budget_bytes: u64, page_bytes: u64) -> Result<PagePool> {
        let capacity = u32::try_from(budget_bytes / page_bytes.max(1)).unwrap_or(u32::MAX);
        if capacity == 0 {
            return Err(Error::InvalidArgument(format!(
                "an ASM budget of {budget_bytes} bytes holds no tile: a tile takes {page_bytes} bytes"
            )));
        }
        let mut pool =
            PagePool { capacity, page_bytes, free: (0..capacity).rev().collect(), tiles: HashMap::new() };
        pool.insert(TileKey::ROOT, 0, f32::INFINITY)?;
        Ok(pool)
    }

    /// Pages the budget holds.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Bytes of all its pages: what the pool's images take, resident or not.
    pub fn bytes_allocated(&self) -> u64 {
        u64::from(self.capacity) * self.page_bytes
    }

    pub fn bytes_in_use(&self) -> u64 {
        self.tiles.len() as u64 * self.page_bytes
    }

    /// The page of a resident tile.
    pub fn page(&self, key: TileKey) -> Option<u32> {
        self.tiles.get(&key).map(|r| r.page)
    }

    /// Resident tiles and their pages, in no particular order.
    pub fn resident(&self) -> impl Iterator<Item = (TileKey, u32)> + '_ {
        self.tiles.iter().map(|(k, r)| (*k, r.page))
    }

    /// Marks a resident tile used in `frame` (a lookup landed in it); false if it is missing.
    pub fn touch(&mut self, key: TileKey, frame: u64) -> bool {
        self.tiles.get_mut(&key).map(|r| r.last_used = r.last_used.max(frame)).is_some()
    }

    /// Makes `key` resident in `frame` with `benefit` (the refinement's benefit/cost), evicting
    /// a tile if the pool is full (see the module's rules). Its parent must be resident: the
    /// tree grows from the root, so the lookup's descent reaches every resident tile.
    pub fn insert(&mut self, key: TileKey, frame: u64, benefit: f32) -> Result<Insert> {
        if let Some(r) = self.tiles.get_mut(&key) {
            r.last_used = r.last_used.max(frame);
            r.benefit = benefit;
            return Ok(Insert::Present { page: r.page });
        }
        if let Some(parent) = key.parent().filter(|p| !self.tiles.contains_key(p)) {
            return Err(Error::InvalidArgument(format!(
                "ASM tile {key:?}: its parent {parent:?} is not resident"
            )));
        }
        let resident = |page| Resident { page, last_used: frame, benefit };
        if let Some(page) = self.free.pop() {
            self.tiles.insert(key, resident(page));
            return Ok(Insert::Allocated { page });
        }
        let Some(evicted) = self.victim(key, frame, benefit) else { return Ok(Insert::Refused) };
        let page = self.tiles.remove(&evicted).map_or(0, |r| r.page);
        self.tiles.insert(key, resident(page));
        Ok(Insert::Replaced { page, evicted })
    }

    /// The tile to evict for `key`, if any may go.
    fn victim(&self, key: TileKey, frame: u64, benefit: f32) -> Option<TileKey> {
        let evictable = self.tiles.iter().filter(|(k, _)| {
            **k != TileKey::ROOT
                && !k.covers(key)
                && k.children().is_none_or(|c| c.iter().all(|c| !self.tiles.contains_key(c)))
        });
        let (stale, current): (Vec<_>, Vec<_>) = evictable.partition(|(_, r)| r.last_used < frame);
        let lru = stale.into_iter().min_by(|a, b| {
            (a.1.last_used.cmp(&b.1.last_used)).then(a.1.benefit.total_cmp(&b.1.benefit)).then(a.0.cmp(b.0))
        });
        if let Some((k, _)) = lru {
            return Some(*k);
        }
        let least = current.into_iter().min_by(|a, b| a.1.benefit.total_cmp(&b.1.benefit).then(a.0.cmp(b.0)));
        least.filter(|(_, r)| r.benefit < benefit).map(|(k, _)| *k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    const PAGE_BYTES: u64 = DEPTH_PAGE_BYTES;

    fn child(key: TileKey, q: usize) -> TileKey {
        key.children().unwrap()[q]
    }

    #[test]
    fn a_budget_below_one_page_is_an_error() {
        assert!(PagePool::new(PAGE_BYTES - 1, PAGE_BYTES).unwrap_err().to_string().contains("holds no tile"));
        let pool = PagePool::new(PAGE_BYTES, PAGE_BYTES).unwrap();
        assert_eq!((pool.capacity(), pool.page(TileKey::ROOT)), (1, Some(0)));
    }

    #[test]
    fn tiles_grow_from_the_root_and_evict_least_recently_used_leaves() {
        let mut pool = PagePool::new(3 * PAGE_BYTES, PAGE_BYTES).unwrap();
        let (a, b) = (child(TileKey::ROOT, 0), child(TileKey::ROOT, 3));
        assert!(pool.insert(child(a, 0), 1, 1.0).is_err(), "parent missing");
        assert!(matches!(pool.insert(a, 1, 1.0).unwrap(), Insert::Allocated { .. }));
        assert!(matches!(pool.insert(b, 2, 1.0).unwrap(), Insert::Allocated { .. }));
        // Full. Frame 3 wants a's child: b (used at 2) is the least recently used leaf; a is
        // the new tile's parent and stays.
        assert!(
            matches!(pool.insert(child(a, 1), 3, 1.0).unwrap(), Insert::Replaced { evicted, .. } if evicted == b)
        );
        // Now a has a resident child, so only that child is evictable; used this frame, it
        // goes only for a larger benefit.
        assert_eq!(pool.insert(b, 3, 0.5).unwrap(), Insert::Refused);
        assert!(
            matches!(pool.insert(b, 3, 2.0).unwrap(), Insert::Replaced { evicted, .. } if evicted == child(a, 1))
        );
        assert!(pool.touch(a, 4) && !pool.touch(child(a, 1), 4));
        assert_eq!(pool.page(TileKey::ROOT), Some(0), "the root is never evicted");
    }

    /// Random requests over many frames: the pool never holds more than its budget, the root
    /// stays, and every resident tile's parent is resident (the lookup reaches it).
    #[test]
    fn the_budget_is_never_exceeded() {
        let budget = 10 * PAGE_BYTES + PAGE_BYTES / 2;
        let mut pool = PagePool::new(budget, PAGE_BYTES).unwrap();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let (mut replaced, mut refused) = (0, 0);
        for frame in 1..400u64 {
            for _ in 0..8 {
                // A random resident tile's random child: the refinement's shape.
                let resident: Vec<TileKey> = pool.resident().map(|(k, _)| k).collect();
                let parent = resident[(next() % resident.len() as u64) as usize];
                let Some(children) = parent.children() else { continue };
                let key = children[(next() % 4) as usize];
                match pool.insert(key, frame, (next() % 100) as f32).unwrap() {
                    Insert::Replaced { .. } => replaced += 1,
                    Insert::Refused => refused += 1,
                    _ => {}
                }
                assert!(pool.bytes_in_use() <= budget);
                assert!(pool.page(TileKey::ROOT).is_some());
                assert!(pool.resident().all(|(k, _)| k.parent().is_none_or(|p| pool.page(p).is_some())));
                let mut pages: Vec<u32> = pool.resident().map(|(_, p)| p).collect();
                pages.sort_unstable();
                pages.dedup();
                assert_eq!(pages.len(), pool.resident().count(), "two tiles share a page");
            }
        }
        assert!(replaced > 100 && refused > 0, "the test should exercise eviction: {replaced}, {refused}");
    }
}
