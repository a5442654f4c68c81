//! The physical page pool. A page is one quadrant of a tile (`ASM_PAGE_TEXELS`² texels, a
//! cell of the pool's atlas), and the pool holds as many pages as its byte budget allows, never
//! more. A resident tile keeps a page for each quadrant that no resident child covers: where a
//! child is resident every lookup descends into it, so the parent's texels there would never be
//! read. A leaf so takes four pages, and each tile refining a quadrant of its parent adds three
//! (it takes four, its parent gives one back): N resident tiles hold exactly 3N + 1 pages. The
//! root is allocated first and never evicted, so every lookup finds a tile.
//!
//! Evicting a leaf gives its parent the quadrant back, which a render of the leaf's square at
//! the parent's resolution fills again (exactly: a rebuild from the leaf's finer texels would
//! shift the coarse samples off their centres; the parent's texels there sample the same
//! points, and the render draws only what lies over the leaf's square). The renders this takes
//! are queued as [`PageOp`]s, in order: a page one frees may be written by a later one; the
//! technique records them before the lookups.
//!
//! Eviction follows the paper: among the evictable tiles (resident leaves other than the root:
//! evicting a tile with resident children would cut them off from the lookup's descent) the
//! least recently used one not used in the current frame goes first; if every evictable tile
//! was used this frame, the one of least benefit goes, and only for a tile of a benefit
//! `EVICTION_MARGIN` times as large.
use super::tile::TileKey;
use crate::error::{Error, Result};
use crate::layouts::constants::{ASM_PAGE_TEXELS, ASM_TILE_TEXELS};
use std::collections::HashMap;

/// Bytes of one page for the depth test with bias: a quadrant of D32 depth texels.
pub const DEPTH_PAGE_BYTES: u64 = 4 * ASM_PAGE_TEXELS as u64 * ASM_PAGE_TEXELS as u64;
/// Bytes of one page for the polygon-ID test: D32 depth and an R32_UINT polygon ID per texel.
pub const ID_PAGE_BYTES: u64 = 2 * DEPTH_PAGE_BYTES;
/// Pages of a tile: its quadrants.
pub const TILE_PAGES: u64 =
    (ASM_TILE_TEXELS / ASM_PAGE_TEXELS) as u64 * (ASM_TILE_TEXELS / ASM_PAGE_TEXELS) as u64;

/// A resident tile's pages, by quadrant ([`TileKey::quadrant`]): `None` where a resident child
/// covers the quadrant.
pub type TilePages = [Option<u32>; 4];

/// How much larger a tile's benefit must be than a resident tile's (used this frame) to evict
/// it: with the paper's "larger" alone, tiles of like benefit displaced each other frame after
/// frame in a full pool, a render each time (BENCHMARKS.md: 24 of 50 renders a frame were
/// evictions' on the walkthrough at 4 MiB).
const EVICTION_MARGIN: f32 = 2.0;

#[derive(Clone, Copy, Debug)]
struct Resident {
    pages: TilePages,
    last_used: u64,
    benefit: f32,
}

/// A render the pages need: the square of tile `key` at `side`² texels, its quadrants stored
/// where `pages` names a page.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PageOp {
    pub key: TileKey,
    /// A tile's own (`ASM_TILE_TEXELS`), or its parent's resolution (`ASM_PAGE_TEXELS`: one
    /// page, quadrant 0, the parent's quadrant over it that an eviction gives back).
    pub side: u32,
    pub pages: TilePages,
}

impl PageOp {
    /// The render of a tile's quadrants `pages`.
    pub fn tile(key: TileKey, pages: TilePages) -> PageOp {
        PageOp { key, side: ASM_TILE_TEXELS, pages }
    }
}

/// What [`PagePool::insert`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Insert {
    /// The tile was resident already (now marked used).
    Present,
    /// The tile got pages (and its render is queued), evicting the listed number of tiles for
    /// them (and queueing their parents' renders of the quadrants they give back).
    Inserted { evicted: usize },
    /// No pages could be freed for it: it stays missing and lookups use an ancestor.
    Refused,
}

#[derive(Debug)]
pub struct PagePool {
    capacity: u32,
    page_bytes: u64,
    free: Vec<u32>,
    tiles: HashMap<TileKey, Resident>,
    ops: Vec<PageOp>,
}

impl PagePool {
    /// A pool of `capacity` pages of `page_bytes`, with the root resident (used at frame 0, its
    /// render queued); it must hold at least the root's pages.
    pub fn new(capacity: u32, page_bytes: u64) -> Result<PagePool> {
        if u64::from(capacity) < TILE_PAGES {
            return Err(Error::InvalidArgument(format!(
                "an ASM pool of {capacity} pages holds no tile: a tile takes {TILE_PAGES}"
            )));
        }
        let mut pool = PagePool {
            capacity,
            page_bytes,
            free: (0..capacity).rev().collect(),
            tiles: HashMap::new(),
            ops: Vec::new(),
        };
        let pages = pool.take_tile_pages();
        pool.tiles.insert(TileKey::ROOT, Resident { pages, last_used: 0, benefit: f32::INFINITY });
        pool.ops.push(PageOp::tile(TileKey::ROOT, pages));
        Ok(pool)
    }

    /// Pages the budget holds.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// The most tiles the pool can hold: N tiles take 3N + 1 pages.
    pub fn max_tiles(&self) -> u32 {
        (self.capacity - 1) / 3
    }

    /// Bytes of all its pages: what the pool's images take, resident or not.
    pub fn bytes_allocated(&self) -> u64 {
        u64::from(self.capacity) * self.page_bytes
    }

    pub fn bytes_in_use(&self) -> u64 {
        u64::from(self.capacity - self.free.len() as u32) * self.page_bytes
    }

    /// Whether `key` is resident.
    pub fn contains(&self, key: TileKey) -> bool {
        self.tiles.contains_key(&key)
    }

    /// The pages of a resident tile.
    pub fn pages(&self, key: TileKey) -> Option<TilePages> {
        self.tiles.get(&key).map(|r| r.pages)
    }

    /// Resident tiles and their pages, in no particular order.
    pub fn resident(&self) -> impl Iterator<Item = (TileKey, TilePages)> + '_ {
        self.tiles.iter().map(|(k, r)| (*k, r.pages))
    }

    /// Marks a resident tile used in `frame` (a lookup landed in it); false if it is missing.
    pub fn touch(&mut self, key: TileKey, frame: u64) -> bool {
        self.tiles.get_mut(&key).map(|r| r.last_used = r.last_used.max(frame)).is_some()
    }

    /// Queues a render of resident tile `key`'s stored quadrants (its texels went stale); a
    /// tile whose children cover it all has nothing to render. False if it is missing.
    pub fn refresh(&mut self, key: TileKey) -> bool {
        let Some(r) = self.tiles.get(&key) else { return false };
        if r.pages.iter().any(Option::is_some) {
            self.ops.push(PageOp::tile(key, r.pages));
        }
        true
    }

    /// The GPU work queued since the last call, in order.
    pub fn take_ops(&mut self) -> Vec<PageOp> {
        std::mem::take(&mut self.ops)
    }

    /// Makes `key` resident in `frame` with `benefit` (the refinement's, per page), evicting
    /// tiles if the pool is short of pages (see the module's rules), and queues its render. Its
    /// parent must be resident: the tree grows from the root, so the lookup's descent reaches
    /// every resident tile.
    pub fn insert(&mut self, key: TileKey, frame: u64, benefit: f32) -> Result<Insert> {
        if let Some(r) = self.tiles.get_mut(&key) {
            r.last_used = r.last_used.max(frame);
            r.benefit = benefit;
            return Ok(Insert::Present);
        }
        let parent = key.parent().expect("the root is always resident");
        if !self.tiles.contains_key(&parent) {
            return Err(Error::InvalidArgument(format!(
                "ASM tile {key:?}: its parent {parent:?} is not resident"
            )));
        }
        // The tile takes a page per quadrant; its parent's page under it comes free.
        let mut evicted = 0;
        while self.free.len() + 1 < TILE_PAGES as usize {
            let Some(victim) = self.victim(key, frame, benefit) else { return Ok(Insert::Refused) };
            self.evict(victim);
            evicted += 1;
        }
        let given_back = self.tiles.get_mut(&parent).and_then(|p| p.pages[key.quadrant()].take());
        self.free.extend(given_back);
        let pages = self.take_tile_pages();
        self.tiles.insert(key, Resident { pages, last_used: frame, benefit });
        self.ops.push(PageOp::tile(key, pages));
        Ok(Insert::Inserted { evicted })
    }

    fn take_tile_pages(&mut self) -> TilePages {
        std::array::from_fn(|_| self.free.pop())
    }

    /// Evicts leaf `key`: one of its pages takes its parent's quadrant over it back (rendered
    /// again), the other three come free.
    fn evict(&mut self, key: TileKey) {
        let leaf = self.tiles.remove(&key).expect("the victim is resident");
        let [first, rest @ ..] = leaf.pages.map(|p| p.expect("a leaf stores all its quadrants"));
        let parent_key = key.parent().expect("the root is never evicted");
        let parent = self.tiles.get_mut(&parent_key).expect("a resident tile's parent is resident");
        parent.pages[key.quadrant()] = Some(first);
        self.ops.push(PageOp { key, side: ASM_PAGE_TEXELS, pages: [Some(first), None, None, None] });
        self.free.extend(rest);
    }

    /// The tile to evict for `key`, if any may go.
    fn victim(&self, key: TileKey, frame: u64, benefit: f32) -> Option<TileKey> {
        let evictable = self
            .tiles
            .iter()
            .filter(|(k, r)| **k != TileKey::ROOT && !k.covers(key) && r.pages.iter().all(Option::is_some));
        let (stale, current): (Vec<_>, Vec<_>) = evictable.partition(|(_, r)| r.last_used < frame);
        let lru = stale.into_iter().min_by(|a, b| {
            (a.1.last_used.cmp(&b.1.last_used)).then(a.1.benefit.total_cmp(&b.1.benefit)).then(a.0.cmp(b.0))
        });
        if let Some((k, _)) = lru {
            return Some(*k);
        }
        let least = current.into_iter().min_by(|a, b| a.1.benefit.total_cmp(&b.1.benefit).then(a.0.cmp(b.0)));
        least.filter(|(_, r)| EVICTION_MARGIN * r.benefit < benefit).map(|(k, _)| *k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    const PAGE_BYTES: u64 = DEPTH_PAGE_BYTES;

    fn child(key: TileKey, q: usize) -> TileKey {
        key.children().unwrap()[q]
    }

    fn budget(pages: u64) -> u64 {
        pages * PAGE_BYTES
    }

    #[test]
    fn a_pool_below_one_tile_is_an_error() {
        let err = PagePool::new(TILE_PAGES as u32 - 1, PAGE_BYTES).unwrap_err().to_string();
        assert!(err.contains("holds no tile"), "{err}");
        let mut pool = PagePool::new(TILE_PAGES as u32, PAGE_BYTES).unwrap();
        assert_eq!((pool.capacity(), pool.max_tiles(), pool.bytes_in_use()), (4, 1, budget(4)));
        let root = pool.pages(TileKey::ROOT).unwrap();
        assert_eq!(pool.take_ops(), vec![PageOp::tile(TileKey::ROOT, root)]);
        assert_eq!(pool.insert(child(TileKey::ROOT, 0), 1, 1.0).unwrap(), Insert::Refused);
    }

    /// A child takes four pages and its parent gives back the one under it; evicting the child
    /// gives that quadrant back to the parent, its render (the child's square at the parent's
    /// resolution) queued after the child's.
    #[test]
    fn a_child_takes_three_pages_and_eviction_gives_its_quadrant_back() {
        let mut pool = PagePool::new(7, PAGE_BYTES).unwrap();
        pool.take_ops();
        let a = child(TileKey::ROOT, 2);
        assert_eq!(pool.insert(a, 1, 1.0).unwrap(), Insert::Inserted { evicted: 0 });
        assert_eq!(pool.bytes_in_use(), budget(7));
        assert_eq!(pool.pages(TileKey::ROOT).unwrap()[2], None, "the root's quadrant under a is given back");
        let a_pages = pool.pages(a).unwrap().map(Option::unwrap);
        // Full: b takes a's place (a used in frame 1, stale in frame 2).
        let b = child(TileKey::ROOT, 1);
        assert_eq!(pool.insert(b, 2, 1.0).unwrap(), Insert::Inserted { evicted: 1 });
        let ops = pool.take_ops();
        assert_eq!(ops[0], PageOp::tile(a, a_pages.map(Some)));
        // a's square at the root's resolution: the root's quadrant over it.
        let restored = PageOp { key: a, side: ASM_PAGE_TEXELS, pages: [Some(a_pages[0]), None, None, None] };
        assert_eq!(ops[1], restored);
        assert_eq!(pool.pages(TileKey::ROOT).unwrap()[2], Some(a_pages[0]));
        assert_eq!(ops[2].key, b);
        assert_eq!(ops.len(), 3);
        assert!(!pool.contains(a) && pool.contains(b));
    }

    #[test]
    fn tiles_grow_from_the_root_and_evict_least_recently_used_leaves() {
        // Room for the root and two children (3N + 1 = 10 pages).
        let mut pool = PagePool::new(10, PAGE_BYTES).unwrap();
        let (a, b) = (child(TileKey::ROOT, 0), child(TileKey::ROOT, 3));
        assert!(pool.insert(child(a, 0), 1, 1.0).is_err(), "parent missing");
        assert_eq!(pool.insert(a, 1, 1.0).unwrap(), Insert::Inserted { evicted: 0 });
        assert_eq!(pool.insert(b, 2, 1.0).unwrap(), Insert::Inserted { evicted: 0 });
        // Full. Frame 3 wants a's child: b (used at 2) is the least recently used leaf; a is
        // the new tile's parent and stays.
        assert_eq!(pool.insert(child(a, 1), 3, 1.0).unwrap(), Insert::Inserted { evicted: 1 });
        assert!(!pool.contains(b));
        // Now a has a resident child, so only that child is evictable; used this frame, it
        // goes only for a benefit EVICTION_MARGIN times as large.
        assert_eq!(pool.insert(b, 3, 0.5).unwrap(), Insert::Refused);
        assert_eq!(pool.insert(b, 3, EVICTION_MARGIN).unwrap(), Insert::Refused);
        assert_eq!(pool.insert(b, 3, 1.01 * EVICTION_MARGIN).unwrap(), Insert::Inserted { evicted: 1 });
        assert!(pool.touch(a, 4) && !pool.touch(child(a, 1), 4));
        assert!(pool.contains(TileKey::ROOT), "the root is never evicted");
    }

    /// Random requests over many frames: the pool never holds more than its budget, N tiles
    /// hold 3N + 1 pages, the root stays, every resident tile's parent is resident (the lookup
    /// reaches it), a tile stores exactly the quadrants no resident child covers, and no two
    /// stored quadrants share a page.
    #[test]
    fn the_budget_is_never_exceeded() {
        let budget = budget(40);
        let mut pool = PagePool::new(40, PAGE_BYTES).unwrap();
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
                    Insert::Inserted { evicted } => replaced += evicted,
                    Insert::Refused => refused += 1,
                    Insert::Present => {}
                }
                let tiles = pool.resident().count() as u64;
                assert!(pool.bytes_in_use() <= budget && tiles <= u64::from(pool.max_tiles()));
                assert_eq!(pool.bytes_in_use(), (3 * tiles + 1) * PAGE_BYTES);
                assert!(pool.contains(TileKey::ROOT));
                let mut pages: Vec<u32> = Vec::new();
                for (k, stored) in pool.resident() {
                    assert!(k.parent().is_none_or(|p| pool.contains(p)), "{k:?} cut off");
                    for (q, page) in stored.iter().enumerate() {
                        let covered = k.children().is_some_and(|c| pool.contains(c[q]));
                        assert_eq!(page.is_none(), covered, "{k:?} quadrant {q}");
                        pages.extend(page);
                    }
                }
                let count = pages.len();
                pages.sort_unstable();
                pages.dedup();
                assert_eq!(pages.len(), count, "two quadrants share a page");
            }
        }
        assert!(replaced > 100 && refused > 0, "the test should exercise eviction: {replaced}, {refused}");
    }
}
