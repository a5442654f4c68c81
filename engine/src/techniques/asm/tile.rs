//! Tiles of the quadtree over the light's view, addressed by level and position. The view is
//! the unit square of the light map's uv (u right, v down, as the shadow maps' texel rows); the
//! root (level 0) covers all of it, and tile (L, x, y) covers [x, x + 1) × [y, y + 1) / 2^L.
use crate::layouts::constants::{ASM_EDGE_CELL_BITS, ASM_MAX_LEVEL, ASM_TILE_TEXELS};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TileKey {
    pub level: u32,
    pub x: u32,
    pub y: u32,
}

impl TileKey {
    pub const ROOT: TileKey = TileKey { level: 0, x: 0, y: 0 };

    /// The tile of `level` (at most `ASM_MAX_LEVEL`) holding `uv`, or `None` for a point outside
    /// the view or a level beyond the deepest.
    pub fn containing(uv: [f32; 2], level: u32) -> Option<TileKey> {
        if level > ASM_MAX_LEVEL || !uv.iter().all(|c| (0.0..1.0).contains(c)) {
            return None;
        }
        let n = (1u64 << level) as f64;
        let at = |c: f32| ((f64::from(c) * n) as u32).min((1u32 << level) - 1);
        Some(TileKey { level, x: at(uv[0]), y: at(uv[1]) })
    }

    pub fn parent(self) -> Option<TileKey> {
        (self.level > 0).then(|| TileKey { level: self.level - 1, x: self.x / 2, y: self.y / 2 })
    }

    /// The four children in quadrant order (x, y) = (0, 0), (1, 0), (0, 1), (1, 1): quadrant
    /// q = 2 · (y & 1) + (x & 1), as the page table stores them; none below the deepest level.
    pub fn children(self) -> Option<[TileKey; 4]> {
        (self.level < ASM_MAX_LEVEL).then(|| {
            std::array::from_fn(|q| TileKey {
                level: self.level + 1,
                x: 2 * self.x + (q as u32 & 1),
                y: 2 * self.y + (q as u32 >> 1),
            })
        })
    }

    /// Which child of its parent this tile is (see [`TileKey::children`]).
    pub fn quadrant(self) -> usize {
        (2 * (self.y & 1) + (self.x & 1)) as usize
    }

    /// The tile of `level` holding the point at `cell` within this tile, in units of
    /// 2^-ASM_EDGE_CELL_BITS of its side (as the analysis's edge records give it), and the
    /// point's texel in that tile; an ancestor of this tile or a descendant at most
    /// `ASM_EDGE_CELL_BITS - log2(ASM_TILE_TEXELS)` levels down, else `None`.
    pub fn at_level(self, cell: [u32; 2], level: u32) -> Option<(TileKey, [u32; 2])> {
        let bits = self.level + ASM_EDGE_CELL_BITS;
        let texel_bits = ASM_TILE_TEXELS.trailing_zeros();
        if level > ASM_MAX_LEVEL || level + texel_bits > bits {
            return None;
        }
        let point = |tile: u32, c: u32| u64::from(tile) << ASM_EDGE_CELL_BITS | u64::from(c);
        let (x, y) = (point(self.x, cell[0]), point(self.y, cell[1]));
        let tile = |p: u64| (p >> (bits - level)) as u32;
        let texel = |p: u64| (p >> (bits - level - texel_bits)) as u32 % ASM_TILE_TEXELS;
        Some((TileKey { level, x: tile(x), y: tile(y) }, [texel(x), texel(y)]))
    }

    /// Whether `self` is `other` or one of its ancestors.
    pub fn covers(self, other: TileKey) -> bool {
        other.level >= self.level
            && other.x >> (other.level - self.level) == self.x
            && other.y >> (other.level - self.level) == self.y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_nest_and_cover_the_view() {
        let key = TileKey::containing([0.7, 0.2], 3).unwrap();
        assert_eq!(key, TileKey { level: 3, x: 5, y: 1 });
        assert_eq!(key.parent(), TileKey::containing([0.7, 0.2], 2));
        let children = key.children().unwrap();
        for (q, child) in children.iter().enumerate() {
            assert_eq!((child.parent(), child.quadrant()), (Some(key), q));
            assert!(key.covers(*child) && !child.covers(key));
        }
        assert!(TileKey::ROOT.covers(key) && key.covers(key));
        assert!(!TileKey { level: 3, x: 4, y: 1 }.covers(children[0]));
        assert_eq!(TileKey::ROOT.parent(), None);
        let deepest = TileKey::containing([0.999_999, 0.0], ASM_MAX_LEVEL).unwrap();
        assert_eq!((deepest.children(), deepest.x), (None, (1 << ASM_MAX_LEVEL) - 1));
        assert_eq!(TileKey::containing([1.0, 0.5], 1), None);
        assert_eq!(TileKey::containing([f32::NAN, 0.5], 1), None);
        assert_eq!(TileKey::containing([0.5, 0.5], ASM_MAX_LEVEL + 1), None);
    }

    #[test]
    fn an_edge_records_cell_names_the_tiles_and_texels_its_point_lies_in() {
        let cells = (1u32 << ASM_EDGE_CELL_BITS) as f64;
        for (i, level) in (0..=12).enumerate() {
            // Points spread over the view, none on a texel border of the levels asked.
            let uv = [(0.137 + 0.071 * i as f64) % 1.0, (0.911 - 0.053 * i as f64) % 1.0];
            let key = TileKey::containing(uv.map(|c| c as f32), level).unwrap();
            let n = (1u64 << level) as f64;
            let cell =
                [uv[0] * n - f64::from(key.x), uv[1] * n - f64::from(key.y)].map(|c| (c * cells) as u32);
            for at in level.saturating_sub(3)..=level + 4 {
                let expected = TileKey::containing(uv.map(|c| c as f32), at).unwrap();
                let side = (1u64 << at) as f64 * f64::from(ASM_TILE_TEXELS);
                let texel =
                    [uv[0] * side, uv[1] * side].map(|t| (t as u64 % u64::from(ASM_TILE_TEXELS)) as u32);
                assert_eq!(
                    key.at_level(cell, at),
                    Some((expected, texel)),
                    "uv {uv:?}, level {level} to {at}"
                );
            }
            assert_eq!(key.at_level(cell, level + 11), None, "finer than the cell");
        }
        let deepest = TileKey::containing([0.5, 0.5], ASM_MAX_LEVEL).unwrap();
        assert_eq!(deepest.at_level([0, 0], ASM_MAX_LEVEL + 1), None);
    }
}
