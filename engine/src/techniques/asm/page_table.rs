//! The page table the GPU lookup descends: the resident tiles as a tree of `AsmNode` records
//! in a texel buffer, the root at index 0 and every node's children after it (breadth first).
//! A child index of 0 means "not resident" (the root is no one's child), so the lookup stops
//! there and uses the last node's page of that quadrant: the finest resident tile over the
//! point, which stores every quadrant no resident child covers (`pool`).
//!
//! A directory comes first in the buffer: one entry per tile of level
//! `ASM_DIRECTORY_LEVEL`, naming the finest resident tile at or above that level over it, so
//! that the descent starts there instead of at the root.
use super::pages::AtlasLayout;
use super::pool::{PagePool, TilePages};
use super::tile::TileKey;
use crate::layouts::constants::ASM_DIRECTORY_LEVEL;
use crate::layouts::{bytes_of_slice, AsmNode};
use std::collections::VecDeque;

/// Entries of the directory per side.
pub const DIRECTORY_SIDE: u32 = 1 << ASM_DIRECTORY_LEVEL;
/// Bytes of the directory at the head of the page-table buffer.
pub const DIRECTORY_BYTES: u64 = 4 * DIRECTORY_SIDE as u64 * DIRECTORY_SIDE as u64;
/// A directory entry's level field (the node index below it).
const LEVEL_SHIFT: u32 = 24;

/// What the page-table buffer holds: the directory (row by row, `node | level << 24`), then
/// the nodes.
pub struct PageTable {
    pub directory: Vec<u32>,
    pub nodes: Vec<AsmNode>,
}

impl PageTable {
    /// The buffer's bytes, as `asm_lookup.glsl`'s `PageTable` block reads them.
    pub fn bytes(&self) -> Vec<u8> {
        let directory = self.directory.iter().flat_map(|e| e.to_ne_bytes());
        directory.chain(bytes_of_slice(&self.nodes).iter().copied()).collect()
    }

    /// Bytes of a table of up to `nodes` nodes.
    pub fn buffer_bytes(nodes: u32) -> u64 {
        DIRECTORY_BYTES + u64::from(nodes) * size_of::<AsmNode>() as u64
    }
}

/// The page table of `pool`'s resident tiles, root first, their pages' cells in an atlas laid
/// out as `layout`.
pub fn build(pool: &PagePool, layout: &AtlasLayout) -> PageTable {
    // A covered quadrant's page is never read: 0 stands in.
    let node = |key: TileKey, pages: TilePages| AsmNode {
        children: [0; 4],
        pages: pages.map(|p| p.map_or(0, |p| layout.cell(p))),
        tile: [key.level, key.x, key.y, 0],
    };
    let root = pool.pages(TileKey::ROOT).expect("the root is always resident");
    let mut nodes = vec![node(TileKey::ROOT, root)];
    let mut directory = vec![0u32; (DIRECTORY_SIDE * DIRECTORY_SIDE) as usize];
    let mut queue = VecDeque::from([(TileKey::ROOT, 0usize)]);
    while let Some((key, at)) = queue.pop_front() {
        // Breadth first: a finer tile overwrites its ancestors' entries.
        if key.level <= ASM_DIRECTORY_LEVEL {
            let span = 1 << (ASM_DIRECTORY_LEVEL - key.level);
            let entry = at as u32 | key.level << LEVEL_SHIFT;
            for y in key.y * span..(key.y + 1) * span {
                let row = (y * DIRECTORY_SIDE) as usize;
                directory[row + (key.x * span) as usize..row + ((key.x + 1) * span) as usize].fill(entry);
            }
        }
        let Some(children) = key.children() else { continue };
        for (q, child) in children.into_iter().enumerate() {
            if let Some(pages) = pool.pages(child) {
                nodes[at].children[q] = nodes.len() as u32;
                queue.push_back((child, nodes.len()));
                nodes.push(node(child, pages));
            }
        }
    }
    PageTable { directory, nodes }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::techniques::asm::pool::DEPTH_PAGE_BYTES as PAGE_BYTES;
    const LAYOUT: AtlasLayout = AtlasLayout { columns: 16, rows: 16 };

    /// asm_lookup.glsl reads the table as 16-byte texels: the directory four entries to a
    /// texel, each node three (children, pages, tile).
    #[test]
    fn the_table_is_whole_texels_as_the_shader_reads_it() {
        assert_eq!(DIRECTORY_BYTES % 16, 0);
        assert_eq!(size_of::<AsmNode>(), 3 * 16);
        assert_eq!(std::mem::offset_of!(AsmNode, children), 0);
        assert_eq!(std::mem::offset_of!(AsmNode, pages), 16);
        assert_eq!(std::mem::offset_of!(AsmNode, tile), 32);
    }

    fn key_of(node: &AsmNode) -> TileKey {
        let [level, x, y, _] = node.tile;
        TileKey { level, x, y }
    }

    /// From node `at`, into the resident child holding `uv` until there is none.
    fn descend(table: &PageTable, mut at: usize, uv: [f32; 2]) -> TileKey {
        loop {
            let here = key_of(&table.nodes[at]);
            let Some(child) = TileKey::containing(uv, here.level + 1) else { return here };
            match table.nodes[at].children[child.quadrant()] {
                0 => return here,
                next => at = next as usize,
            }
        }
    }

    /// The GPU's lookup (asm_lookup.glsl) on the CPU: the directory's tile over `uv`, and on
    /// from there only where that tile is of the directory's level.
    fn lookup(table: &PageTable, uv: [f32; 2]) -> TileKey {
        let cell = |c: f32| ((c * DIRECTORY_SIDE as f32) as u32).min(DIRECTORY_SIDE - 1);
        let entry = table.directory[(cell(uv[1]) * DIRECTORY_SIDE + cell(uv[0])) as usize];
        let at = (entry & 0xff_ffff) as usize;
        assert_eq!(table.nodes[at].tile[0], entry >> LEVEL_SHIFT, "the entry's level is its node's");
        if entry >> LEVEL_SHIFT < ASM_DIRECTORY_LEVEL {
            return key_of(&table.nodes[at]);
        }
        descend(table, at, uv)
    }

    #[test]
    fn a_missing_tile_falls_back_to_its_nearest_resident_ancestor() {
        let mut pool = PagePool::new(16, PAGE_BYTES).unwrap();
        // Refine towards uv = (0.3, 0.6) down to level 4.
        let uv = [0.3, 0.6];
        for level in 1..=4 {
            pool.insert(TileKey::containing(uv, level).unwrap(), 1, 1.0).unwrap();
        }
        let table = build(&pool, &LAYOUT);
        assert_eq!(table.nodes.len(), 5);
        assert_eq!(lookup(&table, uv), TileKey::containing(uv, 4).unwrap());
        // A point in the same level-2 tile but another level-3 one gets the level-2 tile.
        let beside = [0.3 + 0.125, 0.6];
        assert_eq!(TileKey::containing(beside, 2), TileKey::containing(uv, 2));
        assert_eq!(lookup(&table, beside), TileKey::containing(uv, 2).unwrap());
        // Far away: the root, which every lookup can fall back to; never "no tile".
        assert_eq!(lookup(&table, [0.9, 0.1]), TileKey::ROOT);
        // Each node's pages are its tile's in the pool, where no child covers the quadrant.
        for node in &table.nodes {
            let pages = pool.pages(key_of(node)).unwrap();
            for (q, page) in pages.iter().enumerate() {
                assert_eq!(page.is_none(), node.children[q] != 0);
                assert_eq!(page.map_or(0, |p| LAYOUT.cell(p)), node.pages[q]);
            }
        }
    }

    #[test]
    fn children_follow_their_parents_and_point_at_the_right_quadrant() {
        let mut pool = PagePool::new(19, PAGE_BYTES).unwrap();
        for child in TileKey::ROOT.children().unwrap() {
            pool.insert(child, 1, 1.0).unwrap();
        }
        let grandchild = TileKey::ROOT.children().unwrap()[2].children().unwrap()[1];
        pool.insert(grandchild, 1, 1.0).unwrap();
        let table = build(&pool, &LAYOUT);
        assert_eq!(table.nodes.len(), 6);
        for (at, node) in table.nodes.iter().enumerate() {
            for (q, &child) in node.children.iter().enumerate().filter(|(_, c)| **c != 0) {
                assert!(child as usize > at);
                let key = key_of(&table.nodes[child as usize]);
                assert_eq!((key.parent(), key.quadrant()), (Some(key_of(node)), q));
            }
        }
    }

    #[test]
    fn the_directory_starts_every_descent_where_the_root_would_arrive() {
        // Chains refined past the directory's level at two points, and a full level 2, so that
        // the directory holds tiles above, at and (through them) below its level.
        let deep = ASM_DIRECTORY_LEVEL + 3;
        let mut pool = PagePool::new(256, PAGE_BYTES).unwrap();
        for uv in [[0.3, 0.6], [0.71, 0.12]] {
            for level in 1..=deep {
                pool.insert(TileKey::containing(uv, level).unwrap(), 1, 1.0).unwrap();
            }
        }
        for key in TileKey::ROOT.children().unwrap() {
            pool.insert(key, 1, 1.0).unwrap();
            for child in key.children().unwrap() {
                pool.insert(child, 1, 1.0).unwrap();
            }
        }
        let table = build(&pool, &LAYOUT);
        assert_eq!(table.bytes().len() as u64, PageTable::buffer_bytes(table.nodes.len() as u32));
        // A lattice of points finer than the deepest tiles near the chains, coarser elsewhere.
        let mut reached_deep = 0;
        for centre in [[0.3f32, 0.6], [0.71, 0.12], [0.5, 0.5]] {
            for i in 0..64 {
                for j in 0..64 {
                    let step = 1.0 / (1u32 << deep) as f32 / 8.0;
                    let uv = [centre[0] + (i as f32 - 32.0) * step, centre[1] + (j as f32 - 32.0) * step];
                    let found = lookup(&table, uv);
                    assert_eq!(found, descend(&table, 0, uv), "at {uv:?}");
                    reached_deep += usize::from(found.level == deep);
                }
            }
        }
        assert!(reached_deep > 0, "the lattice reaches the chains' deepest tiles");
        for uv in [[0.0, 0.0], [0.999_99, 0.999_99], [0.5, 0.25]] {
            assert_eq!(lookup(&table, uv), descend(&table, 0, uv));
        }
    }
}
