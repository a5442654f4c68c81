//! The physical page pool. A tile's `ASM_TILE_TEXELS`² texels are cut into `TILE_PAGES` slots of
//! `ASM_PAGE_TEXELS`² (a 4 × 4 grid), and a page holds one slot. The pool holds as many pages
//! as its byte budget allows, never more.
//!
//! A tile stores only its *wanted* slots, not its whole square: with texels a thirty-second of
//! the eye pixel, a finest tile spans a pixel or two and a shadow edge crosses a few of its
//! slots, and a slot no pixel looks up needs no texels. A point in a slot its finest resident
//! tile does not store reads the nearest ancestor's slot that holds it (the page table names
//! it), at worst the root's, which wants every slot, as do the tiles down to `WHOLE_LEVELS`
//! (so that no lookup falls back further than a level-3 tile's texels).
//!
//! A new tile is on *trial* for `TRIAL_FRAMES`: it stores every slot (its render is paid
//! anyway; the analysis sees a quarter of the pixels a frame, and each slot asked for later
//! would cost a render of its own) and notes the slots asked for (edge pixels needing them or
//! finer ones, or resolved by them) and those pixels read; at its end it wants the first, and
//! the second too while half the pages are free. A tile on trial covers nothing of its
//! parent's, so that its end needs no render of the parent. A pool short of pages ends the
//! longest trial begun in an earlier frame early, after the stale slots and before evicting.
//!
//! A wanted slot is not stored where it is *covered*: its child tile is resident and stores
//! (or covers) all four of the child's slots under it, so every lookup there finds finer
//! texels. Where the child holds only some of them, the parent keeps the slot for the others.
//! Tiles between the root and a requested tile that nobody asked for are resident without
//! pages (the lookup descends through them), and go when their last child does.
//!
//! Every render is a whole tile's, into a scratch from which the slots it stores are copied
//! ([`PageOp`]); they are queued in order (a page one frees may be written by a later one) and
//! the technique records them before the lookups. Evicting a leaf frees its pages; an ancestor
//! whose wanted slot it covered stores it again, from a render of that ancestor.
//!
//! Eviction follows the paper's least recently used order, per slot first: when pages run short,
//! the wanted slots no pixel asked for or read (its own texels, or a descendant's lookup falling
//! back to them) in `STALE_FRAMES` are given back, the longest unseen first, as many as the
//! insertion needs (a tile in view is looked up every frame, but in motion most of its slots
//! fall out of use; without this a full pool refused nearly every request while moving). A
//! tile renders at most once a frame ([`PagePool::merged`]). Then, among the evictable tiles (resident leaves
//! other than the root: evicting a tile with resident children would cut them off from the
//! lookup's descent) the least recently used one not used in the current frame goes first; if
//! every evictable tile was used this frame, the one of least benefit goes, and only for a tile
//! of a benefit `EVICTION_MARGIN` times as large.
use super::tile::TileKey;
use crate::error::{Error, Result};
use crate::layouts::constants::{
    ASM_PAGE_DEPTH_TEXELS, ASM_PAGE_ID_TEXELS, ASM_PAGE_TEXELS, ASM_TILE_TEXELS,
};
use rustc_hash::FxHashMap;
use std::collections::hash_map::Entry;

/// Frames the analysis takes to see every eye pixel (one of each 2×2 block a frame): a trial's
/// length.
pub const ANALYSIS_PHASES: u64 = 4;
const TRIAL_FRAMES: u64 = ANALYSIS_PHASES;

/// Bytes of one page for the depth test with bias: a slot's depths, 16 bits each, and their span
/// (`asm_pack.comp`).
pub const DEPTH_PAGE_BYTES: u64 = 16 * ASM_PAGE_DEPTH_TEXELS as u64;
/// Bytes of a slot's polygon IDs, 32 bits a texel (the ID test's second buffer of pages).
pub const PAGE_ID_BYTES: u64 = 16 * ASM_PAGE_ID_TEXELS as u64;
/// Bytes of one page for the polygon-ID test: the depth page and the slot's polygon IDs.
pub const ID_PAGE_BYTES: u64 = DEPTH_PAGE_BYTES + PAGE_ID_BYTES;
/// Slots per side of a tile.
pub const SLOT_SIDE: u32 = ASM_TILE_TEXELS / ASM_PAGE_TEXELS;
/// Slots of a tile: the root's pages.
pub const TILE_PAGES: u64 = SLOT_SIDE as u64 * SLOT_SIDE as u64;
/// [`TILE_PAGES`] as an array length.
pub const SLOTS: usize = TILE_PAGES as usize;

/// Tiles down to this level keep every slot, never trimmed at a trial's end nor given back
/// stale. With slots alone a pixel where no edge asked for texels before reads a far ancestor's
/// slot (the root's 64² over the whole view), which misses thin occluders: after a camera jump
/// of 1,000 px at 512², 1 % of the pixels leaked for a frame (BENCHMARKS.md, "At 512²"). At most
/// 85 tiles (1.3 MiB of depth pages), and the tiles every view asks for nearly whole.
const WHOLE_LEVELS: u32 = 3;

/// Frames after which a slot nobody asked for or read is given back when pages run short:
/// twice the analysis's phases, in each of which it sees a quarter of the pixels.
const STALE_FRAMES: u64 = 2 * ANALYSIS_PHASES;

fn see(seen: &mut [u64; SLOTS], slots: Slots, frame: u64) {
    for (s, at) in seen.iter_mut().enumerate() {
        if slots & 1 << s != 0 {
            *at = (*at).max(frame);
        }
    }
}

/// A set of a tile's slots: bit `SLOT_SIDE · y + x` for slot (x, y).
pub type Slots = u16;
/// Every slot of a tile.
pub const ALL_SLOTS: Slots = u16::MAX;
const _: () = assert!(SLOTS == Slots::BITS as usize);

/// A resident tile's pages, by slot: `None` where the slot is not stored.
pub type TilePages = [Option<u32>; SLOTS];

/// How much larger a tile's benefit must be than a resident tile's (used this frame) to evict
/// it: with the paper's "larger" alone, tiles of like benefit displaced each other frame after
/// frame in a full pool, a render each time (BENCHMARKS.md: 24 of 50 renders a frame were
/// evictions' on the walkthrough at 4 MiB).
const EVICTION_MARGIN: f32 = 2.0;

/// What the analysis saw of a tile on trial.
#[derive(Clone, Copy, Debug)]
struct Trial {
    /// Slots asked for: edge pixels needing them or finer ones, or resolved by them.
    asked: Slots,
    /// Slots pixels read.
    used: Slots,
    /// The frame from which it keeps the slots asked for (and, where pages are plentiful,
    /// those used).
    ends: u64,
}

#[derive(Clone, Copy, Debug)]
struct Resident {
    pages: TilePages,
    /// The slots asked for.
    wanted: Slots,
    /// The slots stored or covered (see the module): what this tile gives its parent's cover.
    full: Slots,
    /// Resident children.
    children: u8,
    /// While a new tile stores every slot (see [`PagePool::insert_within`]).
    trial: Option<Trial>,
    last_used: u64,
    benefit: f32,
    /// The last frame each slot was asked for or read (its own texels, or by a descendant's
    /// lookup falling back to it).
    seen: [u64; SLOTS],
}

impl Resident {
    fn stored(&self) -> Slots {
        self.pages.iter().enumerate().filter(|(_, p)| p.is_some()).fold(0, |m, (s, _)| m | 1 << s)
    }
}

/// A render the pages need: tile `key`'s square, the listed (slot, page) pairs stored.
#[derive(Clone, Debug, PartialEq)]
pub struct PageOp {
    pub key: TileKey,
    pub stores: Vec<(u32, u32)>,
}

/// What [`PagePool::insert_within`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Insert {
    /// The tile was resident with those slots already (now marked used).
    Present,
    /// The tile got the slots (and its render is queued), evicting the listed number of tiles
    /// for them (and queueing the renders of the ancestors' slots they gave back).
    Inserted { evicted: usize },
    /// No pages could be freed for it: it stays as it was and lookups use an ancestor.
    Refused,
}

/// The slot of a tile of `level` holding the slot (`slot`) of a tile `down` levels below it at
/// absolute texel position `texel` (the slot's first texel at its own level).
fn slot_at(texel: [u64; 2], down: u32) -> u32 {
    let within = |t: u64| ((t >> down) % u64::from(ASM_TILE_TEXELS)) as u32 / ASM_PAGE_TEXELS;
    within(texel[0]) + SLOT_SIDE * within(texel[1])
}

/// The first texel of slot `slot` of `key`, in texels of its level from the view's corner.
fn slot_texel(key: TileKey, slot: u32) -> [u64; 2] {
    let at =
        |tile: u32, s: u32| u64::from(tile) * u64::from(ASM_TILE_TEXELS) + u64::from(s * ASM_PAGE_TEXELS);
    [at(key.x, slot % SLOT_SIDE), at(key.y, slot / SLOT_SIDE)]
}

/// The slot of `key`'s parent over slot `slot` of `key`.
pub fn parent_slot(key: TileKey, slot: u32) -> u32 {
    slot_at(slot_texel(key, slot), 1)
}

/// The slots of `key`'s parent over `slots` of `key`.
pub fn parent_slots(key: TileKey, slots: Slots) -> Slots {
    (0..SLOTS as u32).filter(|s| slots & 1 << s != 0).fold(0, |m, s| m | 1 << parent_slot(key, s))
}

/// The slots of a tile covered where its children give `full` (per quadrant, as
/// [`TileKey::children`]): a slot is covered when the four slots of its child under it are.
fn covered_by(full: [Slots; 4]) -> Slots {
    let mut covered = 0;
    for slot in 0..SLOTS as u32 {
        let (x, y) = (slot % SLOT_SIDE, slot / SLOT_SIDE);
        let half = SLOT_SIDE / 2;
        let child = full[((x / half) + 2 * (y / half)) as usize];
        let (cx, cy) = (2 * (x % half), 2 * (y % half));
        let under = [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(i, j)| 1u16 << ((cx + i) + SLOT_SIDE * (cy + j)));
        if under.iter().all(|b| child & b != 0) {
            covered |= 1 << slot;
        }
    }
    covered
}

#[derive(Debug)]
pub struct PagePool {
    capacity: u32,
    page_bytes: u64,
    free: Vec<u32>,
    tiles: FxHashMap<TileKey, Resident>,
    ops: Vec<PageOp>,
    /// The frame `stale_order` was made in.
    released: u64,
    /// The tiles with stale slots when the frame first ran short of pages, the next to give
    /// them back last ([`PagePool::release_stalest`]).
    stale_order: Vec<TileKey>,
    /// Tiles down to this level keep every slot (see [`WHOLE_LEVELS`]).
    whole: u32,
}

/// A tile's state along a change's chain: its new wanted and full slots.
struct Step {
    key: TileKey,
    wanted: Slots,
    full: Slots,
    stored: Slots,
}

impl PagePool {
    /// A pool of `capacity` pages of `page_bytes`, with the root resident and every slot of it
    /// wanted (used at frame 0, its render queued); it must hold at least the root's pages.
    pub fn new(capacity: u32, page_bytes: u64) -> Result<PagePool> {
        PagePool::keeping_whole(capacity, page_bytes, WHOLE_LEVELS)
    }

    /// [`PagePool::new`] with the tiles down to level `whole` keeping every slot.
    fn keeping_whole(capacity: u32, page_bytes: u64, whole: u32) -> Result<PagePool> {
        if u64::from(capacity) < TILE_PAGES {
            return Err(Error::InvalidArgument(format!(
                "an ASM pool of {capacity} pages holds no tile: the root takes {TILE_PAGES}"
            )));
        }
        let mut pool = PagePool {
            capacity,
            page_bytes,
            free: (0..capacity).rev().collect(),
            tiles: FxHashMap::default(),
            ops: Vec::new(),
            released: 0,
            stale_order: Vec::new(),
            whole,
        };
        pool.commit(pool.chain(TileKey::ROOT, ALL_SLOTS, false, None), 0, f32::INFINITY);
        Ok(pool)
    }

    /// Pages the budget holds.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// The most tiles the pool holds (the page table's nodes): a quarter of its pages, since a
    /// tile that holds texels stores a few slots and the tiles between them none (the `asm`
    /// scene's views after 30 frames at 4 MiB: 6 pages a tile; 16 MiB after 90: 4.3).
    pub fn max_tiles(&self) -> u32 {
        max_tiles(self.capacity)
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

    /// The (slot, page) pairs a resident tile stores.
    pub fn stores(&self, key: TileKey) -> Vec<(u32, u32)> {
        let pages = self.pages(key).unwrap_or([None; SLOTS]);
        pages.iter().enumerate().filter_map(|(s, p)| p.map(|p| (s as u32, p))).collect()
    }

    /// Resident tiles and their pages, in no particular order.
    pub fn resident(&self) -> impl Iterator<Item = (TileKey, TilePages)> + '_ {
        self.tiles.iter().map(|(k, r)| (*k, r.pages))
    }

    /// [`PagePool::holding`]'s page and levels up, as `page_table::build` must find them: the
    /// tests' oracle for the holders the build hands down.
    #[cfg(test)]
    pub fn holder(&self, key: TileKey, slot: u32) -> Result<(u32, u32)> {
        let (_, _, page, up) = self.holding(key, slot).ok_or_else(|| {
            Error::Internal(format!("no resident tile at or above ASM tile {key:?} stores its slot {slot}"))
        })?;
        Ok((page, up))
    }

    /// The nearest tile at or above resident `key` that stores the point of `key`'s slot
    /// `slot`: the tile, its slot over the point, its page and the levels up to it (the root
    /// wants every slot, and a slot stored nowhere below is covered nowhere above, so one is
    /// always found); `None` where the tiles break the rules.
    fn holding(&self, key: TileKey, slot: u32) -> Option<(TileKey, usize, u32, u32)> {
        let texel = slot_texel(key, slot);
        let mut at = Some(key);
        for up in 0..=key.level {
            let tile = at?;
            let s = slot_at(texel, up) as usize;
            if let Some(page) = self.tiles.get(&tile)?.pages[s] {
                return Some((tile, s, page, up));
            }
            at = tile.parent();
        }
        None
    }

    /// Marks a resident tile used in `frame` (a lookup landed in it); false if it is missing.
    pub fn touch(&mut self, key: TileKey, frame: u64) -> bool {
        self.tiles.get_mut(&key).map(|r| r.last_used = r.last_used.max(frame)).is_some()
    }

    /// Queues a render of resident tile `key`'s stored slots (its texels went stale); a tile
    /// that stores none has nothing to render. False if it is missing.
    pub fn refresh(&mut self, key: TileKey) -> bool {
        if !self.contains(key) {
            return false;
        }
        let stores = self.stores(key);
        if !stores.is_empty() {
            self.ops.push(PageOp { key, stores });
        }
        true
    }

    /// The GPU work queued since the last call, in order.
    pub fn take_ops(&mut self) -> Vec<PageOp> {
        std::mem::take(&mut self.ops)
    }

    /// `ops` (queued in one frame, in order) with each tile rendered once: at its last render's
    /// place, into the pages it holds now of the slots any of them stored. A page a tile gave
    /// up between its renders went to a later render of another tile or stays free; one it
    /// holds now was written by nothing after its last render. Evictions of several children
    /// of one ancestor each queued a render of that ancestor (12 of one level-3 tile in a
    /// frame of 28 renders after a camera turn).
    pub fn merged(&self, ops: Vec<PageOp>) -> Vec<PageOp> {
        let mut slots: FxHashMap<TileKey, Slots> = FxHashMap::default();
        for op in &ops {
            *slots.entry(op.key).or_default() |= op.stores.iter().fold(0, |m, (s, _)| m | 1 << s);
        }
        let mut merged: Vec<PageOp> = ops
            .into_iter()
            .rev()
            .filter_map(|op| {
                let slots = slots.remove(&op.key)?;
                let stores: Vec<(u32, u32)> =
                    self.stores(op.key).into_iter().filter(|(s, _)| slots & 1 << s != 0).collect();
                (!stores.is_empty()).then_some(PageOp { key: op.key, stores })
            })
            .collect();
        merged.reverse();
        merged
    }

    /// Notes that `slots` of `key` are asked for in `frame`; true if that needs no render: the
    /// tile stores them, or stores every slot while on trial (see [`PagePool::insert_within`]).
    /// With a `benefit`, that is the tile's now.
    pub fn note(&mut self, key: TileKey, slots: Slots, frame: u64, benefit: Option<f32>) -> bool {
        let Some(r) = self.tiles.get_mut(&key) else { return false };
        // Nothing asked for is no use: the tile's last use stays (its eviction order with it;
        // the technique notes every tile each frame, most with no slot).
        if slots == 0 {
            return true;
        }
        see(&mut r.seen, slots, frame);
        match &mut r.trial {
            Some(trial) => trial.asked |= slots,
            None if r.wanted & slots == slots => {}
            None => return false,
        }
        r.last_used = r.last_used.max(frame);
        r.benefit = benefit.unwrap_or(r.benefit);
        true
    }

    /// Notes that pixels read `slots` of `key`'s own texels (kept past a trial where pages are
    /// plentiful).
    pub fn note_used(&mut self, key: TileKey, slots: Slots, frame: u64) {
        let Some(r) = self.tiles.get_mut(&key) else { return };
        see(&mut r.seen, slots, frame);
        if let Some(trial) = r.trial.as_mut() {
            trial.used |= slots;
        }
    }

    /// Notes that pixels in `slots` of `key` read an ancestor's texels: the holders' slots.
    pub fn note_read_above(&mut self, key: TileKey, slots: Slots, frame: u64) {
        for slot in (0..SLOTS as u32).filter(|s| slots & 1 << s != 0) {
            if let Some((tile, s, _, _)) = self.holding(key, slot) {
                let seen = &mut self.tiles.get_mut(&tile).expect("found resident").seen[s];
                *seen = (*seen).max(frame);
            }
        }
    }

    /// The tile's wanted slots no pixel asked for or read in `STALE_FRAMES` before `frame`,
    /// with the last frame any of them was seen; `None` where it has none (or may not give them).
    fn stale(&self, key: TileKey, frame: u64) -> Option<(Slots, u64)> {
        let before = frame.checked_sub(STALE_FRAMES)?;
        let r = self.tiles.get(&key).filter(|r| key.level > self.whole && r.trial.is_none())?;
        let slots = (0..SLOTS).filter(|&s| r.seen[s] < before).fold(0, |m, s| m | 1 << s) & r.wanted;
        let last = (0..SLOTS).filter(|&s| slots & 1 << s != 0).map(|s| r.seen[s]).max()?;
        Some((slots, last))
    }

    /// Gives back the stale slots of one more tile (see [`PagePool::stale`]): the tiles whose
    /// stale slots were seen longest ago first (the paper's least recently used order, per
    /// slot), deeper ones first among those (a leaf's release may leave its parent a leaf); a
    /// leaf left wanting nothing is evicted. Only as many as an insertion needs go, one tile at
    /// a time: releasing every stale slot at once queued the renders of all their ancestors in
    /// one frame (28 against the 7 a frame's time allowed after a camera turn). False when no
    /// stale tile is left this frame.
    fn release_stalest(&mut self, frame: u64, afford: &mut dyn FnMut(&[TileKey]) -> bool) -> bool {
        if self.released < frame {
            self.released = frame;
            let mut keys: Vec<(u64, TileKey)> =
                self.tiles.keys().filter_map(|&k| self.stale(k, frame).map(|(_, last)| (last, k))).collect();
            keys.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.level.cmp(&b.1.level)).then(b.1.cmp(&a.1)));
            self.stale_order = keys.into_iter().map(|(_, k)| k).collect();
        }
        // A tile whose release renders more than `afford` allows keeps its slots this frame.
        while let Some(key) = self.stale_order.pop() {
            // Noted since the list was made, or gone with a child's eviction.
            let Some((stale, _)) = self.stale(key, frame) else { continue };
            let r = self.tiles[&key];
            let wanted = r.wanted & !stale;
            if wanted == 0 && r.children == 0 {
                let (gone, chain) = self.eviction(key);
                if afford(&self.renders(&chain)) {
                    self.evict(gone, chain, frame);
                    return true;
                }
                continue;
            }
            let chain = self.chain(key, wanted, false, None);
            if self.pages_needed(&chain) < 0 && afford(&self.renders(&chain)) {
                self.commit(chain, frame, r.benefit);
                return true;
            }
        }
        false
    }

    /// [`PagePool::insert_within`] with every render afforded.
    #[cfg(test)]
    pub fn insert(&mut self, key: TileKey, slots: Slots, frame: u64, benefit: f32) -> Result<Insert> {
        self.insert_within(key, slots, frame, benefit, &mut |_| true)
    }

    /// Makes `slots` of `key` wanted in `frame` with `benefit` (the refinement's), the tiles
    /// between it and its nearest resident ancestor resident without pages, evicting tiles if
    /// the pool is short of pages or nodes (see the module's rules), and queues the renders. A
    /// tile that stored nothing starts its trial ([`PagePool::end_trials`]). Each stale
    /// release and eviction is done only where `afford` accepts the tiles it would render (it
    /// is told them before): the time a frame's renders take is bounded, the renders
    /// evictions cause included. Where none is accepted and pages are short, the tile is
    /// refused; what was freed stays free.
    pub fn insert_within(
        &mut self,
        key: TileKey,
        slots: Slots,
        frame: u64,
        benefit: f32,
        afford: &mut dyn FnMut(&[TileKey]) -> bool,
    ) -> Result<Insert> {
        if key.level > crate::layouts::constants::ASM_MAX_LEVEL {
            return Err(Error::Internal(format!("ASM tile {key:?} is below the deepest level")));
        }
        if self.note(key, slots, frame, Some(benefit)) {
            return Ok(Insert::Present);
        }
        let fresh = self.tiles.get(&key).is_none_or(|r| r.wanted == 0);
        let mut evicted = 0;
        loop {
            let wanted = match fresh {
                true => ALL_SLOTS,
                false => self.tiles.get(&key).map_or(0, |r| r.wanted) | slots,
            };
            let chain = self.chain(key, wanted, fresh, None);
            let new_tiles = chain.iter().filter(|s| !self.tiles.contains_key(&s.key)).count();
            let pages = self.pages_needed(&chain);
            let fits_pages = pages <= self.free.len() as i64;
            let fits_nodes = self.tiles.len() + new_tiles <= self.max_tiles() as usize;
            if fits_pages && fits_nodes {
                self.commit(chain, frame, benefit);
                if fresh {
                    let trial = Trial { asked: slots, used: 0, ends: frame + TRIAL_FRAMES };
                    self.tiles.get_mut(&key).expect("committed").trial = Some(trial);
                }
                return Ok(Insert::Inserted { evicted });
            }
            if self.release_stalest(frame, afford) || self.end_a_trial_early(frame) {
                continue;
            }
            let Some(victim) = self.victim(key, frame, benefit) else {
                return Ok(Insert::Refused);
            };
            let (gone, chain) = self.eviction(victim);
            if !afford(&self.renders(&chain)) {
                return Ok(Insert::Refused);
            }
            self.evict(gone, chain, frame);
            evicted += 1;
        }
    }

    /// Ends the trials due by `frame`: each such tile keeps the slots asked for during it, the
    /// others' pages come free (its ancestors store what it no longer covers, renders queued).
    pub fn end_trials(&mut self, frame: u64) {
        let due: Vec<(TileKey, Trial)> = self
            .tiles
            .iter()
            .filter_map(|(k, r)| r.trial.filter(|t| t.ends <= frame).map(|t| (*k, t)))
            .collect();
        for (key, _) in due {
            self.end_trial(key, frame);
        }
    }

    /// Ends `key`'s trial: it keeps the slots asked for during it, and, while half the pages
    /// are free, those pixels read (each would cost a render when the tile's coarser
    /// neighbours no longer suffice); the others' pages come free. False where its ancestors'
    /// uncovered slots would take more than it gives back (then later).
    fn end_trial(&mut self, key: TileKey, frame: u64) -> bool {
        let Some(trial) = self.tiles.get(&key).and_then(|r| r.trial) else { return false };
        let plenty = 2 * self.free.len() >= self.capacity as usize;
        let keep = match key.level <= self.whole {
            true => ALL_SLOTS,
            false => trial.asked | if plenty { trial.used } else { 0 },
        };
        let chain = self.chain(key, keep, false, None);
        if self.pages_needed(&chain) > self.free.len() as i64 {
            return false;
        }
        self.tiles.get_mut(&key).expect("on trial").trial = None;
        self.commit(chain, frame, 0.0);
        true
    }

    /// Ends early the trial of the tile on trial longest, begun before `frame`, where that
    /// gives pages back: a full pool held a quarter of its pages in tiles on trial while
    /// refining (4,000 of 15,000 at 16 MiB on the asm scene's grating).
    fn end_a_trial_early(&mut self, frame: u64) -> bool {
        let oldest = self
            .tiles
            .iter()
            .filter_map(|(k, r)| r.trial.map(|t| (t.ends, *k)))
            .filter(|(ends, k)| *ends < frame + TRIAL_FRAMES && k.level > self.whole)
            .min();
        oldest.is_some_and(|(_, key)| self.end_trial(key, frame))
    }

    /// The states of `key` (wanted `wanted`) and of each ancestor up to the root after the
    /// change: a tile's cover depends on its children's.
    /// A tile on trial covers nothing of its parent's: the parent keeps those pages, so that
    /// the trial's end, where the tile keeps fewer slots, needs no render of the parent.
    /// `gone`, where given, is a tile about to be evicted: as if not resident.
    fn chain(&self, key: TileKey, wanted: Slots, on_trial: bool, gone: Option<TileKey>) -> Vec<Step> {
        let mut steps: Vec<Step> = Vec::new();
        let mut at = Some(key);
        while let Some(k) = at {
            let wanted = match steps.last() {
                None => wanted,
                Some(_) => self.tiles.get(&k).map_or(0, |r| r.wanted),
            };
            let full = k.children().map_or([0; 4], |children| {
                children.map(|c| {
                    let trial = match c == key {
                        true => on_trial,
                        false => self.tiles.get(&c).is_some_and(|r| r.trial.is_some()),
                    };
                    match steps.last().filter(|s| s.key == c) {
                        _ if trial || gone == Some(c) => 0,
                        Some(s) => s.full,
                        None => self.tiles.get(&c).map_or(0, |r| r.full),
                    }
                })
            });
            let covered = covered_by(full);
            steps.push(Step { key: k, wanted, full: wanted | covered, stored: wanted & !covered });
            at = k.parent();
        }
        steps
    }

    /// The pages a chain of states takes beyond those its tiles store now (negative where it
    /// gives pages back).
    fn pages_needed(&self, chain: &[Step]) -> i64 {
        let now = |key: &TileKey| self.tiles.get(key).map_or(0, |r| r.stored().count_ones());
        chain.iter().map(|s| i64::from(s.stored.count_ones()) - i64::from(now(&s.key))).sum()
    }

    /// Applies a chain of states: pages given back first, then taken, renders queued.
    fn commit(&mut self, chain: Vec<Step>, frame: u64, benefit: f32) {
        for step in &chain {
            if let Some(r) = self.tiles.get_mut(&step.key) {
                for (s, page) in r.pages.iter_mut().enumerate() {
                    if step.stored & 1 << s == 0 {
                        self.free.extend(page.take());
                    }
                }
            }
        }
        // New tiles parents first, so that each counts in its parent's children.
        for step in chain.iter().rev() {
            if let Entry::Vacant(vacant) = self.tiles.entry(step.key) {
                let resident = Resident {
                    pages: [None; SLOTS],
                    wanted: 0,
                    full: 0,
                    children: 0,
                    trial: None,
                    last_used: frame,
                    benefit,
                    seen: [frame; SLOTS],
                };
                vacant.insert(resident);
                if let Some(parent) = step.key.parent() {
                    self.tiles.get_mut(&parent).expect("inserted before its child").children += 1;
                }
            }
        }
        for step in chain {
            let r = self.tiles.get_mut(&step.key).expect("inserted above");
            r.wanted = step.wanted;
            r.full = step.full;
            let mut stores = Vec::new();
            for s in 0..SLOTS {
                if step.stored & 1 << s != 0 && r.pages[s].is_none() {
                    let page = self.free.pop().expect("the change was checked to fit");
                    r.pages[s] = Some(page);
                    stores.push((s as u32, page));
                }
            }
            if !stores.is_empty() {
                self.ops.push(PageOp { key: step.key, stores });
            }
        }
    }

    /// What evicting leaf `key` does: the tiles that go (it, then the ancestors it leaves with
    /// no child and nothing wanted), and the new states of the nearest one that stays and its
    /// ancestors (those that wanted what the tiles going covered store it again).
    fn eviction(&self, key: TileKey) -> (Vec<TileKey>, Vec<Step>) {
        let mut gone = vec![key];
        let mut parent = key.parent().expect("the root is never evicted");
        while parent != TileKey::ROOT {
            let r = &self.tiles[&parent];
            if r.children > 1 || r.wanted != 0 {
                break;
            }
            gone.push(parent);
            parent = parent.parent().expect("not the root");
        }
        let r = &self.tiles[&parent];
        let chain = self.chain(parent, r.wanted, r.trial.is_some(), gone.last().copied());
        (gone, chain)
    }

    /// Applies an [`PagePool::eviction`]: the tiles `gone` leave, their pages come free, and
    /// `chain`'s renders are queued.
    fn evict(&mut self, gone: Vec<TileKey>, chain: Vec<Step>, frame: u64) {
        for key in &gone {
            let r = self.tiles.remove(key).expect("the tiles going are resident");
            self.free.extend(r.pages.iter().flatten());
        }
        let top = gone.last().expect("the victim goes").parent().expect("the root is never evicted");
        self.tiles.get_mut(&top).expect("a resident tile's parent is resident").children -= 1;
        // The chain holds no new tile: `frame` and the benefit go nowhere.
        self.commit(chain, frame, 0.0);
    }

    /// The tiles a chain of states renders: those that store slots they do not now.
    fn renders(&self, chain: &[Step]) -> Vec<TileKey> {
        let now = |key: &TileKey| self.tiles.get(key).map_or(0, |r| r.stored());
        chain.iter().filter(|s| s.stored & !now(&s.key) != 0).map(|s| s.key).collect()
    }

    /// The tile to evict for `key`, if any may go.
    fn victim(&self, key: TileKey, frame: u64, benefit: f32) -> Option<TileKey> {
        let evictable =
            self.tiles.iter().filter(|(k, r)| **k != TileKey::ROOT && !k.covers(key) && r.children == 0);
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

/// The most tiles a pool of `pages` pages holds ([`PagePool::max_tiles`]).
pub fn max_tiles(pages: u32) -> u32 {
    pages / 4
}

#[cfg(test)]
mod tests {
    use super::*;
    const PAGE_BYTES: u64 = DEPTH_PAGE_BYTES;
    const ROOT_PAGES: u32 = TILE_PAGES as u32;

    fn child(key: TileKey, q: usize) -> TileKey {
        key.children().unwrap()[q]
    }

    fn bit(x: u32, y: u32) -> Slots {
        1 << (x + SLOT_SIDE * y)
    }

    fn in_use(pool: &PagePool) -> u64 {
        pool.bytes_in_use() / PAGE_BYTES
    }

    #[test]
    fn a_pool_below_the_roots_slots_is_an_error() {
        let err = PagePool::new(ROOT_PAGES - 1, PAGE_BYTES).unwrap_err().to_string();
        assert!(err.contains("holds no tile"), "{err}");
        let mut pool = PagePool::new(ROOT_PAGES, PAGE_BYTES).unwrap();
        assert_eq!((pool.capacity(), in_use(&pool)), (ROOT_PAGES, TILE_PAGES));
        let ops = pool.take_ops();
        assert_eq!((ops.len(), ops[0].key, ops[0].stores.len()), (1, TileKey::ROOT, SLOTS));
        assert_eq!(pool.insert(child(TileKey::ROOT, 0), bit(0, 0), 1, 1.0).unwrap(), Insert::Refused);
    }

    /// A new tile stores every slot until its trial ends, then the slots asked for (and, with
    /// half the pages free, those read); a slot it does not store is read from its parent's.
    #[test]
    fn a_trial_keeps_the_slots_asked_for() {
        let mut pool = PagePool::keeping_whole(64, PAGE_BYTES, 0).unwrap();
        pool.take_ops();
        let a = child(TileKey::ROOT, 0);
        assert_eq!(pool.insert(a, bit(1, 1), 1, 1.0).unwrap(), Insert::Inserted { evicted: 0 });
        // On trial it covers nothing of the root's.
        assert_eq!(in_use(&pool), 2 * TILE_PAGES);
        assert_eq!(pool.take_ops()[0].stores.len(), SLOTS);
        assert!(pool.note(a, bit(2, 1), 2, None), "asked for on trial: no render");
        pool.note_used(a, bit(3, 3), 2);
        pool.end_trials(TRIAL_FRAMES);
        assert_eq!(pool.stores(a).len(), SLOTS, "not over before its last frame");
        // 32 of 64 pages in use: half are free, so the slot read stays too.
        pool.end_trials(1 + TRIAL_FRAMES);
        let kept: Vec<u32> = pool.stores(a).iter().map(|s| s.0).collect();
        assert_eq!(kept, vec![5, 6, 15]);
        assert!(pool.take_ops().is_empty(), "a trial's end renders nothing");
        assert_eq!(in_use(&pool), TILE_PAGES + 3);
        // Slot (0, 0) of `a` is the root's slot (0, 0), one level up.
        assert_eq!(pool.holder(a, 0).unwrap(), (pool.pages(TileKey::ROOT).unwrap()[0].unwrap(), 1));
        // Asked for later, a slot costs a render of the tile.
        assert!(!pool.note(a, bit(0, 0), 9, None));
        assert_eq!(pool.insert(a, bit(0, 0), 9, 1.0).unwrap(), Insert::Inserted { evicted: 0 });
        assert_eq!(
            pool.take_ops(),
            vec![PageOp { key: a, stores: vec![(0, pool.pages(a).unwrap()[0].unwrap())] }]
        );
    }

    /// A parent's slot whose four slots below its child stores gives its page back, and stores
    /// it again (a render of the parent) when the child is evicted.
    #[test]
    fn a_covered_slot_is_given_back_and_stored_again_after_eviction() {
        let mut pool = PagePool::keeping_whole(48, PAGE_BYTES, 0).unwrap();
        let a = child(TileKey::ROOT, 0);
        let under = bit(0, 0) | bit(1, 0) | bit(0, 1) | bit(1, 1);
        pool.insert(a, under, 1, 1.0).unwrap();
        // 32 of 48 in use: fewer than half free, so the slots asked for alone stay.
        pool.end_trials(1 + TRIAL_FRAMES);
        assert_eq!(pool.pages(TileKey::ROOT).unwrap()[0], None, "covered by a");
        assert_eq!(in_use(&pool), TILE_PAGES - 1 + 4);
        pool.take_ops();
        // Another tile needs 16 pages; 29 are free. A third one in the same frame (the second's
        // trial runs on) evicts the least recently used.
        let b = child(TileKey::ROOT, 3);
        assert_eq!(pool.insert(b, bit(3, 3), 8, 1.0).unwrap(), Insert::Inserted { evicted: 0 });
        let c = child(TileKey::ROOT, 1);
        assert_eq!(pool.insert(c, bit(3, 0), 8, 1.0).unwrap(), Insert::Inserted { evicted: 1 });
        assert!(!pool.contains(a) && pool.contains(b) && pool.contains(c));
        let ops = pool.take_ops();
        let root_page = pool.pages(TileKey::ROOT).unwrap()[0].expect("stored again");
        assert_eq!(ops[1], PageOp { key: TileKey::ROOT, stores: vec![(0, root_page)] });
        assert_eq!(ops[2].key, c);
    }

    /// A full pool gives back the slots nobody asked for or read in `STALE_FRAMES` before it
    /// weighs benefits: the tile stays with the slots still in use.
    #[test]
    fn stale_slots_are_given_back_when_pages_run_short() {
        let mut pool = PagePool::keeping_whole(ROOT_PAGES + 17, PAGE_BYTES, 0).unwrap();
        let a = child(TileKey::ROOT, 0);
        pool.insert(a, bit(0, 0) | bit(3, 3), 1, 10.0).unwrap();
        pool.end_trials(1 + TRIAL_FRAMES);
        assert_eq!(pool.stores(a).len(), 2);
        // Slot (0, 0) is read in frame 20, (3, 3) was last asked for in frame 1.
        let frame = 2 + STALE_FRAMES + TRIAL_FRAMES;
        pool.note_used(a, bit(0, 0), frame);
        pool.touch(a, frame);
        // 15 pages free, 16 needed; by benefit alone (1 against 10) nothing may go.
        let b = child(TileKey::ROOT, 1);
        assert_eq!(pool.insert(b, bit(0, 0), frame, 1.0).unwrap(), Insert::Inserted { evicted: 0 });
        assert_eq!(pool.stores(a).iter().map(|s| s.0).collect::<Vec<_>>(), vec![0]);
        // Nothing stale is left: the next tile is refused.
        let c = child(TileKey::ROOT, 2);
        assert_eq!(pool.insert(c, bit(0, 0), frame, 1.0).unwrap(), Insert::Refused);
    }

    /// A pool short of pages ends a trial begun in an earlier frame before it evicts: the tile
    /// keeps the slots asked for; one begun in this frame runs on.
    #[test]
    fn a_short_pool_ends_an_earlier_trial_first() {
        let mut pool = PagePool::keeping_whole(ROOT_PAGES + 16 + 15, PAGE_BYTES, 0).unwrap();
        let (a, b, c) = (child(TileKey::ROOT, 0), child(TileKey::ROOT, 1), child(TileKey::ROOT, 2));
        pool.insert(a, bit(0, 0), 1, 1.0).unwrap();
        assert_eq!(pool.insert(b, bit(1, 1), 2, 1.0).unwrap(), Insert::Inserted { evicted: 0 });
        assert!(pool.tiles[&a].trial.is_none() && pool.tiles[&b].trial.is_some());
        assert_eq!(pool.stores(a).iter().map(|s| s.0).collect::<Vec<_>>(), vec![0]);
        // 14 pages free; b's trial began in frame 2 and runs on: a (not used since frame 1) is
        // evicted, which frees too little, and c is refused.
        assert_eq!(pool.insert(c, bit(0, 0), 2, 1.0).unwrap(), Insert::Refused);
        assert!(!pool.contains(a) && pool.stores(b).len() == SLOTS);
    }

    /// A short pool gives back the stale slots seen longest ago, only as many as the insertion
    /// needs: the tile seen later keeps its slots.
    #[test]
    fn stale_slots_go_stalest_first_and_no_more_than_needed() {
        let mut pool = PagePool::keeping_whole(ROOT_PAGES + 4 + 15, PAGE_BYTES, 0).unwrap();
        let (a, b, c) = (child(TileKey::ROOT, 0), child(TileKey::ROOT, 1), child(TileKey::ROOT, 2));
        pool.insert(a, bit(0, 0) | bit(3, 3), 1, 1.0).unwrap();
        pool.end_trials(1 + TRIAL_FRAMES);
        pool.insert(b, bit(0, 0) | bit(3, 3), 3, 1.0).unwrap();
        pool.end_trials(3 + TRIAL_FRAMES);
        assert_eq!((pool.stores(a).len(), pool.stores(b).len(), in_use(&pool)), (2, 2, TILE_PAGES + 4));
        // Both stale; c's trial takes 16 pages of 15 free: a's two (seen in frame 1) go.
        let frame = 3 + STALE_FRAMES + 10;
        assert_eq!(pool.insert(c, bit(0, 0), frame, 1.0).unwrap(), Insert::Inserted { evicted: 0 });
        assert!(!pool.contains(a), "stale and wanting nothing else: evicted");
        assert_eq!(pool.stores(b).len(), 2, "not needed: kept");
    }

    /// Renders of one tile queued in a frame become one, at the last's place, into the pages
    /// it holds then; a tile no longer resident renders nothing.
    #[test]
    fn a_tile_renders_once_a_frame() {
        let mut pool = PagePool::keeping_whole(64, PAGE_BYTES, 0).unwrap();
        let a = child(TileKey::ROOT, 0);
        pool.insert(a, ALL_SLOTS, 1, 1.0).unwrap();
        let root = pool.stores(TileKey::ROOT);
        let gone = child(TileKey::ROOT, 2);
        let op = |key, stores: &[(u32, u32)]| PageOp { key, stores: stores.to_vec() };
        let ops = vec![
            op(TileKey::ROOT, &root[..2]),
            op(a, &pool.stores(a)[..1]),
            op(gone, &[(0, 99)]),
            op(TileKey::ROOT, &[(0, 99), root[5]]),
        ];
        let merged = pool.merged(ops);
        let root_slots = [root[0], root[1], root[5]];
        assert_eq!(merged, vec![op(a, &pool.stores(a)[..1]), op(TileKey::ROOT, &root_slots)]);
    }

    /// The tiles down to `WHOLE_LEVELS` keep every slot past their trial, stale or not; a tile
    /// below them keeps the slots asked for.
    #[test]
    fn the_upper_levels_keep_every_slot() {
        let mut pool = PagePool::new(2000, PAGE_BYTES).unwrap();
        let uv = [0.3, 0.6];
        let key = |level| TileKey::containing(uv, level).unwrap();
        for level in 1..=WHOLE_LEVELS + 1 {
            pool.insert(key(level), bit(0, 0), 1, 1.0).unwrap();
        }
        pool.end_trials(1 + TRIAL_FRAMES);
        for level in 1..=WHOLE_LEVELS {
            // Wanted whole (its child covers four of them).
            assert_eq!(pool.tiles[&key(level)].wanted, ALL_SLOTS, "level {level}");
        }
        // 2000 pages, 1000 free: not half, so the deepest keeps the slot asked for alone.
        assert_eq!(pool.stores(key(WHOLE_LEVELS + 1)).len(), 1);
        while pool.release_stalest(100, &mut |_| true) {}
        for level in 1..=WHOLE_LEVELS {
            assert_eq!(pool.tiles[&key(level)].wanted, ALL_SLOTS, "level {level} after a release");
        }
        assert!(!pool.contains(key(WHOLE_LEVELS + 1)), "stale and wanting nothing else: evicted");
    }

    /// Noting no slot is no use: the least recently used tile still goes first.
    #[test]
    fn noting_no_slot_leaves_the_eviction_order() {
        let mut pool = PagePool::keeping_whole(ROOT_PAGES + 16, PAGE_BYTES, 0).unwrap();
        let a = child(TileKey::ROOT, 0);
        pool.insert(a, ALL_SLOTS, 1, 100.0).unwrap();
        pool.end_trials(1 + TRIAL_FRAMES);
        assert!(pool.note(a, 0, 9, None));
        // Full; a tile of least benefit takes a's pages: a was last used in frame 1.
        let b = child(TileKey::ROOT, 1);
        assert_eq!(pool.insert(b, bit(0, 0), 9, 1.0).unwrap(), Insert::Inserted { evicted: 1 });
        assert!(!pool.contains(a));
    }

    /// A lookup falling back to an ancestor's slot keeps that slot in use.
    #[test]
    fn a_slot_read_from_below_is_seen() {
        let mut pool = PagePool::keeping_whole(64, PAGE_BYTES, 0).unwrap();
        let a = child(TileKey::ROOT, 0);
        let d = child(a, 3);
        pool.insert(a, ALL_SLOTS, 1, 1.0).unwrap();
        pool.insert(d, bit(0, 0), 1, 1.0).unwrap();
        pool.end_trials(1 + TRIAL_FRAMES);
        assert_eq!((pool.stores(a).len(), pool.stores(d).len()), (SLOTS, 1));
        // d's slot (3, 3) lies in a's slot (3, 3), its slots (0, 0) and (1, 1) in a's (2, 2).
        assert_eq!(parent_slots(d, bit(3, 3)), bit(3, 3));
        assert_eq!(parent_slots(d, bit(0, 0) | bit(1, 1)), bit(2, 2));
        pool.note_read_above(d, bit(3, 3), 9);
        assert_eq!(pool.tiles[&a].seen[15], 9);
        assert_eq!(pool.tiles[&a].seen[0], 1, "asked for when inserted");
    }

    /// Random requests over many frames: the pool never holds more than its budget or its
    /// nodes, the root stays, every resident tile's parent is resident (the lookup reaches it),
    /// a tile stores exactly its wanted slots that its children do not cover, every point
    /// finds a stored slot, and no two stored slots share a page.
    #[test]
    fn the_budget_is_never_exceeded() {
        // With every level trimmed, and with the engine's whole upper levels.
        for whole in [0, WHOLE_LEVELS] {
            random_requests(whole);
        }
    }

    fn random_requests(whole: u32) {
        let capacity = 160;
        let mut pool = PagePool::keeping_whole(capacity, PAGE_BYTES, whole).unwrap();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let (mut replaced, mut refused, mut trials) = (0, 0, 0);
        for frame in 1..400u64 {
            for _ in 0..8 {
                // A random resident tile's random descendant one or two levels down.
                let resident: Vec<TileKey> = pool.resident().map(|(k, _)| k).collect();
                let mut key = resident[(next() % resident.len() as u64) as usize];
                for _ in 0..1 + next() % 2 {
                    key = key.children().map_or(key, |c| c[(next() % 4) as usize]);
                }
                let slots = (next() & next() & 0xffff) as Slots;
                if !pool.note(key, slots, frame, None) {
                    match pool.insert(key, slots, frame, (next() % 100) as f32).unwrap() {
                        Insert::Inserted { evicted } => replaced += evicted,
                        Insert::Refused => refused += 1,
                        Insert::Present => {}
                    }
                }
                pool.note_used(key, (next() & 0xffff) as Slots, frame);
            }
            trials += pool.tiles.values().filter(|r| r.trial.is_some()).count();
            pool.end_trials(frame);
            // The frame's renders, one per tile, write only pages their tiles hold.
            let taken = pool.take_ops();
            let ops = pool.merged(taken);
            for (i, op) in ops.iter().enumerate() {
                assert!(ops[..i].iter().all(|o| o.key != op.key), "{:?} rendered twice", op.key);
                assert!(op.stores.iter().all(|s| pool.stores(op.key).contains(s)), "{op:?}");
            }
            assert!(in_use(&pool) <= u64::from(capacity) && pool.tiles.len() <= pool.max_tiles() as usize);
            assert!(pool.contains(TileKey::ROOT));
            let mut pages: Vec<u32> = Vec::new();
            for (&k, r) in &pool.tiles {
                assert!(k.parent().is_none_or(|p| pool.contains(p)), "{k:?} cut off");
                // The deepest level has no children.
                let full = k.children().map_or([0; 4], |children| {
                    children.map(|c| pool.tiles.get(&c).filter(|r| r.trial.is_none()).map_or(0, |r| r.full))
                });
                assert_eq!(r.stored(), r.wanted & !covered_by(full), "{k:?}");
                // A point in a slot with no child over it reads this tile's or an ancestor's.
                for slot in 0..SLOT_SIDE * SLOT_SIDE {
                    let (x, y) = (slot % SLOT_SIDE, slot / SLOT_SIDE);
                    if !k.children().is_some_and(|c| pool.contains(c[(x / 2 + 2 * (y / 2)) as usize])) {
                        pool.holder(k, slot).unwrap();
                    }
                }
                pages.extend(r.pages.iter().flatten());
            }
            let count = pages.len();
            assert_eq!(count as u64, in_use(&pool));
            pages.sort_unstable();
            pages.dedup();
            assert_eq!(pages.len(), count, "two slots share a page");
        }
        assert!(replaced > 100 && refused > 0 && trials > 100, "{replaced}, {refused}, {trials}");
    }
}
