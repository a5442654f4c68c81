//! The page table the GPU lookup descends: the resident tiles as a tree of `AsmNode` records
//! in a buffer, the root at index 0 and every node's children after it (breadth first). A child
//! index of 0 means "not resident" (the root is no one's child), so the lookup stops there and
//! uses the last node's page: the finest resident tile over the point.
use super::pool::PagePool;
use super::tile::TileKey;
use crate::layouts::AsmNode;
use std::collections::VecDeque;

/// The page table of `pool`'s resident tiles, root first.
pub fn build(pool: &PagePool) -> Vec<AsmNode> {
    let node = |key: TileKey, page: u32| AsmNode { children: [0; 4], tile: [page, key.level, key.x, key.y] };
    let root_page = pool.page(TileKey::ROOT).unwrap_or(0);
    let mut nodes = vec![node(TileKey::ROOT, root_page)];
    let mut queue = VecDeque::from([(TileKey::ROOT, 0usize)]);
    while let Some((key, at)) = queue.pop_front() {
        let Some(children) = key.children() else { continue };
        for (q, child) in children.into_iter().enumerate() {
            if let Some(page) = pool.page(child) {
                nodes[at].children[q] = nodes.len() as u32;
                queue.push_back((child, nodes.len()));
                nodes.push(node(child, page));
            }
        }
    }
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::techniques::asm::pool::DEPTH_PAGE_BYTES as PAGE_BYTES;

    /// The GPU's descent (as the lighting shader will do it), on the CPU: from the root, into
    /// the resident child holding `uv`, until there is none. Returns the tile reached.
    fn lookup(table: &[AsmNode], uv: [f32; 2]) -> TileKey {
        let mut at = 0usize;
        loop {
            let [_, level, x, y] = table[at].tile;
            let here = TileKey { level, x, y };
            let Some(child) = TileKey::containing(uv, level + 1) else { return here };
            match table[at].children[child.quadrant()] {
                0 => return here,
                next => at = next as usize,
            }
        }
    }

    #[test]
    fn a_missing_tile_falls_back_to_its_nearest_resident_ancestor() {
        let mut pool = PagePool::new(8 * PAGE_BYTES, PAGE_BYTES).unwrap();
        // Refine towards uv = (0.3, 0.6) down to level 4.
        let uv = [0.3, 0.6];
        for level in 1..=4 {
            pool.insert(TileKey::containing(uv, level).unwrap(), 1, 1.0).unwrap();
        }
        let table = build(&pool);
        assert_eq!(table.len(), 5);
        assert_eq!(lookup(&table, uv), TileKey::containing(uv, 4).unwrap());
        // A point in the same level-2 tile but another level-3 one gets the level-2 tile.
        let beside = [0.3 + 0.125, 0.6];
        assert_eq!(TileKey::containing(beside, 2), TileKey::containing(uv, 2));
        assert_eq!(lookup(&table, beside), TileKey::containing(uv, 2).unwrap());
        // Far away: the root, which every lookup can fall back to; never "no tile".
        assert_eq!(lookup(&table, [0.9, 0.1]), TileKey::ROOT);
        // Each node's page is its tile's page in the pool.
        for node in &table {
            let [page, level, x, y] = node.tile;
            assert_eq!(pool.page(TileKey { level, x, y }), Some(page));
        }
    }

    #[test]
    fn children_follow_their_parents_and_point_at_the_right_quadrant() {
        let mut pool = PagePool::new(16 * PAGE_BYTES, PAGE_BYTES).unwrap();
        for child in TileKey::ROOT.children().unwrap() {
            pool.insert(child, 1, 1.0).unwrap();
        }
        let grandchild = TileKey::ROOT.children().unwrap()[2].children().unwrap()[1];
        pool.insert(grandchild, 1, 1.0).unwrap();
        let table = build(&pool);
        assert_eq!(table.len(), 6);
        for (at, node) in table.iter().enumerate() {
            let [_, level, x, y] = node.tile;
            for (q, &child) in node.children.iter().enumerate().filter(|(_, c)| **c != 0) {
                assert!(child as usize > at);
                let [_, cl, cx, cy] = table[child as usize].tile;
                let key = TileKey { level: cl, x: cx, y: cy };
                assert_eq!((key.parent(), key.quadrant()), (Some(TileKey { level, x, y }), q));
            }
        }
    }
}
