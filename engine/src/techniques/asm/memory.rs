//! Where the ASM budget goes: every buffer and image the technique allocates counts in it, so
//! that `--asm-budget-mb 16` compares with a 2048² D32 map (16 MiB) byte for byte. Some parts
//! are fixed (the scratch tiles, the page table's directory, the light records, the analysis's
//! edge records, [`edge_records`]); the rest grows with the pool: its pages, and per tile
//! a page-table node, a use mark and a request flag. The pool gets what the fixed parts leave.
use super::page_table::PageTable;
use super::pages::{scratch_bytes, scratch_layers};
use super::pool::{max_tiles, TILE_PAGES};
use crate::error::{Error, Result};
use crate::layouts::constants::{self, MAX_LOCAL_LIGHTS};
use crate::layouts::ShadowLight;

/// Bytes per word of the analysis's `requests` buffer (a u32).
const WORD: u64 = 4;

/// The bytes of each part of the technique's memory.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AsmMemory {
    /// The pages (16-bit depths, and polygon IDs with the ID test).
    pub pages: u64,
    /// The scratch every tile renders into before its slots are packed into pages.
    pub scratch: u64,
    /// The scratch's layers ([`scratch_layers`]), counted in `scratch`.
    pub scratch_layers: u32,
    /// The page table: the directory and a node per tile.
    pub page_table: u64,
    /// The analysis's requests (a counter, a flag per node, an edge record per analysed pixel)
    /// and the lighting's use marks (one per node).
    pub analysis: u64,
    /// The light records.
    pub lights: u64,
}

impl AsmMemory {
    pub fn total(&self) -> u64 {
        self.pages + self.scratch + self.page_table + self.analysis + self.lights
    }

    /// The parts for a pool of `pages` pages of `page_bytes`, its nodes ([`max_tiles`]),
    /// `edges` edge records of the analysis ([`edge_records`]) and a scratch of `layers` layers.
    pub fn of(pages: u32, page_bytes: u64, edges: u32, layers: u32) -> AsmMemory {
        let nodes = max_tiles(pages);
        AsmMemory {
            pages: u64::from(pages) * page_bytes,
            scratch: scratch_bytes(page_bytes, layers),
            scratch_layers: layers,
            page_table: PageTable::buffer_bytes(nodes),
            analysis: requests_bytes(nodes, edges) + used_bytes(nodes),
            lights: lights_bytes(),
        }
    }

    /// The most pages of `page_bytes` whose memory, with everything else (a scratch of
    /// [`scratch_layers`] layers), stays within `budget`; an error naming the fixed parts when
    /// not even the root tile fits.
    pub fn within(budget: u64, page_bytes: u64, edges: u32) -> Result<(u32, AsmMemory)> {
        let layers = scratch_layers(budget);
        let of = |pages: u32| AsmMemory::of(pages, page_bytes, edges, layers);
        let fixed = of(0).total();
        // A pool of N pages has N / 4 nodes: four pages carry a node's bytes.
        let per_node = of(4).total() - fixed - 4 * page_bytes;
        let estimate = budget.saturating_sub(fixed) * 4 / (4 * page_bytes + per_node);
        // The estimate spreads a node over 4 pages; the exact count is a few pages away.
        let fits = |pages: u32| of(pages).total() <= budget;
        let mut pages = u32::try_from(estimate).unwrap_or(u32::MAX - 1);
        while fits(pages + 1) {
            pages += 1;
        }
        while pages > 0 && !fits(pages) {
            pages -= 1;
        }
        if u64::from(pages) < TILE_PAGES {
            return Err(Error::InvalidArgument(format!(
                "an ASM budget of {budget} bytes holds no tile: the root takes {} bytes beside {fixed} bytes of scratch, page directory, light records and the analysis's {edges} edge records",
                TILE_PAGES * page_bytes
            )));
        }
        Ok((pages, of(pages)))
    }
}

/// The edge records the analysis keeps a frame for images of `size` (width, height): an eighth
/// of the pixels it looks at (one of each 2×2 block). Measured over the `asm` walkthrough at
/// 512²: median 916 records a frame, 90th percentile 2,834, at most 15,839 (the first frame)
/// of 65,536 analysed pixels; a frame's records beyond the capacity are dropped, and the next
/// frames ask again (a frame renders a few dozen tiles at most anyway).
pub fn edge_records(size: (u32, u32)) -> u32 {
    (size.0.div_ceil(2) * size.1.div_ceil(2)).div_ceil(8)
}

/// The analysis's `requests` buffer: a counter, a flag per node, then `edges` edge records.
pub fn requests_bytes(nodes: u32, edges: u32) -> u64 {
    WORD * (1 + 2 * u64::from(nodes) + u64::from(constants::ASM_EDGE_WORDS) * u64::from(edges))
}

/// The lighting's use marks: one frame number per node.
pub fn used_bytes(nodes: u32) -> u64 {
    WORD * u64::from(nodes)
}

/// The light records (the light in record 0, as the shadowmap technique's).
pub fn lights_bytes() -> u64 {
    u64::from(MAX_LOCAL_LIGHTS) * size_of::<ShadowLight>() as u64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::techniques::asm::page_table::DIRECTORY_BYTES;
    use crate::techniques::asm::pool::DEPTH_PAGE_BYTES;

    #[test]
    fn the_parts_fill_the_budget_and_never_pass_it() {
        let edges = edge_records((512, 512));
        for budget in [1u64 << 20, 4 << 20, 16 << 20, 256 << 20] {
            let (pages, memory) = AsmMemory::within(budget, DEPTH_PAGE_BYTES, edges).unwrap();
            assert!(memory.total() <= budget, "{memory:?} over {budget}");
            // One more page would not fit: the budget is used up to a page and a node.
            let layers = memory.scratch_layers;
            assert!(AsmMemory::of(pages + 1, DEPTH_PAGE_BYTES, edges, layers).total() > budget);
            // The least budget for an image of these pixels holds the root exactly.
            let least = AsmMemory::of(TILE_PAGES as u32, DEPTH_PAGE_BYTES, edges, 1).total();
            assert_eq!(AsmMemory::within(least, DEPTH_PAGE_BYTES, edges).unwrap().0, TILE_PAGES as u32);
            assert_eq!(memory.pages, u64::from(pages) * DEPTH_PAGE_BYTES);
            assert!(memory.scratch > 0 && memory.page_table >= DIRECTORY_BYTES && memory.analysis > 0);
        }
        // 64 KiB hold the scratch alone: a clear error naming the fixed parts.
        let err = AsmMemory::within(64 << 10, DEPTH_PAGE_BYTES, edges).unwrap_err().to_string();
        assert!(err.contains("holds no tile") && err.contains("the analysis's 8192 edge records"), "{err}");
    }
}
