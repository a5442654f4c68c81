//! The page table the GPU lookup descends: the resident tiles as a tree of `AsmNode` records
//! in a texel buffer, the root at index 0 and every node's descendants after it (breadth
//! first). Each node names, over each cell of its grandchildren's 4×4 grid, the finest resident
//! tile up to two levels below it, so that the lookup goes down two levels per texel fetch; it
//! stops where that tile is less than two levels down (or none is) and reads the last node's
//! entry for the slot of its tile that holds the point: the page of that slot where the tile
//! stores it, else the page of the nearest ancestor's slot that holds the point, with the levels
//! up (`pool`: a tile stores only the slots asked for).
//!
//! A directory comes first in the buffer: one entry per tile of level
//! `ASM_DIRECTORY_LEVEL`, naming the finest resident tile at or above that level over it, so
//! that the descent starts there instead of at the root.
use super::pool::{parent_slot, PagePool, SLOTS, SLOT_SIDE};
use super::tile::TileKey;
use crate::backend::TexelBuffer;
use crate::error::{Error, Result};
use crate::layouts::constants::ASM_DIRECTORY_LEVEL;
use crate::layouts::{bytes_of_slice, AsmNode};
use std::collections::VecDeque;

/// Per slot of a tile: the page and levels up of the nearest tile at or above it that stores the
/// slot's point (what `PagePool::holding` finds walking up), `None` where none does.
type Held = [Option<(u32, u32)>; SLOTS];

/// Entries of the directory per side.
pub const DIRECTORY_SIDE: u32 = 1 << ASM_DIRECTORY_LEVEL;
/// Bytes of the directory at the head of the page-table buffer.
pub const DIRECTORY_BYTES: u64 = 4 * DIRECTORY_SIDE as u64 * DIRECTORY_SIDE as u64;
/// The levels-down field of a directory entry (its tile's level) and of a node's `below`
/// entries (1 or 2), above the node index.
const LEVEL_SHIFT: u32 = 24;
/// Pages a `pages` entry can index, below the levels-up field.
pub const MAX_PAGES: u32 = 1 << LEVEL_SHIFT;

/// A page's index as a node's `pages` entry holds it, below the levels-up field.
fn page_entry(page: u32) -> Result<u32> {
    if page >= MAX_PAGES {
        return Err(Error::Internal(format!("ASM page {page} past the page table's 24-bit page index")));
    }
    Ok(page)
}

/// What the page-table buffer holds: the directory (row by row, `node | level << 24`), then
/// the nodes; and each node's tile, for the host.
pub struct PageTable {
    pub directory: Vec<u32>,
    pub nodes: Vec<AsmNode>,
    pub keys: Vec<TileKey>,
}

impl PageTable {
    /// Writes the table into `buffer` as `asm_lookup.glsl`'s `PageTable` block reads it: the
    /// directory, then the nodes straight from their array (no copy of the whole table: the host
    /// writes it every frame).
    pub fn write(&self, buffer: &mut TexelBuffer) -> Result<()> {
        let directory: Vec<u8> = self.directory.iter().flat_map(|e| e.to_ne_bytes()).collect();
        buffer.write(0, &directory)?;
        buffer.write(DIRECTORY_BYTES, bytes_of_slice(&self.nodes))
    }

    /// Bytes of a table of up to `nodes` nodes.
    pub fn buffer_bytes(nodes: u32) -> u64 {
        DIRECTORY_BYTES + u64::from(nodes) * size_of::<AsmNode>() as u64
    }
}

/// The page table of `pool`'s resident tiles, root first.
pub fn build(pool: &PagePool) -> Result<PageTable> {
    // Per slot: its page, or the nearest ancestor's that holds it, with the levels up (handed
    // down from the parent, so that no slot walks up the tree: the host builds this table every
    // frame); a slot under a resident child is never read (the descent goes on): 0 stands in.
    let node = |key: TileKey, above: &Held| -> Result<(AsmNode, Held, [bool; 4])> {
        let pages = pool
            .pages(key)
            .ok_or_else(|| Error::Internal(format!("ASM tile {key:?} listed but not resident")))?;
        let children = key.children();
        let resident = std::array::from_fn(|q| children.is_some_and(|c| pool.contains(c[q])));
        let mut held: Held = [None; SLOTS];
        let mut entries = [[0u32; 4]; 4];
        for (slot, entry) in entries.as_flattened_mut().iter_mut().enumerate() {
            held[slot] = match pages[slot] {
                Some(page) => Some((page, 0)),
                None => above[slot].map(|(page, up)| (page, up + 1)),
            };
            let (x, y) = (slot as u32 % SLOT_SIDE, slot as u32 / SLOT_SIDE);
            let half = SLOT_SIDE / 2;
            *entry = match (held[slot], resident[((x / half) + 2 * (y / half)) as usize]) {
                (Some((page, 0)), _) => page_entry(page)?,
                (_, true) => 0,
                (Some((page, up)), false) => page_entry(page)? | up << LEVEL_SHIFT,
                (None, false) => {
                    return Err(Error::Internal(format!(
                        "no resident tile at or above ASM tile {key:?} stores its slot {slot}"
                    )))
                }
            };
        }
        Ok((AsmNode { below: [[0; 4]; 4], pages: entries }, held, resident))
    };
    // What a child's slots inherit: the holder of the parent's slot over each.
    let handed_down = |child: TileKey, held: &Held| -> Held {
        std::array::from_fn(|slot| held[parent_slot(child, slot as u32) as usize])
    };
    let (root, held, resident) = node(TileKey::ROOT, &[None; SLOTS])?;
    let (mut nodes, mut keys) = (vec![root], vec![TileKey::ROOT]);
    // Each node's resident children (node indices, 0: none), for the `below` entries.
    let mut children = vec![[0u32; 4]];
    let mut directory = vec![0u32; (DIRECTORY_SIDE * DIRECTORY_SIDE) as usize];
    let mut queue = VecDeque::from([(TileKey::ROOT, 0usize, held, resident)]);
    while let Some((key, at, held, resident)) = queue.pop_front() {
        // Breadth first: a finer tile overwrites its ancestors' entries.
        if key.level <= ASM_DIRECTORY_LEVEL {
            let span = 1 << (ASM_DIRECTORY_LEVEL - key.level);
            let entry = at as u32 | key.level << LEVEL_SHIFT;
            for y in key.y * span..(key.y + 1) * span {
                let row = (y * DIRECTORY_SIDE) as usize;
                directory[row + (key.x * span) as usize..row + ((key.x + 1) * span) as usize].fill(entry);
            }
        }
        let Some(tiles) = key.children() else { continue };
        for (q, child) in tiles.into_iter().enumerate().filter(|(q, _)| resident[*q]) {
            let (record, child_held, child_resident) = node(child, &handed_down(child, &held))?;
            children[at][q] = nodes.len() as u32;
            queue.push_back((child, nodes.len(), child_held, child_resident));
            nodes.push(record);
            keys.push(child);
            children.push([0; 4]);
        }
    }
    // Children come after their parents: each node's grandchildren are known by now.
    for at in 0..nodes.len() {
        for (q, &child) in children[at].iter().enumerate().filter(|(_, c)| **c != 0) {
            for (g, &grandchild) in children[child as usize].iter().enumerate() {
                // Cell (x, y) of the 4×4 grid: the child's quadrant is its high bit, the
                // grandchild's the low one.
                let (x, y) = (2 * (q & 1) + (g & 1), 2 * (q >> 1) + (g >> 1));
                nodes[at].below[y][x] = match grandchild {
                    0 => child | 1 << LEVEL_SHIFT,
                    _ => grandchild | 2 << LEVEL_SHIFT,
                };
            }
        }
    }
    Ok(PageTable { directory, nodes, keys })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::techniques::asm::pool::DEPTH_PAGE_BYTES as PAGE_BYTES;
    use crate::techniques::asm::pool::SLOT_SIDE;

    /// asm_lookup.glsl reads the table as 16-byte texels: the directory four entries to a
    /// texel, each node eight (below's four rows, then pages': ASM_NODE_TEXELS, ASM_NODE_PAGES).
    #[test]
    fn the_table_is_whole_texels_as_the_shader_reads_it() {
        assert_eq!(DIRECTORY_BYTES % 16, 0);
        assert_eq!(size_of::<AsmNode>(), 8 * 16);
        assert_eq!(std::mem::offset_of!(AsmNode, below), 0);
        assert_eq!(std::mem::offset_of!(AsmNode, pages), 4 * 16);
    }

    /// The finest tile over `uv` whose ancestors are all resident, from the pool alone.
    fn finest(pool: &PagePool, uv: [f32; 2]) -> TileKey {
        let mut found = TileKey::ROOT;
        while let Some(next) = TileKey::containing(uv, found.level + 1).filter(|k| pool.pages(*k).is_some()) {
            found = next;
        }
        found
    }

    /// The GPU's lookup (asm_lookup.glsl) on the CPU: the directory's tile over `uv`, and on
    /// from there, two levels a step, only where that tile is of the directory's level.
    fn lookup(table: &PageTable, uv: [f32; 2]) -> TileKey {
        let cell = |c: f32, n: u32| ((c * n as f32) as u32).min(n - 1);
        let entry = table.directory
            [(cell(uv[1], DIRECTORY_SIDE) * DIRECTORY_SIDE + cell(uv[0], DIRECTORY_SIDE)) as usize];
        let mut at = (entry & 0xff_ffff) as usize;
        assert_eq!(table.keys[at].level, entry >> LEVEL_SHIFT, "the entry's level is its node's");
        if entry >> LEVEL_SHIFT < ASM_DIRECTORY_LEVEL {
            return table.keys[at];
        }
        loop {
            let n = 4 << table.keys[at].level;
            let below = table.nodes[at].below[(cell(uv[1], n) & 3) as usize][(cell(uv[0], n) & 3) as usize];
            let down = below >> LEVEL_SHIFT;
            if down == 0 {
                return table.keys[at];
            }
            let next = (below & 0xff_ffff) as usize;
            assert_eq!(table.keys[next].level, table.keys[at].level + down);
            at = next;
            if down == 1 {
                return table.keys[at];
            }
        }
    }

    #[test]
    fn a_missing_tile_falls_back_to_its_nearest_resident_ancestor() {
        let mut pool = PagePool::new(80, PAGE_BYTES).unwrap();
        // Refine towards uv = (0.3, 0.6) down to level 4.
        let uv = [0.3, 0.6];
        for level in 1..=4 {
            pool.insert(TileKey::containing(uv, level).unwrap(), 1, 1, 1.0).unwrap();
        }
        let table = build(&pool).unwrap();
        assert_eq!(table.nodes.len(), 5);
        assert_eq!(lookup(&table, uv), TileKey::containing(uv, 4).unwrap());
        // A point in the same level-2 tile but another level-3 one gets the level-2 tile.
        let beside = [0.3 + 0.125, 0.6];
        assert_eq!(TileKey::containing(beside, 2), TileKey::containing(uv, 2));
        assert_eq!(lookup(&table, beside), TileKey::containing(uv, 2).unwrap());
        // Far away: the root, which every lookup can fall back to; never "no tile".
        assert_eq!(lookup(&table, [0.9, 0.1]), TileKey::ROOT);
        // Each node names, per slot no resident child lies over, its own page or the nearest
        // ancestor's that holds the slot, with the levels up.
        for (node, key) in table.nodes.iter().zip(&table.keys) {
            let pages = pool.pages(*key).unwrap();
            for (slot, &entry) in node.pages.as_flattened().iter().enumerate() {
                let (x, y) = (slot as u32 % SLOT_SIDE, slot as u32 / SLOT_SIDE);
                let child = key.children().unwrap()[((x / 2) + 2 * (y / 2)) as usize];
                if pool.contains(child) {
                    continue;
                }
                let expected = match pages[slot] {
                    Some(page) => page,
                    None => {
                        let (page, up) = pool.holder(*key, slot as u32).unwrap();
                        assert!(up > 0 && pool.pages(TileKey::ROOT).is_some());
                        page | up << LEVEL_SHIFT
                    }
                };
                assert_eq!(entry, expected, "{key:?} slot {slot}");
            }
        }
    }

    #[test]
    fn each_node_names_the_finest_resident_tile_two_levels_down_in_the_right_cell() {
        let mut pool = PagePool::new(96, PAGE_BYTES).unwrap();
        for child in TileKey::ROOT.children().unwrap() {
            pool.insert(child, 1, 1, 1.0).unwrap();
        }
        let grandchild = TileKey::ROOT.children().unwrap()[2].children().unwrap()[1];
        pool.insert(grandchild, 1, 1, 1.0).unwrap();
        let table = build(&pool).unwrap();
        assert_eq!(table.nodes.len(), 6);
        let mut named = [0; 3];
        for (at, (node, key)) in table.nodes.iter().zip(&table.keys).enumerate() {
            for (y, row) in node.below.iter().enumerate() {
                for (x, &entry) in row.iter().enumerate() {
                    let cell =
                        TileKey { level: key.level + 2, x: 4 * key.x + x as u32, y: 4 * key.y + y as u32 };
                    let down = (entry >> LEVEL_SHIFT) as usize;
                    named[down] += 1;
                    // The finest resident tile of the cell's ancestors up to two levels down.
                    let resident = (1..=2).rev().find(|d| {
                        pool.pages(TileKey {
                            level: key.level + d,
                            x: cell.x >> (2 - d),
                            y: cell.y >> (2 - d),
                        })
                        .is_some()
                    });
                    assert_eq!(down as u32, resident.unwrap_or(0), "cell {x}, {y} of {key:?}");
                    if down > 0 {
                        let below = (entry & 0xff_ffff) as usize;
                        assert!(below > at);
                        assert_eq!(table.keys[below].level, key.level + down as u32);
                        assert!(table.keys[below].covers(cell));
                    }
                }
            }
        }
        // The root names the grandchild in one cell and its children in the 15 others, the
        // grandchild's parent names it in the 4 cells under it; the other 76 cells name none.
        assert_eq!(named, [6 * 16 - 20, 15 + 4, 1]);
    }

    #[test]
    fn the_lookup_finds_the_finest_resident_tile_wherever_the_chains_end() {
        // Chains refined past the directory's level at two points, and a full level 2, so that
        // the directory holds tiles above, at and (through them) below its level.
        let deep = ASM_DIRECTORY_LEVEL + 3;
        let mut pool = PagePool::new(1024, PAGE_BYTES).unwrap();
        for uv in [[0.3, 0.6], [0.71, 0.12]] {
            for level in 1..=deep {
                pool.insert(TileKey::containing(uv, level).unwrap(), 1, 1, 1.0).unwrap();
            }
        }
        for key in TileKey::ROOT.children().unwrap() {
            pool.insert(key, 1, 1, 1.0).unwrap();
            for child in key.children().unwrap() {
                pool.insert(child, 1, 1, 1.0).unwrap();
            }
        }
        let table = build(&pool).unwrap();
        assert_eq!(table.directory.len() as u64 * 4, DIRECTORY_BYTES);
        // A lattice of points finer than the deepest tiles near the chains, coarser elsewhere.
        let mut reached_deep = 0;
        for centre in [[0.3f32, 0.6], [0.71, 0.12], [0.5, 0.5]] {
            for i in 0..64 {
                for j in 0..64 {
                    let step = 1.0 / (1u32 << deep) as f32 / 8.0;
                    let uv = [centre[0] + (i as f32 - 32.0) * step, centre[1] + (j as f32 - 32.0) * step];
                    let found = lookup(&table, uv);
                    assert_eq!(found, finest(&pool, uv), "at {uv:?}");
                    reached_deep += usize::from(found.level == deep);
                }
            }
        }
        assert!(reached_deep > 0, "the lattice reaches the chains' deepest tiles");
        for uv in [[0.0, 0.0], [0.999_99, 0.999_99], [0.5, 0.25]] {
            assert_eq!(lookup(&table, uv), finest(&pool, uv));
        }
    }
}
